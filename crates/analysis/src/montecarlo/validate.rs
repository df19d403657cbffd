//! Before a lot runs: its config, its two sweeps and every drawn device are validated (no
//! sample is computed for a lot holding an impossible device), and its size is said.

use super::draw::{device_config, draw_device};
use crate::selfcal::{sweep_configs, validate_selfcal};
use gyroemu_board::Point;
use gyroemu_config::{Config, ConfigError};
use gyroemu_experiment::sweep::canonical_work;
use gyroemu_experiment::{lock_work, sweep_work, Work, MAX_POINT_SAMPLES};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Refused devices, and distinct device warnings, listed one by one at most (the rest are
/// counted).
const LISTED_DEVICES: usize = 5;

/// Devices validated per pass: a lot above the work cap is refused after the pass that
/// crosses it, not after validating a million devices.
const CHUNK: usize = 4096;

/// A device's warnings and work, or its refusal.
type DeviceCheck = Result<(Vec<String>, Work), ConfigError>;

/// Why a lot was refused before any sample: a config rule, or the work cap.
#[derive(Debug)]
pub enum LotRefusal {
    /// The config, its sweeps or a drawn device broke a rule.
    Config(ConfigError),
    /// The devices run more point-samples than [`MAX_POINT_SAMPLES`] without `--force`: the
    /// plan, with what to do.
    Cap(String),
}

/// Validates the lot of `cfg` for the devices `indices`, before any sample is computed: the
/// `[montecarlo]` section present, the config's own rules, `selfcal`'s rules on its two sweeps
/// (the `[selfcal]` analyses do not run in a lot), then every drawn device's config the same
/// way. Returns the warnings (those of the devices grouped by text, naming the first device
/// and how many share it), or every problem in one error, a device's problems naming it.
pub fn validate_lot(cfg: &Config, indices: &[u64]) -> Result<Vec<String>, ConfigError> {
    validate_lot_capped(cfg, indices, true).map_err(|r| match r {
        LotRefusal::Config(e) => e,
        LotRefusal::Cap(m) => unreachable!("no cap when forced: {m}"),
    })
}

/// [`validate_lot`], and unless `force` the cap of [`MAX_POINT_SAMPLES`] on the devices'
/// work, as `gyroemu run` caps a shard's share of its sweep (saved or not). The devices are
/// validated 4096 at a time (`CHUNK`); when no device has been refused, the lot is
/// refused as soon as the devices validated so far run more than the cap (their work is a
/// lower bound on the lot's), so a mistyped `--devices` is told in seconds.
pub fn validate_lot_capped(
    cfg: &Config,
    indices: &[u64],
    force: bool,
) -> Result<Vec<String>, LotRefusal> {
    let Some(mc) = &cfg.montecarlo else {
        return Err(LotRefusal::Config(ConfigError::message(
            "the config has no [montecarlo] section: a lot draws its devices from its \
             tolerances and judges them against its spec_abs_relative_error (example: \
             `gyroemu config --preset m2tfg-montecarlo`)",
        )));
    };
    let plain = Config {
        selfcal: None,
        ..cfg.clone()
    };
    // As selfcal reads it: `[dump]`, `kind` and `rate_table` are not the lot's.
    let mut warnings = validate_selfcal(&plain).map_err(LotRefusal::Config)?;
    let mut refused = Vec::new();
    let mut refused_devices = 0usize;
    // Warning text -> (first device, devices).
    let mut device_warnings: BTreeMap<String, (u64, usize)> = BTreeMap::new();
    let mut work = Work::default();
    let mut validated = 0usize;
    for chunk in indices.chunks(CHUNK) {
        let checked: Vec<(u64, DeviceCheck)> = chunk
            .par_iter()
            .map(|&i| {
                let dev = device_config(cfg, &draw_device(mc, i));
                let r = validate_selfcal(&dev).map(|w| {
                    // Planned only once valid: the work of a refused device means nothing.
                    let work = if force {
                        Work::default()
                    } else {
                        device_work(&dev).0
                    };
                    (w, work)
                });
                (i, r)
            })
            .collect();
        for (i, r) in checked {
            match r {
                Ok((w, dw)) => {
                    work = work.plus(dw);
                    for w in w.into_iter().filter(|w| !warnings.contains(w)) {
                        device_warnings.entry(w).or_insert((i, 0)).1 += 1;
                    }
                }
                Err(e) => {
                    refused_devices += 1;
                    if refused_devices <= LISTED_DEVICES {
                        refused.push(e.map_details(|d| {
                            format!("{d} (device {i} of the lot, drawn from [montecarlo])")
                        }));
                    }
                }
            }
        }
        validated += chunk.len();
        if !force && refused_devices == 0 && work.capped_samples() > MAX_POINT_SAMPLES {
            return Err(LotRefusal::Cap(cap_refusal(
                &work,
                validated,
                indices.len(),
            )));
        }
    }
    if refused_devices > LISTED_DEVICES {
        refused.push(ConfigError::message(format!(
            "and {} more of the {} devices are refused: narrow the [montecarlo] spreads or \
             move the nominal device away from the limit",
            refused_devices - LISTED_DEVICES,
            indices.len()
        )));
    }
    if let Some(e) = ConfigError::from_problems(refused) {
        return Err(LotRefusal::Config(e));
    }
    let mut grouped: Vec<(String, (u64, usize))> = device_warnings.into_iter().collect();
    grouped.sort_by_key(|(_, (first, _))| *first);
    for (w, (first, n)) in grouped.iter().take(LISTED_DEVICES) {
        let others = if *n > 1 {
            format!(" and {} more devices", n - 1)
        } else {
            String::new()
        };
        warnings.push(format!("device {first}{others}: {w}"));
    }
    if grouped.len() > LISTED_DEVICES {
        let devices: std::collections::BTreeSet<u64> = grouped
            .iter()
            .skip(LISTED_DEVICES)
            .map(|(_, (f, _))| *f)
            .collect();
        warnings.push(format!(
            "{} more distinct device warnings (from device {} on); to see a device's, run \
             `gyroemu selfcal` on its config from `gyroemu montecarlo CONFIG --print-device I` \
             (it validates it as the lot does, before any sample)",
            grouped.len() - LISTED_DEVICES,
            devices.iter().next().copied().unwrap_or_default()
        ));
    }
    Ok(warnings)
}

/// The cap's refusal for the `validated` devices of a lot of `total` whose `work` crossed it:
/// the whole plan when every device was validated, else a lower bound and the lot's work
/// extrapolated from the devices' mean (said as such).
fn cap_refusal(work: &Work, validated: usize, total: usize) -> String {
    if validated == total {
        return work
            .check_cap(false)
            .expect_err("the caller saw the work above the cap");
    }
    let mean = work.capped_samples() as f64 / validated as f64;
    format!(
        "plan: the first {validated} of these {total} devices alone run {:.3e} point-samples \
         (about {:.3e} for all {total} at their mean; longest point {:.4} s of signal): above \
         the cap of {:.0e} point-samples without --force (a mistyped --devices, Q or \
         averaging time would otherwise start a run of days); run fewer devices, shorten \
         experiment.average_s or experiment.settle_s, or add --force to run it anyway",
        work.capped_samples() as f64,
        mean * total as f64,
        work.longest_s,
        MAX_POINT_SAMPLES as f64
    )
}

/// The work of one device's self-calibration (its config from [`device_config`]): the two
/// sweeps' size, and the input samples they run (summed over lane groups: the unit of the
/// sweeps' progress reports).
pub fn device_work(device: &Config) -> (Work, u64) {
    let (rot, cor) = sweep_configs(device);
    let input = |c: &Config| {
        let points: Vec<Point> = c
            .emulated_rates_dps()
            .iter()
            .map(|&r| c.plan_point(r))
            .collect();
        canonical_work(c, &points).0
    };
    (
        // A [pll] locks each device's carrier first.
        lock_work(device)
            .plus(sweep_work(&rot))
            .plus(sweep_work(&cor)),
        input(&rot) + input(&cor),
    )
}

/// The work of the devices `indices` of the lot of `cfg`, and their input samples.
pub fn lot_work(cfg: &Config, indices: &[u64]) -> (Work, u64) {
    let Some(mc) = &cfg.montecarlo else {
        return (Work::default(), 0);
    };
    indices
        .par_iter()
        .map(|&i| device_work(&device_config(cfg, &draw_device(mc, i))))
        .reduce(
            || (Work::default(), 0),
            |(a, x), (b, y)| (a.plus(b), x.saturating_add(y)),
        )
}
