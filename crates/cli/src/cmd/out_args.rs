//! The arguments `run` and `montecarlo` share: where they write, which share of the work this
//! process runs, and `--force`; and opening the output folder for them.

use crate::input::command_line;
use crate::progress::Terminal;
use crate::signals;
use anyhow::Result;
use gyroemu_runs::shard::Shard;
use gyroemu_runs::{lock_out, prepare_out, resolve_shard, LockScope, OutLock};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// `--out DIR [--shard I/N] [--shard-count N] [--force]`.
#[derive(clap::Args)]
pub struct OutArgs {
    /// Output folder. Points (a lot's devices) already computed there for the same config are
    /// reused, so rerunning an interrupted command resumes it.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Run only shard I of N (0-based): operating point (device) p belongs to shard p % N;
    /// then `gyroemu merge OUT`. Default: from SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX
    /// when set (see docs/cluster.md).
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// The shard count N beside JOB_COMPLETION_INDEX (or GYROEMU_SHARD_COUNT).
    #[arg(long, value_name = "N")]
    pub shard_count: Option<usize>,
    /// Run even when the plan exceeds the cap of 1e11 point-samples, and delete results of
    /// another config found in the output folder instead of refusing.
    #[arg(long)]
    pub force: bool,
}

impl OutArgs {
    /// This process's shard: `--shard`, else the scheduler's index (or none).
    pub fn shard(&self) -> Result<Option<Shard>> {
        let env = |k: &str| std::env::var(k).ok();
        Ok(resolve_shard(
            self.shard.as_deref(),
            self.shard_count,
            &env,
        )?)
    }

    /// Catches Ctrl-C (the first one stops the work gracefully), then creates the output
    /// folder and locks it (the whole folder, or the shard's index); returns the cancel flag
    /// and the lock.
    pub fn open(&self, shard: Option<&Shard>) -> Result<(Arc<AtomicBool>, OutLock)> {
        let cancel = signals::install(true);
        prepare_out(&self.out)?;
        let scope = shard.map_or(LockScope::Folder, |s| LockScope::Shard {
            index: s.index,
            count: s.count,
        });
        let lock = lock_out(&self.out, &command_line(), scope, &Terminal)?;
        Ok((cancel, lock))
    }
}
