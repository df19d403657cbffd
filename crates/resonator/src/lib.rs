//! 2-DOF vibratory gyroscope plant, exactly discretised with the matrix exponential.
//!
//! State `x = [q1, q2, v1, v2]` (m, m/s), force per unit mass `u = [f1, f2]` (m/s^2):
//!
//! ```text
//! q1'' + (w1/Q1) q1' - 2 lambda Omega_z q2' + w1^2 q1 + k12 q2 = f1
//! q2'' + (w2/Q2) q2' + 2 lambda Omega_z q1' + w2^2 q2 + k12 q1 = f2
//! ```
//!
//! The DAC holds each drive sample for `Ts`, so the exact step is the zero-order-hold
//! discretisation `x[n+1] = Phi x[n] + Gamma u[n]` (THEORY.md sections 2 and 6). A rate that
//! varies in time uses a second-order expansion of the step about the design rate, so no
//! exponential is taken per sample.

mod discretise;
mod hold;
mod params;
mod plant;
mod steady;
mod table_held;
mod thermal;

pub use hold::hold_response;
pub use params::{ModeParams, ResonatorParams};
pub use plant::{PlantOutput, Resonator};
pub use steady::{continuous_steady_state, rate_table_steady_state};
pub use table_held::held_table_steady_state;
pub use thermal::{thermomechanical_accel_psd, thermomechanical_force_psd};

/// Stage name used in every [`gyroemu_core::ParamError`] of this crate.
pub const STAGE: &str = "resonator";
