//! Why writing a report failed.

use gyroemu_config::ConfigError;
use gyroemu_experiment::SweepError;
use gyroemu_io::IoError;
use gyroemu_plot::PlotError;

/// A report (or the runs it needs) failed.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A config (a preset, or one derived from the user's) is refused: bad input.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The emulation failed.
    #[error(transparent)]
    Sweep(#[from] SweepError),
    /// Writing a file failed.
    #[error(transparent)]
    Io(#[from] IoError),
    /// Rendering a figure failed.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// The run finished but some of its numbers cannot be trusted (a dead channel, a
    /// non-finite read-out): the outputs are written with those values null, and this says why.
    #[error("{0}")]
    Unreliable(String),
    /// Deleting a stale file failed.
    #[error("cannot delete `{path}`: {reason}")]
    Remove {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: std::io::Error,
    },
    /// Creating a folder failed.
    #[error("cannot create `{path}`: {reason}")]
    Dir {
        /// The folder.
        path: std::path::PathBuf,
        /// Why.
        reason: std::io::Error,
    },
}

/// Creates `dir` (and its parents).
pub(crate) fn create_dir(dir: &std::path::Path) -> Result<(), ReportError> {
    std::fs::create_dir_all(dir).map_err(|reason| ReportError::Dir {
        path: dir.to_path_buf(),
        reason,
    })
}

/// The problems of a sweep as one error, or nothing when there are none.
pub fn check_problems(what: &str, problems: &[String]) -> Result<(), ReportError> {
    if problems.is_empty() {
        return Ok(());
    }
    Err(ReportError::Unreliable(format!(
        "{what}: {} phase(s) refused, written as NaN/null:\n  {}",
        problems.len(),
        problems.join("\n  ")
    )))
}
