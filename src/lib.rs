//! gyroemu: a sample-level emulator of the mixed-signal readout board of a MEMS vibratory
//! gyroscope and its electrostatic self-calibration (Casinovi et al., MEMS 2012).
//!
//! This facade re-exports the crates by layer (see `docs/architecture.md`): the stage crates,
//! one per stage of the board, sharing the [`Stage`] interface; the board; the config; the
//! theory; the experiments and analyses; the run lifecycle and the reports.

pub use gyroemu_am as am;
pub use gyroemu_analysis as analysis;
pub use gyroemu_board as board;
pub use gyroemu_config as config;
pub use gyroemu_core as core;
pub use gyroemu_core::{Complex64, ParamError, Response, Sample, Stage};
pub use gyroemu_experiment as experiment;
pub use gyroemu_lpf as lpf;
pub use gyroemu_mixer as mixer;
pub use gyroemu_nco as nco;
pub use gyroemu_pll as pll;
pub use gyroemu_resonator as resonator;
pub use gyroemu_theory as theory;
pub use gyroemu_tia as tia;
