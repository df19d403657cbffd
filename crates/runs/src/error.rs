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
    /// The emulation failed after validation (e.g. the chain overflowed). Its text is in the
    /// message, so it is not also the error's `source()` (a chain printer such as anyhow's
    /// `{:#}` would print it twice).
    #[error("emulation failed: {0}")]
    Sweep(SweepError),
    /// Writing the outputs failed.
    #[error(transparent)]
    Report(#[from] ReportError),
    /// The outputs were written, but they hold numbers that cannot be trusted (refused phases,
    /// untrusted devices: [`ReportError::Unreliable`], written as NaN / null): the run exits
    /// non-zero and lists `files`, what it wrote.
    #[error("{error}")]
    Refused {
        /// Boxed: the error type stays small on every other path.
        error: Box<ReportError>,
        files: Vec<std::path::PathBuf>,
        /// A lot's figures over its trusted devices, which `montecarlo.json` holds: printed
        /// as a completed lot prints them (an 85 % reliable lot had shown only its errors).
        lot: Option<Box<gyroemu_analysis::montecarlo::LotSummary>>,
    },
    /// A failure (`cause`) after which the manifest could not be updated either: it still
    /// says `running`.
    #[error("{cause}; the manifest `{}` could not be updated either ({why}): it still says `running`", manifest.display())]
    Unrecorded {
        cause: Box<RunError>,
        manifest: std::path::PathBuf,
        why: String,
    },
    /// A file of the output folder could not be read, written or removed.
    #[error("{context}: {reason}")]
    Io {
        /// What was being done, with the path.
        context: String,
        /// The system's reason: in the message, so not the error's `source()` (not named
        /// `source`, which would make it one and print it twice in a chain).
        reason: std::io::Error,
    },
}

impl From<SweepError> for RunError {
    fn from(e: SweepError) -> Self {
        RunError::Sweep(e)
    }
}

impl RunError {
    /// `files` when `check` passed; else a [`RunError::Refused`] carrying them (the outputs
    /// are written, the numbers `check` names are not to be trusted).
    pub(crate) fn refused_unless(
        check: Result<(), ReportError>,
        files: Vec<std::path::PathBuf>,
    ) -> Result<Vec<std::path::PathBuf>, Self> {
        match check {
            Ok(()) => Ok(files),
            Err(error) => Err(RunError::Refused {
                error: Box::new(error),
                files,
                lot: None,
            }),
        }
    }

    /// This error with a lot's summary attached when it is a [`RunError::Refused`].
    pub(crate) fn with_lot(mut self, summary: &gyroemu_analysis::montecarlo::LotSummary) -> Self {
        if let RunError::Refused { lot, .. } = &mut self {
            *lot = Some(Box::new(summary.clone()));
        }
        self
    }

    /// A file-system failure while doing `context`.
    pub(crate) fn io(context: impl Into<String>) -> impl FnOnce(std::io::Error) -> Self {
        let context = context.into();
        move |reason| RunError::Io { context, reason }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The message followed by every `source()` below it, as anyhow's `{:#}` prints it.
    fn chain(e: &dyn std::error::Error) -> String {
        let mut text = e.to_string();
        let mut next = e.source();
        while let Some(s) = next {
            text += &format!(": {s}");
            next = s.source();
        }
        text
    }

    #[test]
    fn a_chain_names_each_cause_once() {
        let os = std::io::Error::new(std::io::ErrorKind::PermissionDenied, "Permission denied");
        let io = RunError::io("cannot create `o/gyroemu.lock`")(os);
        assert_eq!(
            chain(&io),
            "cannot create `o/gyroemu.lock`: Permission denied"
        );
        let sweep = RunError::from(SweepError::Output("disk full".into()));
        assert_eq!(
            chain(&sweep),
            "emulation failed: writing the outputs failed: disk full"
        );
    }
}
