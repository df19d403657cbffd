//! The experiment layer of gyroemu: sweeps over operating points run on the emulated board
//! (`gyroemu-board`) as a config (`gyroemu-config`) describes them, their read-out into phases
//! with the chain compensated and the exact theory (`gyroemu-theory`) beside every point, the
//! paper's line fits, and the throughput measurement.

pub mod bench;
pub mod dump;
pub mod fit;
pub mod leaks;
pub mod lock;
pub mod mutex;
pub mod prepared;
pub mod progress;
pub mod queue;
pub mod readout;
pub mod refill_plan;
pub mod split;
pub mod sweep;
pub mod table_sweep;
pub mod work;

pub use dump::{dump_extra, DumpPlan};
pub use leaks::Stage2Leaks;
pub use lock::{
    lock_blocks, lock_config_carrier, lock_config_carrier_with, pll_params, resolve_lock,
    resolve_lock_with, CarrierLock,
};
pub use prepared::{run_sweep, run_sweep_with};
pub use progress::{Progress, Quiet, Reporter, Task, Written};
pub use readout::{
    fit_readings, post_process, post_process_with, reading_period_deg, theory_deg, Compensation,
    PointResult, SweepResult,
};
pub use sweep::{
    dump_point, finish_sweep, finish_sweep_with, OnDump, OnGroup, SweepError, SweepOptions,
    SweepRun, DUMP_STEM,
};
pub use table_sweep::run_table_sweeps;
pub use work::{lock_work, sweep_work, Work, MAX_POINT_SAMPLES};
