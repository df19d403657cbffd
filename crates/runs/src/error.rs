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
    /// Another live process holds the output folder's lock (named in the message): wait or
    /// choose another folder; nothing was written.
    #[error("{0}")]
    Locked(String),
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
    /// A failure (`cause`) after which the manifest could not be updated either: it still
    /// says `running`.
    #[error("{cause}; the manifest `{}` could not be updated either ({why}): it still says `running`", manifest.display())]
    Unrecorded {
        cause: Box<RunError>,
        manifest: std::path::PathBuf,
        why: String,
    },
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
