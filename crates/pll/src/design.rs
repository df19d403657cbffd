//! The loop design: the PI gains that put the poles of the sampled loop exactly where the
//! continuous second-order design (natural frequency, damping) puts them.

use core::f64::consts::TAU;
use num_complex::Complex64;

/// The PI gains of a loop designed for natural frequency `wn`, damping `zeta`, envelope time
/// constant `tau` and update period `T` (see the crate docs for the derivation).
///
/// The sampled loop is `e[k+1] = alpha e[k] - g dw[k]` (the envelope's phase, with the
/// detuning `dw` held over each update: `alpha = exp(-T/tau)`, `g = tau (1 - alpha)`), closed
/// by `u[k] = Kp e[k] + I[k]`, `I[k] = I[k-1] + Ki T e[k]`. Its characteristic polynomial is
/// `z^2 + (g (Kp + Ki T) - 1 - alpha) z + (alpha - g Kp)`; equating it to
/// `(z - p1)(z - p2)` with `p = exp(s T)` at the continuous poles
/// `s = -zeta wn +- wn sqrt(zeta^2 - 1)` gives
/// `Kp = (alpha - p1 p2) / g` and `Ki T = (1 - p1)(1 - p2) / g`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopDesign {
    /// Proportional gain `Kp`, (rad/s) of carrier per rad of phase error.
    pub kp_per_s: f64,
    /// Integral gain per update `Ki T`, (rad/s) per rad, added to the integrator each update.
    pub ki_t_per_s: f64,
    /// The update period `T`, s.
    pub update_s: f64,
    /// The closed-loop poles `p1, p2 = exp(s T)` in the z-plane (a conjugate pair, or two
    /// real poles for `damping >= 1`).
    pub poles: [Complex64; 2],
}

impl LoopDesign {
    /// The design for `natural_hz` (`wn / 2 pi`), `damping` (`zeta`), `tau_s` and
    /// `update_rate_hz` (`1/T`), all finite and > 0 (the caller validates). `Kp` comes out
    /// negative exactly when `2 zeta wn tau < 1` (the caller refuses that).
    ///
    /// Differences of nearby exponentials go through `expm1`, so the gains keep full relative
    /// precision even when `wn T` is tiny.
    pub fn new(natural_hz: f64, damping: f64, tau_s: f64, update_rate_hz: f64) -> Self {
        let t = 1.0 / update_rate_hz;
        let wn = TAU * natural_hz;
        let zeta = damping;
        // 1 - alpha and g = tau (1 - alpha).
        let one_minus_alpha = -(-t / tau_s).exp_m1();
        let alpha = 1.0 - one_minus_alpha;
        let g = tau_s * one_minus_alpha;
        // alpha - p1 p2 = alpha (1 - exp(-(2 zeta wn - 1/tau) T)).
        let kp = -alpha * (-(2.0 * zeta * wn - 1.0 / tau_s) * t).exp_m1() / g;
        let sigma = zeta * wn * t;
        let r = (-sigma).exp();
        let (poles, one_minus_prod) = if zeta < 1.0 {
            let theta = wn * t * (1.0 - zeta * zeta).sqrt();
            let p = Complex64::from_polar(r, theta);
            // |1 - p|^2 with 1 - r cos = (1 - r) + 2 r sin^2(theta/2), free of cancellation.
            let half = (0.5 * theta).sin();
            let re = -(-sigma).exp_m1() + 2.0 * r * half * half;
            let im = r * theta.sin();
            ([p, p.conj()], re * re + im * im)
        } else {
            let d = wn * t * (zeta * zeta - 1.0).sqrt();
            let (s1, s2) = (-sigma + d, -sigma - d);
            let p = [s1.exp(), s2.exp()].map(|v| Complex64::new(v, 0.0));
            (p, s1.exp_m1() * s2.exp_m1())
        };
        Self {
            kp_per_s: kp,
            ki_t_per_s: one_minus_prod / g,
            update_s: t,
            poles,
        }
    }

    /// The integral gain `Ki = (Ki T) / T`, (rad/s) per rad per s; tends to `wn^2` as
    /// `T -> 0`.
    pub fn ki_per_s2(&self) -> f64 {
        self.ki_t_per_s / self.update_s
    }
}

/// The one-sided noise bandwidth `int_0^inf |H(j 2 pi f)|^2 df`, Hz, of the continuous loop
/// `H(s) = (Kp s + wn^2) / (s^2 + 2 zeta wn s + wn^2)` with `Kp = 2 zeta wn - 1/tau`:
/// `(Kp^2 + wn^2) / (8 zeta wn)` (the standard integral `I_2`; for `Kp = 2 zeta wn`, the
/// classic `wn/2 (zeta + 1/(4 zeta))`).
pub fn noise_bandwidth_hz(natural_hz: f64, damping: f64, tau_s: f64) -> f64 {
    let wn = TAU * natural_hz;
    let kp = 2.0 * damping * wn - 1.0 / tau_s;
    (kp * kp + wn * wn) / (8.0 * damping * wn)
}
