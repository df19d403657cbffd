//! The drive side of the board: the AM modulator that makes the two electrode forces (the
//! Coriolis pair `F1 cos w0t`, `F2 sin w0t`, or the rotating pair of THEORY eq. 4), and the
//! drive DAC (optional quantisation; its zero-order hold is realised by the plant's ZOH
//! discretisation and reported by [`Dac`]'s frequency response).

#![warn(missing_docs)]

mod dac;
mod modulator;
mod quantizer;

pub use dac::Dac;
pub use modulator::{AmInput, AmModulator, DrivePattern};
pub use quantizer::Quantizer;
