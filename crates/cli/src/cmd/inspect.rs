//! `gyroemu inspect DUMP [--out DIR]`.

use crate::input::{list_written, print_out, BadInput};
use anyhow::Result;
use gyroemu_report::{dump_figures, inspect_text, read_dump_set};
use std::path::Path;

/// Prints each channel's RMS, peak and strongest tones, and renders `signals.png` and
/// `spectrum.png` beside the dump (or into `out`).
pub fn inspect_command(dump: &Path, out: Option<&Path>) -> Result<()> {
    let set = read_dump_set(dump).map_err(|e| BadInput(e.to_string()))?;
    // Laid out and checked before anything is written or printed.
    let figures = dump_figures(&set).map_err(|e| BadInput(format!("{}: {e}", dump.display())))?;
    let dir = out.unwrap_or(&set.dir);
    gyroemu_runs::prepare_out(dir)?;
    print_out(&inspect_text(&set))?;
    let files = figures.write(dir)?;
    list_written(dir, &files);
    Ok(())
}
