//! How the white noise reaches a rate table's reading: the read-out divides each demodulated
//! harmonic n of the envelope by the low-pass's gain at its own frequency n f_t, then takes
//! the fundamental of the envelope's phase. Two things the reading's scatter owes to that,
//! which the small-swing count (two harmonics at the low-pass's DC gain) left out:
//!
//! - the noise each harmonic carries after the division: besides the noise at n f_t, which
//!   the low-pass passes as it passes the signal, the averaging window's sidelobes leak in
//!   the noise near DC, which the low-pass passes whole, and the decimation folds in the noise
//!   at n f_t + k fs_out; divided by |L(n f_t)| far down the skirt, both come back multiplied;
//! - how much each harmonic's noise moves the fundamental of the phase: for a small swing
//!   only harmonics +-1, for a large one every harmonic, through the Fourier coefficients of
//!   1 / V(theta).
//!
//! A 9 Hz table read to its 15th harmonic behind a 10 Hz low-pass scattered 13 times the
//! small-swing count (21 times past the output's Nyquist frequency).

use crate::config::Config;
use crate::window_weight::{integrate_over_decades, window_weight};
use gyroemu_board::ChainResponse;
use gyroemu_core::Complex64;

impl Config {
    /// Per harmonic n = -N ..= N (index n + N), the noise power the read-out's harmonic n
    /// carries per unit of the DC reading's, both on the same span and window: `I(n f_t) /
    /// I(0) |L(0) / L(n f_t)|^2`, where `I(f) = int S_dec(f + d) K(d T) dd` over one output
    /// period is the window's weight `K` (main lobe and sidelobes) on the decimated noise's
    /// shape `S_dec(x) = sum_k |L(x + k fs_out) / L(0)|^2` (white noise at the ADC). 1 for
    /// every harmonic when the low-pass is flat over them.
    pub(crate) fn table_harmonic_noise_gains(
        &self,
        chain: &ChainResponse,
        freq_hz: f64,
        harmonics: usize,
        span_s: f64,
        hann: bool,
    ) -> Vec<f64> {
        let fs_out = self.fs_out_hz();
        let dc = chain.lowpass(0.0).norm_sqr();
        let k_max = (0.5 * self.fs_hz() / fs_out).floor() as i64;
        // The decimated noise's shape at x: outwards from x until the low-pass's weight is
        // below 1e-9 of the sum.
        let s_dec = |x: f64| {
            let mut sum = chain.lowpass(x).norm_sqr() / dc;
            for k in 1..=k_max {
                let f = k as f64 * fs_out;
                let l = (chain.lowpass(x + f).norm_sqr() + chain.lowpass(x - f).norm_sqr()) / dc;
                sum += l;
                if l < 1e-9 * sum {
                    break;
                }
            }
            sum
        };
        // I(f): the main lobe on a linear grid over |d| <= 4 / T, the sidelobes' mean beyond
        // on a grid of 64 points a decade in ln |d|, to fs_out / 2 either side.
        let integral = |f: f64| {
            let near = 4.0 / span_s;
            let half = 0.5 * fs_out;
            let mut sum = 0.0;
            let steps = 400;
            let lim = near.min(half);
            let dd = 2.0 * lim / steps as f64;
            for i in 0..=steps {
                let d = -lim + i as f64 * dd;
                let w = if i == 0 || i == steps { 0.5 } else { 1.0 };
                sum += w * s_dec(f + d) * window_weight(d * span_s, hann) * dd;
            }
            for sign in [1.0, -1.0] {
                sum = integrate_over_decades(sum, near, half, |d| {
                    s_dec(f + sign * d) * window_weight(d * span_s, hann)
                });
            }
            sum
        };
        let i0 = integral(0.0);
        (-(harmonics as i64)..=harmonics as i64)
            .map(|n| {
                let f = n as f64 * freq_hz;
                integral(f) / i0 * dc / chain.lowpass(f).norm_sqr()
            })
            .collect()
    }
}

