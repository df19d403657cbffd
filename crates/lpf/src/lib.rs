//! Low-pass decimator (Butterworth and lock-in biquad cascades) and compensated averager.
//!
//! Stage 1 of the readout (THEORY section 6) low-passes the mixer products; stage 2 averages
//! over a whole number of half modulation periods (section 7), which over 5e8 samples needs
//! compensated summation.
#![warn(missing_docs)]

mod averager;
mod bank;
mod cascade;
mod decimator;
mod design;
mod kahan;
mod lowpass;
mod section;

pub use averager::{Averager, Window, MAX_LANES};
pub use bank::{BiquadPair, LowPassBank};
pub use decimator::{DecimateMode, Decimator};
pub use design::{LowPassDesign, MAX_ORDER};
pub use kahan::KahanSum;
pub use lowpass::LowPass;

/// The stage name used in this crate's parameter errors.
pub(crate) const STAGE: &str = "lpf";
