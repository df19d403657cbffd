//! The experiment layer of gyroemu: the config, the board assembled from the stage crates and
//! run sample by sample, the Coriolis and rotating-excitation sweeps, and the exact theory
//! that the figures overlay.

pub mod allan;
pub mod bench;
pub mod board;
pub mod checkpoint;
pub mod config;
pub mod fit;
pub mod presets;
pub mod probe;
pub mod selfcal;
pub mod selfcal_analyses;
pub mod sweep;
pub use gyroemu_theory as theory;
pub mod validate;
mod validate_noise;

pub use config::{Config, ExperimentKind, RateTable, WindowKind};
pub use sweep::{run_sweep, PointResult, SweepError, SweepResult};
pub use validate::{parse_config, ConfigError};
