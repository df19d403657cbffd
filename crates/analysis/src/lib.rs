//! Analyses built from sweeps of the emulated board, each run sample by sample: the
//! self-calibration itself (the scale factor from the rotating excitation alone against the
//! virtual rate table), the Allan deviation of the zero-rate output, the error against the
//! averaging time, a temperature drift, the mechanical bandwidth of a rate table, and a
//! production lot's self-calibration errors (Monte Carlo over tolerances).

pub mod allan;
pub mod bandwidth;
pub mod freq_response;
pub mod matrix_fit;
pub mod montecarlo;
pub mod resonance_fit;
pub mod selfcal;
pub mod selfcal_analyses;
pub mod selfcal_combined;
mod selfcal_run;
mod slope_fit;
pub mod stepped_sine;

pub use freq_response::{run_frequency_response, FrequencyResponse};
pub use selfcal_run::{run_selfcal, selfcal_work, SelfcalReport};
pub use stepped_sine::stepped_sine_work;
