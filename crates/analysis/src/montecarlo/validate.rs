//! Before a lot runs: its config, its two sweeps and every drawn device are validated (no
//! sample is computed for a lot holding an impossible device), and its size is said.

use super::draw::{device_config, draw_device};
use crate::selfcal::{sweep_configs, validate_selfcal};
use gyroemu_board::Point;
use gyroemu_config::{Config, ConfigError};
use gyroemu_experiment::sweep::canonical_work;
use gyroemu_experiment::{sweep_work, Work};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Refused devices, and distinct device warnings, listed one by one at most (the rest are
/// counted).
const LISTED_DEVICES: usize = 5;

/// Validates the lot of `cfg` for the devices `indices`, before any sample is computed: the
/// `[montecarlo]` section present, the config's own rules, `selfcal`'s rules on its two sweeps
/// (the `[selfcal]` analyses do not run in a lot), then every drawn device's config the same
/// way. Returns the warnings (those of the devices grouped by text, naming the first device
/// and how many share it), or every problem in one error, a device's problems naming it.
pub fn validate_lot(cfg: &Config, indices: &[u64]) -> Result<Vec<String>, ConfigError> {
    let Some(mc) = &cfg.montecarlo else {
        return Err(ConfigError::message(
            "the config has no [montecarlo] section: a lot draws its devices from its \
             tolerances and judges them against its spec_abs_relative_error (example: \
             `gyroemu config --preset m2tfg-montecarlo`)",
        ));
    };
    let plain = Config {
        selfcal: None,
        ..cfg.clone()
    };
    let mut warnings = plain.validate()?;
    warnings.extend(validate_selfcal(&plain)?);
    let checked: Vec<(u64, Result<Vec<String>, ConfigError>)> = indices
        .par_iter()
        .map(|&i| {
            let dev = device_config(cfg, &draw_device(mc, i));
            let r = dev.validate().and_then(|mut w| {
                w.extend(validate_selfcal(&dev)?);
                Ok(w)
            });
            (i, r)
        })
        .collect();
    let mut refused = Vec::new();
    let mut refused_devices = 0usize;
    // Warning text -> (first device, devices).
    let mut device_warnings: BTreeMap<String, (u64, usize)> = BTreeMap::new();
    for (i, r) in checked {
        match r {
            Ok(w) => {
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
    if refused_devices > LISTED_DEVICES {
        refused.push(ConfigError::message(format!(
            "and {} more of the {} devices are refused: narrow the [montecarlo] spreads or \
             move the nominal device away from the limit",
            refused_devices - LISTED_DEVICES,
            indices.len()
        )));
    }
    if let Some(e) = ConfigError::from_problems(refused) {
        return Err(e);
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
             `gyroemu config --resolved` on its config from `gyroemu montecarlo CONFIG \
             --print-device I`",
            grouped.len() - LISTED_DEVICES,
            devices.iter().next().copied().unwrap_or_default()
        ));
    }
    Ok(warnings)
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
        sweep_work(&rot).plus(sweep_work(&cor)),
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
        .reduce(|| (Work::default(), 0), |(a, x), (b, y)| (a.plus(b), x + y))
}
