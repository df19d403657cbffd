//! `gyroemu reproduce --out DIR [--quick]`.

use crate::input::{command_line, list_written, BadInput};
use crate::progress::Terminal;
use crate::signals;
use anyhow::Result;
use gyroemu_report::{plan_reproduce, reproduce, ReportError};
use gyroemu_runs::{lock_out, lock_subfolders, prepare_out, refuse_runs_under, LockScope};
use std::path::Path;

/// Reproduces the paper's figures from the embedded presets into `out`.
pub fn reproduce_command(out: &Path, quick: bool) -> Result<()> {
    // Every preset validated before the first sample.
    let plan = plan_reproduce(quick).map_err(|e| match e {
        ReportError::Config(c) => anyhow::Error::new(BadInput(c.to_string())),
        e => e.into(),
    })?;
    for w in &plan.warnings {
        note!("warning: {w}");
    }
    signals::install(false);
    // The folders are checked and locked before any sample (the throughput measure included).
    refuse_runs_under(out, &plan.preset_folders())?;
    prepare_out(out)?;
    let _lock = lock_out(out, &command_line(), LockScope::Folder, &Terminal)?;
    let _preset_locks = lock_subfolders(out, &plan.preset_folders(), &command_line(), &Terminal)?;
    let rate = gyroemu_experiment::work::measured_throughput(plan.heaviest_config());
    note!("{}", plan.work().describe(Some(rate)));
    // Each output folder synced once at the end, not after every file renamed into it, and
    // each file synced and renamed by a thread of its own, not by the worker that wrote it.
    let files = gyroemu_io::with_deferred_dir_sync(|| {
        gyroemu_io::with_background_persist(|| reproduce(&plan, out, &Terminal))
    })?;
    list_written(out, &files);
    Ok(())
}
