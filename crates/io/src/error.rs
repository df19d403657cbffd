//! The error type of every writer in this crate.

use std::path::PathBuf;

/// Failure of an output write. Every message names the file and the step that failed, so a
/// user can act on it without a backtrace.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// The target path has no file name (e.g. `/` or `..`), so no temporary sibling can be named.
    #[error("cannot write {}: the path has no file name", .path.display())]
    NoFileName {
        /// Requested target.
        path: PathBuf,
    },
    /// The temporary file next to the target could not be created (missing directory, permissions).
    #[error("cannot create a temporary file next to {}: {reason}", .path.display())]
    TempCreate {
        /// Requested target.
        path: PathBuf,
        /// Underlying OS error.
        reason: std::io::Error,
    },
    /// Writing, flushing or syncing the temporary file failed.
    #[error("cannot write data for {}: {reason}", .path.display())]
    Write {
        /// Requested target.
        path: PathBuf,
        /// Underlying OS error.
        reason: std::io::Error,
    },
    /// Renaming the finished temporary file over the target failed.
    #[error("cannot move the finished temporary file onto {}: {reason}", .path.display())]
    Persist {
        /// Requested target.
        path: PathBuf,
        /// Underlying OS error.
        reason: std::io::Error,
    },
    /// JSON serialisation failed (e.g. a map with non-string keys).
    #[error("cannot serialise JSON for {}: {reason}", .path.display())]
    Json {
        /// Requested target.
        path: PathBuf,
        /// serde_json's error.
        reason: serde_json::Error,
    },
    /// The csv crate failed while writing a record.
    #[error("cannot write CSV {}: {reason}", .path.display())]
    Csv {
        /// Requested target.
        path: PathBuf,
        /// csv's error.
        reason: csv::Error,
    },
    /// A CSV row does not have as many cells as the header.
    #[error("cannot write CSV {}: row {row} has {got} cells but the header has {expected}", .path.display())]
    CsvShape {
        /// Requested target.
        path: PathBuf,
        /// Zero-based data row index.
        row: usize,
        /// Cells in that row.
        got: usize,
        /// Header columns.
        expected: usize,
    },
    /// hound failed while writing the WAV.
    #[error("cannot write WAV {}: {reason}", .path.display())]
    Wav {
        /// Requested target.
        path: PathBuf,
        /// hound's error.
        reason: hound::Error,
    },
    /// The WAV request is malformed (no channels, unequal lengths, zero rate...).
    #[error("cannot write WAV {}: {reason}", .path.display())]
    WavInvalid {
        /// Requested target.
        path: PathBuf,
        /// What is wrong with the request.
        reason: String,
    },
    /// The WAV would exceed the 4 GiB RIFF size limit (hound would silently overflow its u32 counters).
    #[error(
        "cannot write WAV {}: {channels} channel(s) x {frames} frame(s) x 4 bytes = {data_bytes} bytes of samples, \
         over the 32-bit RIFF limit of {limit_bytes} bytes; record a shorter window or fewer channels",
        .path.display()
    )]
    WavTooLarge {
        /// Requested target.
        path: PathBuf,
        /// Number of channels.
        channels: u64,
        /// Samples per channel.
        frames: u64,
        /// Sample bytes that would be written.
        data_bytes: u64,
        /// Largest admissible sample byte count.
        limit_bytes: u64,
    },
    /// The SigMF request is malformed (no channels, unequal lengths, bad rate, names not matching).
    #[error("cannot write SigMF recording {}: {reason}", .path.display())]
    SigmfInvalid {
        /// Requested data file (`<stem>.sigmf-data`).
        path: PathBuf,
        /// What is wrong with the request.
        reason: String,
    },
    /// A caller-supplied producer (e.g. a PNG renderer) failed while filling the temporary file.
    #[error("cannot produce {}: {reason}", .path.display())]
    Producer {
        /// Requested target.
        path: PathBuf,
        /// The producer's error.
        reason: Box<dyn std::error::Error + Send + Sync>,
    },
    /// A recording cannot be read back (missing, malformed, or not what its metadata says).
    #[error("cannot read {}: {reason}", .path.display())]
    Read {
        /// The file that was being read.
        path: PathBuf,
        /// What is wrong, naming the key or line.
        reason: String,
    },
}
