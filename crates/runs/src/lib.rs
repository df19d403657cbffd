//! The run lifecycle of gyroemu, as a library the program drives: per-item result files (a
//! sweep's operating points, a production lot's devices) named by the config's hash,
//! manifests saying which kind of run a folder holds, resuming after an interrupt, shards
//! (Slurm arrays, Kubernetes Indexed Jobs) and their merge into the outputs one machine would
//! have written. Errors are typed ([`RunError`]) so a program can map them to exit codes.

mod abort;
mod config_diff;
pub mod device_file;
mod dumps;
mod error;
mod foreign_outputs;
mod ledger;
mod lock;
mod lot_merge;
mod lot_run;
pub mod manifest;
mod merge;
mod merge_split;
pub mod points;
pub mod records;
mod resume;
mod run;
pub mod shard;

pub use abort::abort_now;
pub use config_diff::{config_diff, config_diff_for};
pub use dumps::dump_files;
pub use error::RunError;
pub use foreign_outputs::{refuse_other_summary, refuse_runs_under};
pub use lock::{lock_out, utc_text, LockInfo, LockScope, OutLock, LOCK_FILE};
pub use lot_run::{check_lot, check_lot_size, run_lot, LotOutcome, MAX_DEVICES};
pub use manifest::RunKind;
pub use merge::{merge, Merged};
pub use resume::{previous_devices, previous_points};
pub use run::{check_run, lock_subfolders, prepare_out, run, RunOutcome, RunRequest};
pub use shard::{check_split, resolve_shard, Shard, ShardFrom};
