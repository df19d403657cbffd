//! The experiment description of gyroemu: a TOML config with units in every key, unknown keys
//! rejected and documented defaults; its parsing, its validation before any sample is
//! computed (every error names the key, the value and the rule, and a file's problems are
//! reported all at once), the embedded presets, and what it implies
//! ([`Config::board_params`], [`Config::plan_point`]).

mod config;
mod document;
mod error;
mod noise_table;
mod parse;
mod plan;
pub mod presets;
mod resolve;
mod rules;
mod schema;
mod validate;
mod validate_dac;
mod validate_montecarlo;
mod validate_noise;
mod validate_noise_phase;
mod validate_regime;
mod validate_resolution;
mod validate_settling;
mod validate_sweep;
mod validate_sweep_dac;
mod window_weight;

pub use config::{
    BoardConfig, Config, DeviceConfig, Distribution, DriveConfig, DumpConfig, ExperimentConfig,
    ExperimentKind, MonteCarloConfig, NoiseConfig, PllConfig, RateTable, SelfcalConfig, Spacing,
    SweepConfig, WindowKind, DEFAULT_SWEEP_POINTS,
};
pub use error::ConfigError;
pub use parse::{parse_config, parse_config_explained, plain_words};
pub use plan::sweep_grid;
pub use resolve::{
    Derived, DECIMATION_CANDIDATES, SWEEP_AVERAGE_TAUS, SWEEP_SETTLE_TAUS,
    SWEEP_SPAN_HALF_BANDWIDTHS,
};
pub use validate::{EXPERIMENT_WARNING, MAX_CORIOLIS_COUPLING, MAX_RUN_SAMPLES};
pub use validate_noise_phase::{phase_variance_rad2, NoisePhase, WARN_NOISE_PHASE_FRACTION};
pub use validate_regime::{MAX_HOLD_ERROR_MDEG, NODE_RANGE, WARN_HOLD_ERROR_MDEG};
pub use validate_resolution::MIN_RESOLVED_PHASE_MDEG;
pub use validate_sweep::{MAX_SWEEP_POINTS, MIN_POINTS_NEAR_RESONANCE, MIN_SWEEP_POINTS};
pub use validate_sweep_dac::WARN_SWEEP_DAC_REL;
