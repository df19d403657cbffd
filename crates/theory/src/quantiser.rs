//! The systematic error of a rounding quantiser (the board's ADC) and the phase error it can
//! leave on a carrier. Without noise the error is a deterministic sawtooth of the input, so on a
//! carrier sampled at a fixed number of points per period it repeats every period and never
//! averages out; Gaussian noise at the input smooths it, term by term of its Fourier series.

/// The largest systematic error of `x -> step * round(x / step)` when the input carries
/// Gaussian noise of rms `sigma`: the maximum over x of |E[Q(x + n)] - x|.
///
/// The error Q(x) - x is the sawtooth sum_k (-1)^k step/(pi k) sin(2 pi k x / step); noise
/// multiplies each term by exp(-2 pi^2 k^2 sigma^2 / step^2) (the Gaussian's characteristic
/// function), so the maximum is at most the sum of the terms' amplitudes, and never more than
/// step/2 (the noiseless sawtooth's).
pub fn quantiser_bias_bound(step: f64, sigma: f64) -> f64 {
    let half = 0.5 * step;
    if sigma.is_nan() || sigma <= 0.0 {
        return half;
    }
    let r = 2.0 * (core::f64::consts::PI * sigma / step).powi(2);
    let mut sum = 0.0;
    for k in 1..=100_000u32 {
        let k = f64::from(k);
        let term = (step / (core::f64::consts::PI * k)) * (-r * k * k).exp();
        sum += term;
        if sum >= half {
            return half;
        }
        if term <= 1e-17 * sum {
            break;
        }
    }
    sum
}

/// The largest phase error, rad, that a quantiser bias of `bias` (see
/// [`quantiser_bias_bound`]) can leave on the fundamental of a carrier of amplitude
/// `amplitude`: the bias moves the fundamental's phasor by at most 2 x bias.
pub fn quantiser_phase_bound_rad(bias: f64, amplitude: f64) -> f64 {
    (2.0 * bias / amplitude).min(1.0).asin()
}
