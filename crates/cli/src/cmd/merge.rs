//! `gyroemu merge DIR`.

use crate::input::list_written;
use crate::progress::Terminal;
use anyhow::Result;
use std::path::Path;

/// Checks the shards in `dir` and writes the results a one-machine run would have written.
pub fn merge_command(dir: &Path) -> Result<()> {
    let files = gyroemu_runs::merge(dir, &Terminal)?;
    list_written(dir, &files);
    Ok(())
}
