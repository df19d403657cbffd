//! One device of a lot: its draw applied to the nominal config, self-calibrated on the emulated
//! board (the rotating sweep and the virtual rate table, sample by sample), and what the lot
//! records of it: a table of named values, each read by a column function, so a new column is
//! one line of [`COLUMNS`].

use super::draw::{device_config, draw_device};
use crate::selfcal::{sweep_configs, SelfcalCore};
use gyroemu_config::Config;
use gyroemu_experiment::{
    finish_sweep, resolve_lock_with, run_sweep_with, SweepError, SweepOptions,
};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

/// What a column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColumnKind {
    /// A drawn device parameter.
    Parameter,
    /// A self-calibration error: the lot reports its distribution.
    Error,
    /// Anything else measured (confidence half-widths, slopes).
    Measured,
}

/// What a column reads a device's value from.
pub struct DeviceInputs<'a> {
    /// The device's config ([`device_config`]).
    pub config: &'a Config,
    /// The nominal angular gain: the lot's config's, the lambda a production line knows.
    pub nominal_angular_gain: f64,
    /// The device's two sweeps and their comparison.
    pub core: &'a SelfcalCore,
}

/// One named value of a device.
pub struct Column {
    /// Its name in `devices.csv`, the device files and `montecarlo.json`.
    pub name: &'static str,
    pub kind: ColumnKind,
    /// Reads it.
    pub get: fn(&DeviceInputs) -> f64,
}

const fn col(name: &'static str, kind: ColumnKind, get: fn(&DeviceInputs) -> f64) -> Column {
    Column { name, kind, get }
}

/// The self-calibration error of mode `k` predicted with the nominal lambda (the device's own
/// is unknown on a production line): nominal lambda times the rotating slope, over the
/// measured Coriolis slope, minus one (the expression `selfcal` evaluates with the device's
/// lambda, so both agree bit for bit when the two lambdas do).
fn nominal_error(d: &DeviceInputs, k: usize) -> f64 {
    let m = &d.core.modes[k];
    d.nominal_angular_gain * m.rotating.slope_deg_per_dps / m.coriolis.slope_deg_per_dps - 1.0
}

/// The lambda ratio a half-width of `selfcal` is scaled by: nominal over the device's own.
fn lambda_ratio(d: &DeviceInputs) -> f64 {
    (d.nominal_angular_gain / d.config.device.angular_gain).abs()
}

/// Its 95 % half-width: `selfcal`'s, scaled as the ratio is by the two lambdas.
fn nominal_ci95(d: &DeviceInputs, k: usize) -> f64 {
    d.core.modes[k].relative_error_ci95 * lambda_ratio(d)
}

/// The two-mode error (geometric means of the two modes' slopes, free of the drive-gain ratio
/// and the Q mismatch) predicted with the nominal lambda.
fn nominal_combined(d: &DeviceInputs) -> f64 {
    let c = &d.core.combined;
    d.nominal_angular_gain * c.rotating.slope_deg_per_dps / c.coriolis.slope_deg_per_dps - 1.0
}

use ColumnKind::{Error, Measured, Parameter};

/// Every value recorded per device, in `devices.csv` order (after `index`).
pub const COLUMNS: &[Column] = &[
    col("mode2_f0_offset_hz", Parameter, |d| {
        d.config.device.mode2_f0_offset_hz
    }),
    col("q", Parameter, |d| d.config.device.q),
    col("q_mode2", Parameter, |d| {
        d.config.device.q_mode2.unwrap_or(d.config.device.q)
    }),
    col("f2_over_f1", Parameter, |d| {
        d.config.f2() / d.config.drive.f1
    }),
    col("phase_shifter_error_deg", Parameter, |d| {
        d.config.board.phase_shifter_error_deg
    }),
    col("angular_gain", Parameter, |d| d.config.device.angular_gain),
    col("relative_error_mode1", Error, |d| nominal_error(d, 0)),
    col("relative_error_ci95_mode1", Measured, |d| {
        nominal_ci95(d, 0)
    }),
    col("relative_error_mode2", Error, |d| nominal_error(d, 1)),
    col("relative_error_ci95_mode2", Measured, |d| {
        nominal_ci95(d, 1)
    }),
    col("combined_relative_error", Error, nominal_combined),
    col("combined_relative_error_ci95", Measured, |d| {
        d.core.combined.relative_error_ci95 * lambda_ratio(d)
    }),
    col("board_relative_error_mode1", Error, |d| {
        d.core.modes[0].relative_error
    }),
    col("board_relative_error_mode2", Error, |d| {
        d.core.modes[1].relative_error
    }),
    col("board_combined_relative_error", Error, |d| {
        d.core.combined.relative_error
    }),
    col("rotating_slope_mode1_deg_per_dps", Measured, |d| {
        d.core.modes[0].rotating.slope_deg_per_dps
    }),
    col("rotating_slope_mode2_deg_per_dps", Measured, |d| {
        d.core.modes[1].rotating.slope_deg_per_dps
    }),
    col("coriolis_slope_mode1_deg_per_dps", Measured, |d| {
        d.core.modes[0].coriolis.slope_deg_per_dps
    }),
    col("coriolis_slope_mode2_deg_per_dps", Measured, |d| {
        d.core.modes[1].coriolis.slope_deg_per_dps
    }),
];

