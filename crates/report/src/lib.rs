//! What gyroemu writes: the results table, summary and paper-style figure of a sweep, the
//! self-calibration's files, a production lot's files, and the `reproduce` job (the paper's figures from the embedded
//! presets). Every file is written atomically (`gyroemu-io`) and every function returns the
//! paths it wrote, so a program can list them.

pub mod dump_figures;
pub mod dump_set;
pub mod dump_stats;
mod error;
pub mod freq_sweep_report;
pub mod montecarlo_report;
pub mod reproduce;
pub mod selfcal_report;
pub mod sweep_report;

pub use dump_figures::{dump_figures, write_dump_figures, DumpFigures};
pub use dump_set::{read_dump_set, DumpSet};
pub use dump_stats::{channel_stats, inspect_text, ChannelStats};
pub use error::{check_problems, ReportError};
pub use freq_sweep_report::{write_freq_sweep, FREQ_SWEEP_COLUMNS, FREQ_SWEEP_FILES};
pub use montecarlo_report::{write_lot, LOT_FILES};
pub use reproduce::{plan_reproduce, reproduce, ReproducePlan};
pub use selfcal_report::{write_selfcal, SelfcalFiles, SELFCAL_ANALYSIS_FILES};
pub use sweep_report::{health_json, run_title, write_run, write_run_with, RUN_FILES};
