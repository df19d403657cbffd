//! `gyroemu merge DIR`.

use crate::input::{command_line, list_written, listing_refused, print_out};
use crate::progress::Terminal;
use crate::signals;
use anyhow::Result;
use gyroemu_runs::{lock_out, LockScope};
use std::path::Path;

/// Checks the shards in `dir` and writes the results a one-machine run would have written.
pub fn merge_command(dir: &Path) -> Result<()> {
    signals::install(false);
    // A missing folder is the merge's own refusal, with its hint.
    let _lock = if dir.is_dir() {
        Some(lock_out(
            dir,
            &command_line(),
            LockScope::Folder,
            &Terminal,
        )?)
    } else {
        None
    };
    let merged = listing_refused(gyroemu_runs::merge(dir, &Terminal), dir, None)?;
    // A lot's figures, as `montecarlo` prints them on one machine.
    if let Some(lot) = &merged.lot {
        print_out(&crate::lot_text::summary_text(lot))?;
    }
    list_written(dir, &merged.files);
    Ok(())
}
