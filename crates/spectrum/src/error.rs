//! Why a spectrum cannot be computed.

/// A refused spectrum request; the message names the value and the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpectrumError {
    /// Fewer samples than one segment needs.
    #[error("{got} sample(s) given, a spectrum needs at least {min}")]
    TooShort {
        /// Samples given.
        got: usize,
        /// Samples needed.
        min: usize,
    },
    /// The segment length is out of range.
    #[error("segment length {segment} must be in 4..={len} (the samples given)")]
    Segment {
        /// Requested segment length.
        segment: usize,
        /// Samples given.
        len: usize,
    },
    /// The sample rate is not finite and positive.
    #[error("sample rate {0} Hz must be finite and > 0")]
    Rate(f64),
    /// A sample is NaN or infinite (a gap or an overflow in the recording).
    #[error("sample {index} is {value}: a spectrum needs finite samples")]
    NonFinite {
        /// Index of the first non-finite sample.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The power spectrum is beyond f64's range: a bin's power overflows (samples near 1e154
    /// and above), or the strongest is below the smallest normal number (samples near 1e-154
    /// and below).
    #[error(
        "the power spectrum is outside f64's range (2.2e-308 to 1.8e308): samples up to \
         {peak:e} have powers near {peak:e}^2"
    )]
    OutOfRange {
        /// The largest |sample|.
        peak: f64,
    },
}