/// The factors the variance of a rate table's amplitude reading takes over one harmonic's own
/// `r = S enbw / (T lo^2)`: `(G1, G2)` with the variance `G1 r + G2 r^2`, for the envelope the
/// read-out forms (`v`, harmonics `-M ..= M`), its smallest modulus `lo`, and each harmonic's
/// noise power per unit of the DC reading's (`gains`, harmonics `-N ..= N` read; the TIA's
/// gain across them included). With `u = 1 / V(theta)`, `U_q` and `W_q` the Fourier
/// coefficients of `u` and `u^2`, `psi` the argument of the phase's fundamental and `e_n`
/// each harmonic's noise (independent, circular, `g_n` per unit):
///
/// - first order: the phase `-arg V` moves by `-Im(dV u)`, whose fundamental takes `e_n`
///   through `U_{1-n}` and its conjugate through `U_{-1-n}`; along `e^{j psi}`,
///   `G1 = sum_n g_n |lo (U_{1-n} e^{-j psi} + U_{-1-n} e^{j psi})|^2`. A small swing (`V`
///   constant) gives `g_1 + g_-1`, the small-swing count's two harmonics.
/// - second order: `+Im((dV u)^2) / 2`, whose fundamental takes the products `e_n e_m`
///   through `W_{+-1-n-m}`: `G2 = lo^4 [sum_{n<m} 2 g_n g_m (|W_{1-n-m}|^2 + |W_{-1-n-m}|^2) +
///   sum_n g_n^2 (|W_{1-2n}|^2 + |W_{-1-2n}|^2)]`. Where the read-out's division leaves a far
///   harmonic's noise large, this is what a small swing's reading scatters by: a 200 deg/s
///   point read with 15 harmonics behind a 10 Hz low-pass scattered 12 times `G1`'s figure.
pub(crate) fn table_reading_gains(v: &[Complex64], lo: f64, gains: &[f64]) -> (f64, f64) {
    let m = v.len() / 2;
    let n = (gains.len() / 2) as i64;
    let points = (16 * v.len()).next_power_of_two().max(1024);
    // e^{j theta_g} on the grid; powers by repeated products (a validation estimate: the
    // roundings of 2N + 3 products are far below what it states), not a sine per term.
    let step: Vec<Complex64> = (0..points)
        .map(|g| Complex64::from_polar(1.0, core::f64::consts::TAU * g as f64 / points as f64))
        .collect();
    let power = |e: Complex64, k: i64| -> Complex64 {
        let mut p = Complex64::new(1.0, 0.0);
        let b = if k < 0 { e.conj() } else { e };
        for _ in 0..k.unsigned_abs() {
            p *= b;
        }
        p
    };
    // 1 / V(theta_g), V = sum_i v_i e^{j (i - M) theta}, by Horner's rule in e^{j theta}.
    let inv: Vec<Complex64> = step
        .iter()
        .map(|&e| {
            let x = v
                .iter()
                .rev()
                .fold(Complex64::new(0.0, 0.0), |acc, &h| acc * e + h);
            1.0 / (x * power(e, -(m as i64)))
        })
        .collect();
    // The Fourier coefficients q = -Q ..= Q of y(theta_g): running phasors e^{-j q theta_g}.
    let coefficients = |y: &[Complex64], q_max: i64| -> Vec<Complex64> {
        let mut p: Vec<Complex64> = step.iter().map(|&e| power(e, q_max)).collect();
        (-q_max..=q_max)
            .map(|_| {
                let c = y.iter().zip(&p).map(|(&a, &b)| a * b).sum::<Complex64>() / points as f64;
                for (pg, &e) in p.iter_mut().zip(&step) {
                    *pg *= e.conj();
                }
                c
            })
            .collect()
    };
    let u_all = coefficients(&inv, n + 1);
    let u = |q: i64| u_all[(q + n + 1) as usize];
    let inv2: Vec<Complex64> = inv.iter().map(|&y| y * y).collect();
    let w: Vec<f64> = coefficients(&inv2, 2 * n + 1)
        .iter()
        .map(|c| c.norm_sqr())
        .collect();
    let w2 = |q: i64| w[(q + 2 * n + 1) as usize];
    let g = |k: i64| gains[(k + n) as usize];
    // psi from the phase -arg V = arg(1 / V) on the same grid, unwrapped: its fundamental
    // (1 / pi) int phi e^{-j theta} d theta by the rectangle rule. A direction to project
    // onto, so this grid serves; the theory's read-out refines its own.
    let mut phase = Vec::with_capacity(points);
    let mut last = inv[0].arg();
    for y in &inv {
        let p = y.arg();
        let turned = p - last;
        last += turned - core::f64::consts::TAU * (turned / core::f64::consts::TAU).round();
        phase.push(last);
    }
    let fundamental: Complex64 = phase
        .iter()
        .zip(&step)
        .map(|(&p, &e)| p * e.conj())
        .sum::<Complex64>()
        * (2.0 / points as f64);
    let psi = fundamental.arg();
    let e = Complex64::from_polar(1.0, -psi);
    let first = (-n..=n)
        .map(|k| g(k) * (lo * (u(1 - k) * e + u(-1 - k) * e.conj())).norm_sqr())
        .sum();
    let mut second = 0.0;
    for a in -n..=n {
        second += g(a) * g(a) * (w2(1 - 2 * a) + w2(-1 - 2 * a));
        for b in a + 1..=n {
            second += 2.0 * g(a) * g(b) * (w2(1 - a - b) + w2(-1 - a - b));
        }
    }
    (first, lo.powi(4) * second)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A constant envelope (no swing): to first order only harmonics +-1 count, each with its
    /// gain; to second order the pairs whose sum is +-1.
    #[test]
    fn a_small_swing_counts_harmonics_one_either_side() {
        let a = Complex64::from_polar(2.5, 0.3);
        let mut v = vec![Complex64::new(0.0, 0.0); 7];
        v[3] = a;
        // A tiny swing, so the fundamental has an argument to take.
        v[4] = Complex64::new(0.0, 1e-9);
        let gains = [7.0, 5.0, 1.5, 1.0, 0.5, 3.0, 11.0];
        let (g1, g2) = table_reading_gains(&v, a.norm(), &gains);
        assert!((g1 - (1.5 + 0.5)).abs() < 1e-6, "{g1}");
        // Pairs summing to +1: (0, 1), (-1, 2), (-2, 3); to -1: (-1, 0), (-2, 1), (-3, 2).
        let p = (1.0 * 0.5 + 1.5 * 3.0 + 5.0 * 11.0) + (1.5 * 1.0 + 5.0 * 0.5 + 7.0 * 3.0);
        assert!(
            (g2 / (2.0 * p) - 1.0).abs() < 1e-6,
            "{g2} against {}",
            2.0 * p
        );
    }
}
