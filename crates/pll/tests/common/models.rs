//! The linear models both loops are checked against: the continuous second-order step
//! response (analytic) and the sampled loop around the envelope's first-order lag (by
//! recursion), with or without the demodulation low-pass in it.

use super::Setup;
use core::f64::consts::TAU;
use gyroemu_core::Stage;

/// The continuous loop's response to a unit step of its target (the PLL's carrier to a step
/// of the resonance, the AGC's log amplitude to a step of the log setpoint; crate docs),
/// `zeta < 1`: `1 - e^{-zeta wn t} (cos wd t + ((1/tau - zeta wn) / wd) sin wd t)`.
pub fn continuous_step(t: f64, natural_hz: f64, zeta: f64, tau: f64) -> f64 {
    let wn = TAU * natural_hz;
    let sigma = zeta * wn;
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    1.0 - (-sigma * t).exp() * ((wd * t).cos() + (1.0 / tau - sigma) / wd * (wd * t).sin())
}

/// How a loop closes around the lag: the lag's input from the controller output `c`, the
/// error from the measured state `m`, and the controller output from the PI's `Kp e + I`.
pub struct LoopShape {
    pub drive: fn(f64, f64) -> f64,
    pub error: fn(f64) -> f64,
    pub output: fn(f64) -> f64,
}

/// The PLL after a unit step of the resonance: the lag is the envelope's phase
/// `phi' = -(phi + 2 pi tau (y - 1)) / tau`, the error the phase, `y = (Kp e + I) / 2 pi`.
pub const PLL: LoopShape = LoopShape {
    drive: |y, tau| -TAU * tau * (y - 1.0),
    error: |m| m,
    output: |u| u / TAU,
};

/// The AGC after a unit step of the log setpoint: the lag is the log amplitude
/// `x' = -(x - ln g) / tau`, the error `1 - x`, `ln g = Kp e + I`.
pub const AGC: LoopShape = LoopShape {
    drive: |lg, _| lg,
    error: |m| 1.0 - m,
    output: |u| u,
};

/// The sampled linear loop after the step, `(measured state, controller output)` at each of
/// `n` updates: per step `h` the lag integrates exactly, `x <- alpha x + (1 - alpha) drive`,
/// `alpha = e^{-h/tau}`, the drive held from the last update; after each update
/// `e = error(m)`, `I += Ki T e`, `c = output(Kp e + I)`. Without `lowpass`, `h = T` and
/// `m = x`; with it, `h` is one input sample and `m` is `x` through the demodulation low-pass
/// (the real stage; for small signals the phase, or log amplitude, of a low-passed phasor is
/// the low-passed phase), taken at the block's last sample: the model with the low-pass in it.
pub fn sampled_loop(
    s: &Setup,
    shape: &LoopShape,
    kp: f64,
    ki_t: f64,
    n: usize,
    lowpass: bool,
) -> Vec<(f64, f64)> {
    let (sub, h) = if lowpass {
        (s.m, 1.0 / s.fs_hz)
    } else {
        (1, 1.0 / s.update_rate_hz())
    };
    let tau = s.tau_s();
    let alpha = (-h / tau).exp();
    let mut lpf = s.lowpass();
    let (mut x, mut integ, mut c) = (0.0f64, 0.0f64, 0.0f64);
    (0..n)
        .map(|_| {
            let mut m = 0.0;
            for _ in 0..sub {
                if lowpass {
                    m = lpf.tick(x);
                }
                x = alpha * x + (1.0 - alpha) * (shape.drive)(c, tau);
            }
            if !lowpass {
                m = x;
            }
            let e = (shape.error)(m);
            integ += ki_t * e;
            c = (shape.output)(kp * e + integ);
            (m, c)
        })
        .collect()
}

/// The largest `|a - b|` over the common length.
pub fn worst_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}
