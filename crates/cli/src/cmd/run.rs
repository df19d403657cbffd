//! `gyroemu run CONFIG --out DIR [--shard I/N] [--force]`.

use crate::input::{command_line, list_written, load_config};
use crate::progress::Terminal;
use crate::signals;
use anyhow::Result;
use gyroemu_runs::{lock_out, prepare_out, resolve_shard, run, LockScope, RunOutcome, RunRequest};
use std::path::Path;

/// The arguments of `gyroemu run`.
pub struct RunArgs<'a> {
    /// The config file.
    pub config: &'a Path,
    /// The output folder.
    pub out: &'a Path,
    /// `--shard I/N`.
    pub shard: Option<&'a str>,
    /// `--shard-count N` (with `JOB_COMPLETION_INDEX` or a Slurm array).
    pub shard_count: Option<usize>,
    /// `--force`: delete results of another config found in the output folder.
    pub force: bool,
}

/// Runs the points not yet saved in the output folder, then writes the results.
pub fn run_command(a: &RunArgs) -> Result<()> {
    let cfg = load_config(a.config)?;
    let shard = resolve_shard(a.shard, a.shard_count, &|k| std::env::var(k).ok())?;
    let cancel = signals::install(true);
    prepare_out(a.out)?;
    let scope = shard
        .as_ref()
        .map_or(LockScope::Folder, |s| LockScope::Shard {
            index: s.index,
            count: s.count,
        });
    let _lock = lock_out(a.out, &command_line(), scope, &Terminal)?;
    let req = RunRequest {
        config: &cfg,
        out: a.out,
        shard,
        force: a.force,
        cancel,
        on_saved: None,
    };
    match run(&req, &Terminal)? {
        RunOutcome::Complete(files) => list_written(a.out, &files),
        RunOutcome::ShardComplete { next } => eprintln!("shard complete; {next}"),
    }
    Ok(())
}
