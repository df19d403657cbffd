//! Numerically controlled oscillator with a 64-bit integer phase accumulator, and the board's
//! phase shifter.
//!
//! The phase is a `u64` word in units of 2^-64 turn, advanced with wrapping integer addition,
//! so after N steps it is exactly `phase0 + N*step mod 2^64`: 500 s at 1 MS/s (5e8 steps)
//! accumulates no drift (THEORY section 7). The phasor `e^{j phase}` comes from a static table
//! of 512 unit phasors (stored as double-doubles, built once by a double-double Taylor series)
//! indexed by the top 9 bits, times `e^{jr}` for the residual angle `|r| <= pi/512` by a short
//! Taylor polynomial: plain IEEE arithmetic only (no libm), so the same bits on every
//! platform, and within about 6e-17 of the true value per component.

#![warn(missing_docs)]

mod dd;
mod nco;
mod rotating;
mod shifter;
mod trig;
mod word;

pub use nco::Nco;
pub use rotating::{RotatingNco, RESYNC};
pub use shifter::PhaseShifter;
pub use trig::{phasor_of_word, TABLE_BITS};
pub use word::{ratio_to_word, turns_of_word};
