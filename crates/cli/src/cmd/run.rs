//! `gyroemu run CONFIG --out DIR [--shard I/N] [--force]`.

use crate::cmd::out_args::OutArgs;
use crate::input::{list_written_with, listing_refused, load_config, ItemFiles, SavedCount};
use crate::progress::Terminal;
use anyhow::Result;
use gyroemu_runs::points::POINTS_DIR;
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
    let saved = SavedCount::default();
    let on_saved = |k: usize| saved.saved(k);
    let req = RunRequest {
        config: &cfg,
        out: &a.out,
        shard,
        force: a.force,
        cancel,
        on_saved: Some(&on_saved),
    };
    let points = || ItemFiles {
        dir: POINTS_DIR,
        item: "point",
        count: saved.get(),
    };
    let outcome = listing_refused(run(&req, &Terminal), &a.out, Some(points()))?;
    let files = match outcome {
        RunOutcome::Complete(files) => files,
        RunOutcome::ShardComplete { next, files } => {
            note!("shard complete; {next}");
            files
        }
    };
    list_written_with(&a.out, &files, Some(points()));
    Ok(())
}
