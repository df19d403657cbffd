//! Pretty JSON files (run parameters, results summaries).

use crate::atomic::atomic_stream;
use crate::IoError;
use std::io::Write;
use std::path::Path;

/// Atomically writes `value` as pretty-printed JSON with a trailing newline.
/// Note: serde_json writes non-finite f64 as `null`.
pub fn write_json<T: serde::Serialize + ?Sized>(path: &Path, value: &T) -> Result<(), IoError> {
    atomic_stream(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value).map_err(|source| IoError::Json {
            path: path.to_path_buf(),
            reason: source,
        })?;
        w.write_all(b"\n").map_err(|source| IoError::Write {
            path: path.to_path_buf(),
            reason: source,
        })
    })
}
