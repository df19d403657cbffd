//! `gyroemu run CONFIG --out DIR [--shard I/N] [--force]`.

use crate::cmd::out_args::OutArgs;
use crate::input::{list_written, load_config};
use crate::progress::Terminal;
use anyhow::Result;
use gyroemu_runs::{check_run, run, RunOutcome, RunRequest};
use std::path::Path;

/// Runs the points not yet saved in the output folder, then writes the results.
pub fn run_command(config: &Path, a: &OutArgs) -> Result<()> {
    let cfg = load_config(config)?;
    let shard = a.shard()?;
    // Every refusal that needs nothing computed comes before the output folder is created,
    // so a refused run leaves no folder behind.
    check_run(&cfg, &a.out, shard.as_ref(), a.force)?;
    let (cancel, _lock) = a.open(shard.as_ref())?;
    let req = RunRequest {
        config: &cfg,
        out: &a.out,
        shard,
        force: a.force,
        cancel,
        on_saved: None,
    };
    match run(&req, &Terminal)? {
        RunOutcome::Complete(files) => list_written(&a.out, &files),
        RunOutcome::ShardComplete { next } => note!("shard complete; {next}"),
    }
    Ok(())
}
