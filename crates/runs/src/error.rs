//! Why a run, a resume or a merge stopped.

use gyroemu_experiment::SweepError;
use gyroemu_report::ReportError;

/// A run lifecycle's failure, typed by what the user should do about it.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The user's input is refused (a bad shard spec, a folder of another config, a merge
    /// with shards missing): fix the input; nothing was computed.
    #[error("{0}")]
    BadInput(String),
    /// Stopped by Ctrl-C or SIGTERM after saving the finished points: rerun to resume.
    #[error("{0}")]
    Interrupted(String),
    /// The emulation failed after validation (e.g. the chain overflowed).
    #[error("emulation failed: {0}")]
    Sweep(#[from] SweepError),
    /// Writing the outputs failed, or they hold numbers that cannot be trusted
    /// ([`ReportError::Unreliable`]: written as null, the run exits non-zero).
    #[error(transparent)]
    Report(#[from] ReportError),
    /// A file of the output folder could not be read, written or removed.
    #[error("{context}: {source}")]
    Io {
        /// What was being done, with the path.
        context: String,
        /// The system's reason.
        source: std::io::Error,
    },
}

impl RunError {
    /// A file-system failure while doing `context`.
    pub(crate) fn io(context: impl Into<String>) -> impl FnOnce(std::io::Error) -> Self {
        let context = context.into();
        move |source| RunError::Io { context, source }
    }
}
