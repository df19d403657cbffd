//! Spectral analysis of recorded signals: Welch power spectra and the tones in them.
//!
//! - [`welch`]: periodic Hann window, 50 % overlap, no detrending (a DC level is a signal here),
//!   one-sided. [`Psd::power`] is the power-spectrum scaling (a sinusoid of amplitude `A` centred
//!   on a bin reads `A^2/2`, its mean square); [`Psd::density`] divides it by the window's
//!   equivalent noise bandwidth ([`Psd::enbw_hz`] = 1.5 fs/L for Hann), giving unit^2/Hz
//!   (white noise of variance s^2 reads `2 s^2 / fs`).
//! - [`find_tones`]: local maxima of the power spectrum, frequency refined between bins and
//!   level corrected for scalloping with the Hann window's exact finite-length response.

mod error;
mod tones;
mod welch;
mod window;

pub use error::SpectrumError;
pub use tones::{
    find_tones, tone_near, unresolved, Tone, EDGE_BINS, SPREAD_MAX, SPREAD_MIN_SEGMENTS,
};
pub use welch::{default_segment_len, power_of_two_scale, scale_exponent, welch, Psd};
pub use window::{hann, hann_response, HANN_ENBW_BINS};
