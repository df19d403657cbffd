//! A production lot (`gyroemu montecarlo`): devices drawn from the tolerances of the config's
//! `[montecarlo]` section, each self-calibrated on the emulated board (both sweeps sample by
//! sample, with its own noise streams), and the distribution of their self-calibration errors
//! with the yield within the spec. Device `i` depends on `(seed, i)` only, never on the lot
//! size, the shard or the thread count, so a lot splits across machines.

mod device;
mod draw;
mod stats;
mod summary;
mod validate;

pub use device::{run_device, Column, ColumnKind, DeviceInputs, DeviceResult, COLUMNS, HEADLINE};
pub use draw::{device_config, draw_device, DeviceDraw, DRAW_STREAM_BASE, PARAMETERS};
pub use stats::{percentile, wilson_interval, Spread, PERCENTILES, Z95};
pub use summary::{LotSummary, YieldEstimate};
pub use validate::{device_work, lot_work, validate_lot, validate_lot_capped, LotRefusal};
