//! The run lifecycle of gyroemu, as a library the program drives: per-point result files named
//! by the config's hash, manifests, resuming after an interrupt, shards (Slurm arrays,
//! Kubernetes Indexed Jobs) and their merge into the outputs one machine would have written.
//! Errors are typed ([`RunError`]) so a program can map them to exit codes.

mod abort;
mod config_diff;
mod dumps;
mod error;
mod lock;
pub mod manifest;
mod merge;
pub mod points;
mod resume;
mod run;
pub mod shard;

pub use abort::abort_now;
pub use config_diff::config_diff;
pub use dumps::dump_files;
pub use error::RunError;
pub use lock::{lock_out, utc_text, LockInfo, LockScope, OutLock, LOCK_FILE};
pub use merge::merge;
pub use resume::previous_points;
pub use run::{prepare_out, run, RunOutcome, RunRequest};
pub use shard::{resolve_shard, Shard};
