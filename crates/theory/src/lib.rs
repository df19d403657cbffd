//! The exact theory of THEORY.md in one place: the closed forms of the two experiments, the
//! theory of what each experiment measures on an ideal or imperfect device, and the periodic
//! steady state under a sinusoidal rate table. Used for theory overlays and tests, never in
//! place of the emulation. Angles in radians, rates in rad/s, lag positive.

pub mod closed_form;
mod device;
mod plant_modes;
pub mod quantiser;

pub use closed_form::*;
pub use device::{converged_envelopes, DrivenDevice, MAX_THEORY_HARMONICS, MEMO_LEN};
pub use plant_modes::{coupled_modes, held_response};
pub use quantiser::{quantiser_bias_bound, quantiser_phase_bound_rad};
