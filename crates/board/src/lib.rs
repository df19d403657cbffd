//! The readout board of gyroemu, assembled from the stage crates and run sample by sample.
//!
//! It takes a plain, validated [`BoardParams`] (no file format: `gyroemu-config` maps its TOML
//! onto it) and owns the sample loop: [`Board`] runs up to four operating points in `f64x4`
//! lanes through one fused kernel (`kernel.rs`), and [`GroupBoard`] up to eight in 512-bit
//! lanes on a CPU with AVX-512 (picked at run time: `lanes.rs`); [`reference::run_reference`] runs the same
//! chain plainly, stage by stage, as its test oracle; [`ChainResponse`] answers the read-out's
//! compensation from the very stages the board runs; [`Probe`] records signal dumps;
//! [`lock_carrier`] locks the carrier onto a resonance with the PLL.

mod board;
mod chain;
mod cpu;
#[cfg(target_arch = "x86_64")]
mod f64x8;
mod fault;
mod flicker;
mod group;
mod health;
mod kernel;
mod lanes;
mod lock;
mod params;
mod point;
mod probe;
pub mod reference;
mod refill;
mod seeding;

pub use board::{drive_shifter, starts_share_carrier, Board, MAX_START};
pub use chain::{unleak_sidebands, unleak_table_harmonics, ChainResponse, RotatingTerms};
pub use cpu::CpuId;
pub use fault::NonFinite;
pub use group::GroupBoard;
pub use health::Health;
pub use lanes::{
    eight_lanes_available, group_sizes, groups_by_length, halves_512, lane_groups, max_lanes,
    max_lanes_for, set_max_lanes, vector_paths, LaneCpu, CANONICAL_LANES, FOUR_LANE_COST,
    MAX_LANES,
};
pub use lock::{lock_carrier, LockRun};
pub use params::{BoardParams, Converter, NoiseParams, Shape};
pub use point::{LaneResult, Point, RunOptions, RunOutput};
pub use probe::{Probe, DUMP_NODES, EVENTS_COUNTED_KEY, EVENT_KEYS};
pub use refill::{Refill, RefillError};
