//! `gyroemu reproduce --out DIR [--quick]`.

use crate::input::{command_line, list_written, BadInput};
use crate::progress::Terminal;
use crate::signals;
use anyhow::Result;
use gyroemu_report::{plan_reproduce, reproduce, ReportError};
use gyroemu_runs::{lock_out, prepare_out, LockScope, OutLock};
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
    prepare_out(out)?;
    let _lock = lock_out(out, &command_line(), LockScope::Folder, &Terminal)?;
    let _preset_locks = lock_preset_folders(out, &plan.preset_folders())?;
    let rate = gyroemu_experiment::work::measured_throughput(plan.first_config());
    note!("{}", plan.work().describe(Some(rate)));
    let files = reproduce(&plan, out, &Terminal)?;
    list_written(out, &files);
    Ok(())
}

/// Each preset's folder below `out`, checked before any is made (a file in the way is named,
/// and nothing is created), then created and locked: a `run` writing into one of them holds
/// its lock, and reproduce wrote over its files.
fn lock_preset_folders(out: &Path, presets: &[&str]) -> Result<Vec<OutLock>> {
    for p in presets {
        let dir = out.join(p);
        if dir.exists() && !dir.is_dir() {
            return Err(BadInput(format!(
                "`{}` is a file, not a folder: reproduce writes the {p} preset's files there; move it away",
                dir.display()
            ))
            .into());
        }
    }
    let mut locks = Vec::new();
    for p in presets {
        let dir = out.join(p);
        prepare_out(&dir)?;
        locks.push(lock_out(
            &dir,
            &command_line(),
            LockScope::Folder,
            &Terminal,
        )?);
    }
    Ok(locks)
}