/// The error the spec and the lot's headline figures are about.
pub const HEADLINE: &str = "relative_error_mode1";

/// What the lot records of one device.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceResult {
    /// Index of the device in the lot.
    pub index: u64,
    /// One value per column of [`COLUMNS`], in that order.
    pub values: Vec<f64>,
    /// Why its numbers cannot be trusted (the sweeps' refused phases); empty when they can.
    pub problems: Vec<String>,
    /// What the sweeps warned about (clipping, saturation).
    pub warnings: Vec<String>,
    /// Operating-point samples its two sweeps emulated.
    pub point_samples: u64,
}

impl DeviceResult {
    /// Reads every column of a self-calibrated device.
    pub fn new(index: u64, inputs: &DeviceInputs, point_samples: u64) -> Self {
        let (rot, cor) = (&inputs.core.rotating, &inputs.core.coriolis);
        Self {
            index,
            values: COLUMNS.iter().map(|c| (c.get)(inputs)).collect(),
            problems: rot.problems.iter().chain(&cor.problems).cloned().collect(),
            warnings: rot.warnings.iter().chain(&cor.warnings).cloned().collect(),
            point_samples,
        }
    }

    /// The value of the column `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        let i = COLUMNS.iter().position(|c| c.name == name)?;
        self.values.get(i).copied()
    }

    /// The headline error, when it can be trusted (no problem, finite).
    pub fn headline(&self) -> Option<f64> {
        self.value(HEADLINE)
            .filter(|v| v.is_finite() && self.problems.is_empty())
    }
}

/// Draws device `index` of the lot of `base` and self-calibrates it: with a `[pll]` the carrier
/// locked first, then both sweeps of [`sweep_configs`] on its config, through the same calls
/// as `selfcal` (so a direct `selfcal` of [`device_config`] gives the same bits). `on_samples` receives each increase of the input
/// samples emulated. `None`: the `cancel` flag stopped it before both sweeps finished.
pub fn run_device(
    base: &Config,
    index: u64,
    cancel: Option<&Arc<AtomicBool>>,
    on_samples: &(dyn Fn(u64) + Sync),
) -> Result<Option<DeviceResult>, SweepError> {
    let Some(mc) = &base.montecarlo else {
        return Err(SweepError::Config(gyroemu_config::ConfigError::message(
            "the config has no [montecarlo] section",
        )));
    };
    // With a [pll], both sweeps run at the carrier it locks, as in `selfcal`; the cancel
    // flag stops the lock too (it runs as long as the user's pll.lock_s).
    let device = device_config(base, &draw_device(mc, index));
    let (cfg, _lock) = match resolve_lock_with(&device, cancel.map(|c| &**c)) {
        Err(SweepError::Cancelled) => return Ok(None),
        other => other?,
    };
    let (rot_cfg, cor_cfg) = sweep_configs(&cfg);
    let mut runs = Vec::with_capacity(2);
    for c in [&rot_cfg, &cor_cfg] {
        // A sweep reports its running total; groups in parallel may report out of order.
        let last = AtomicU64::new(0);
        let progress = |done: u64, _total: u64| {
            let prev = last.fetch_max(done, Ordering::Relaxed);
            on_samples(done.saturating_sub(prev));
        };
        let opts = SweepOptions {
            cancel: cancel.cloned(),
            ..Default::default()
        };
        let run = run_sweep_with(c, &progress, None, opts)?;
        if run.cancelled {
            return Ok(None);
        }
        runs.push(run);
    }
    let rotating = finish_sweep(&rot_cfg, &runs[0].lanes)?;
    let coriolis = finish_sweep(&cor_cfg, &runs[1].lanes)?;
    // The canonical count (four points per group in index order), not what this machine's
    // grouping ran: a device's record must not depend on threads, lanes or shards.
    let samples = rotating.point_samples + coriolis.point_samples;
    let core = SelfcalCore::from_sweeps(&cfg, rotating, coriolis);
    let inputs = DeviceInputs {
        config: &cfg,
        nominal_angular_gain: base.device.angular_gain,
        core: &core,
    };
    Ok(Some(DeviceResult::new(index, &inputs, samples)))
}
