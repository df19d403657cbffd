//! Per-device files of a lot and the lot's identity. A device's file holds everything the lot
//! records of it, every value bit for bit (the hex of its IEEE bits), so the lot's outputs
//! rebuilt from the files (a resumed lot, `merge`) equal one machine's byte for byte.

use crate::points::canonical_toml;
use crate::records::hex;
use crate::records::{f64_hex, hex_f64, RecordFile};
use gyroemu_analysis::montecarlo::{DeviceResult, COLUMNS};
use gyroemu_analysis::selfcal::sweep_configs;
use gyroemu_config::{Config, MonteCarloConfig};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;

/// Format tag of a device file.
pub const DEVICE_FORMAT: &str = "gyroemu-device/1";

/// The folder of the device files inside an output folder.
pub const DEVICES_DIR: &str = "devices";

/// The part of a config that decides a lot's devices: the rotating sweep's config (the
/// experiment kind and rate-table keys are overridden for both sweeps; `[dump]` and
/// `[selfcal]` do not run) with `[montecarlo]` but its spec, which only judges the devices.
/// A config differing only elsewhere reuses the saved devices.
pub fn lot_config(cfg: &Config) -> Config {
    let (rot, _) = sweep_configs(cfg);
    Config {
        selfcal: None,
        montecarlo: cfg.montecarlo.as_ref().map(|m| MonteCarloConfig {
            spec_abs_relative_error: 0.0,
            ..m.clone()
        }),
        ..rot
    }
}

/// SHA-256 of a tag and the canonical text of [`lot_config`]: the identity of a lot (the tag
/// keeps it apart from any sweep's [`crate::points::config_hash`]). The lot's size is not in
/// it: device `i` is the same in a lot of any size.
pub fn lot_hash(cfg: &Config) -> String {
    let text = format!("gyroemu lot\n{}", canonical_toml(&lot_config(cfg)));
    hex(&Sha256::digest(text.as_bytes()))
}

/// One finished device as stored on disk.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeviceFile {
    /// [`DEVICE_FORMAT`].
    pub format: String,
    /// [`lot_hash`] of the lot the device belongs to.
    pub lot_sha256: String,
    /// The device's index in the lot.
    pub index: usize,
    /// Every column of the device, as 16 hex digits of its bits.
    pub values: BTreeMap<String, String>,
    pub problems: Vec<String>,
    pub warnings: Vec<String>,
    pub point_samples: u64,
}

impl DeviceFile {
    /// The record of `d` in the lot `hash`.
    pub fn new(hash: &str, d: &DeviceResult) -> Self {
        Self {
            format: DEVICE_FORMAT.to_string(),
            lot_sha256: hash.to_string(),
            index: d.index as usize,
            values: COLUMNS
                .iter()
                .zip(&d.values)
                .map(|(c, &v)| (c.name.to_string(), hex_f64(v)))
                .collect(),
            problems: d.problems.clone(),
            warnings: d.warnings.clone(),
            point_samples: d.point_samples,
        }
    }

    /// The device, bit for bit as it was computed; refused when its columns are not exactly
    /// this version's (a file of another gyroemu version is recomputed).
    pub fn result(&self) -> Result<DeviceResult, String> {
        if self.values.len() != COLUMNS.len() {
            return Err(format!(
                "it holds {} values, this gyroemu records {}",
                self.values.len(),
                COLUMNS.len()
            ));
        }
        let values = COLUMNS
            .iter()
            .map(|c| match self.values.get(c.name) {
                Some(s) => f64_hex(s),
                None => Err(format!("it has no `{}`", c.name)),
            })
            .collect::<Result<Vec<f64>, String>>()?;
        Ok(DeviceResult {
            index: self.index as u64,
            values,
            problems: self.problems.clone(),
            warnings: self.warnings.clone(),
            point_samples: self.point_samples,
        })
    }
}

impl RecordFile for DeviceFile {
    const FORMAT: &'static str = DEVICE_FORMAT;
    const DIR: &'static str = DEVICES_DIR;
    const STEM: &'static str = "device";
    fn format(&self) -> &str {
        &self.format
    }
    fn config_sha256(&self) -> &str {
        &self.lot_sha256
    }
    fn index(&self) -> usize {
        self.index
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_device_round_trips_bit_for_bit() {
        let odd = [
            0.1,
            -0.0,
            f64::NAN,
            1.0 / 3.0,
            f64::MAX,
            -2.5e-300,
            f64::INFINITY,
        ];
        let d = DeviceResult {
            index: 42,
            values: (0..COLUMNS.len()).map(|i| odd[i % odd.len()]).collect(),
            problems: vec!["a phase refused".into()],
            warnings: vec![],
            point_samples: 1 << 40,
        };
        let text = serde_json::to_string(&DeviceFile::new("abc", &d)).unwrap();
        let back: DeviceFile = serde_json::from_str(&text).unwrap();
        let r = back.result().unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&r.values), bits(&d.values));
        assert_eq!(
            (r.index, &r.problems, r.point_samples),
            (42, &d.problems, 1 << 40)
        );
        // A file missing a column (an older version) is refused, not half-read.
        let mut old = back.clone();
        old.values.remove(COLUMNS[3].name);
        assert!(old.result().is_err());
    }

    #[test]
    fn the_lot_identity_ignores_the_spec_the_kind_and_the_analyses_only() {
        let base = gyroemu_config::presets::preset("m2tfg-montecarlo").unwrap();
        let h = lot_hash(&base);
        let mut c = base.clone();
        c.montecarlo.as_mut().unwrap().spec_abs_relative_error = 0.5;
        c.experiment.kind = gyroemu_config::ExperimentKind::Coriolis;
        c.selfcal = Some(Default::default());
        assert_eq!(lot_hash(&c), h);
        let mut c = base.clone();
        c.montecarlo.as_mut().unwrap().seed += 1;
        assert_ne!(lot_hash(&c), h);
        let mut c = base.clone();
        c.noise.as_mut().unwrap().seed += 1;
        assert_ne!(lot_hash(&c), h);
        // Never a sweep's identity.
        assert_ne!(crate::points::config_hash(&base), h);
    }
}
