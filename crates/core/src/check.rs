//! The stage contract, checked: one harness that every stage's tests run (gyroemu issue 13,
//! after RustFFT's `check_fft_algorithm` and rubato's test macros), so there is one way to
//! check a stage. Behind the cargo feature `check`; a stage crate enables it for its tests
//! only (`gyroemu-core = { workspace = true, features = ["check"] }` in `[dev-dependencies]`).
//!
//! * [`tick_vs_process`]: [`Stage::process`](crate::Stage::process) on blocks of 0, 1, odd,
//!   prime and large sizes gives the bits of [`Stage::tick`](crate::Stage::tick), and touches
//!   only the common prefix of input and output.
//! * [`reset_restores`]: after [`Stage::reset`](crate::Stage::reset) a used stage gives the bits
//!   of a fresh clone.
//! * [`lanes_match`]: every lane of an `f64x4` stage gives the bits of the `f64` stage fed that
//!   lane's input.
//! * [`lane_replaced_matches`]: a lane reset or replaced mid-run (a board's lane refilled with
//!   another operating point) gives the bits of a fresh `f64` stage from there, and the other
//!   lanes keep theirs.
//! * [`response_matches_impulse`]: the DFT of the (decayed) impulse response equals
//!   [`Response::response`](crate::Response::response) at the DFT bins, magnitude and phase.
//! * [`latency_matches`] and [`latency_matches_response`]:
//!   [`Stage::latency_samples`](crate::Stage::latency_samples) is the DC group delay of the
//!   impulse response (`sum n h[n] / sum h[n]`) and the phase slope of the response at DC.
//!
//! Inputs come from a seeded [`Gen`] through a closure the caller writes for its stage's input
//! type, so every run sees the same inputs. Outputs are compared bit for bit as [`Bits`]; a
//! `view` closure maps an output type defined in a stage crate (which cannot implement
//! [`Bits`] there) to tuples and arrays of samples; [`same`] is the view of an output that
//! already is [`Bits`]. The linear checks see a stage through an *adapter*: a closure from one
//! real input sample to one real output sample (e.g. the force on mode 1 to the displacement
//! of mode 1), so a stage with several inputs and outputs is checked one path at a time.
//!
//! Every check panics on failure, with a message naming the stage, the check, the sample index
//! or frequency, and both values.

mod bits;
mod gen;
mod impulse;
mod lanes;
mod process;
mod reset;

pub use bits::{same, Bits};
pub use gen::Gen;
pub use impulse::{
    latency_matches, latency_matches_response, response_matches_impulse, FnResponse,
};
pub use lanes::{lane_replaced_matches, lanes_match};
pub use process::{tick_vs_process, BLOCK_SIZES};
pub use reset::reset_restores;

/// The seed of every check's [`Gen`]: fixed, so a failure reproduces.
pub const SEED: u64 = 0x5EED_C0DE_0013_0003;

#[cfg(test)]
mod tests;
