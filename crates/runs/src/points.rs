//! Per-point files of a sweep: the config hash that names a sweep, and one small JSON
//! file per finished operating point holding its raw lane averages bit for bit (f64 as the hex
//! of its IEEE bits: decimal text round-trips only with a correctly rounded parser). A resumed
//! run, a shard, and `gyroemu merge` rebuild the sweep's results from these files; the lane
//! grouping does not change any bits, so the outputs equal a one-machine run's.

use crate::records::{f64_hex, hex, hex_f64, scan_records, write_record, RecordFile, Scan};
use gyroemu_board::{Health, LaneResult};
use gyroemu_config::Config;
use gyroemu_core::Complex64;
use gyroemu_mixer::{MAX_TABLE_HARMONIC, TABLE_HARMONICS};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::Path;

/// Format tag of a point file.
pub const POINT_FORMAT: &str = "gyroemu-point/3";

/// The folder of the point files inside an output folder.
pub const POINTS_DIR: &str = "points";

/// The canonical text of a config: `toml::to_string` of the parsed config (comments, key
/// order and number spelling of the user's file do not matter).
pub fn canonical_toml(cfg: &Config) -> String {
    toml::to_string(cfg).expect("a config always serialises to TOML")
}

/// The sections [`result_config`] leaves out of a sweep's identity, by their TOML names.
pub(crate) const SECTIONS_OUTSIDE_HASH: [&str; 4] = ["dump", "selfcal", "sweep", "montecarlo"];

/// The part of a config that decides a sweep's results: all but `[dump]` (what is recorded
/// on the way), `[selfcal]` (what `selfcal` adds), `[sweep]` (what `sweep` measures) and
/// `[montecarlo]` (what a lot draws), so a config differing only there reuses the saved
/// points.
pub fn result_config(cfg: &Config) -> Config {
    Config {
        dump: None,
        selfcal: None,
        sweep: None,
        montecarlo: None,
        ..cfg.clone()
    }
}

/// SHA-256 of the canonical text of the config's [`result_config`], lowercase hex: the
/// identity of a sweep.
pub fn config_hash(cfg: &Config) -> String {
    hex(&Sha256::digest(
        canonical_toml(&result_config(cfg)).as_bytes(),
    ))
}

/// A hash's first 12 characters, as messages name it (by characters: a hash read from an
/// edited file need not be ASCII, and a byte slice could split a character).
pub(crate) fn short_sha(h: &str) -> String {
    h.chars().take(12).collect()
}

/// One finished operating point as stored on disk.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointFile {
    /// [`POINT_FORMAT`].
    pub format: String,
    /// [`config_hash`] of the sweep the point belongs to.
    pub config_sha256: String,
    /// Index of the point in `emulated_rates_dps(cfg)` (also its noise stream).
    pub index: usize,
    /// The point's rate, deg/s (for people reading the file).
    pub rate_dps: f64,
    /// The lane averages, each f64 as 16 hex digits of its bits: z, c, s, each as [re mode 1,
    /// im mode 1, re mode 2, im mode 2].
    pub z: [String; 4],
    pub c: [String; 4],
    pub s: [String; 4],
    /// Rate-table runs: the table harmonics `-N ..= N` of z (the board's `table_z` without
    /// its zero ends), each as the four values above; empty for the other shapes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub table_z: Vec<[String; 4]>,
    /// The converters' and rails' counts over the point's run.
    pub health: HealthCounts,
}

/// [`Health`] as stored (plain integers, below 2^53 so JSON numbers keep them exact).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HealthCounts {
    pub samples: u64,
    pub dac_clipped: [u64; 2],
    pub dac_zero: [u64; 2],
    pub tia_railed: [u64; 2],
    pub adc_clipped: [u64; 2],
    pub adc_zero: [u64; 2],
}

impl From<Health> for HealthCounts {
    fn from(h: Health) -> Self {
        Self {
            samples: h.samples,
            dac_clipped: h.dac_clipped,
            dac_zero: h.dac_zero,
            tia_railed: h.tia_railed,
            adc_clipped: h.adc_clipped,
            adc_zero: h.adc_zero,
        }
    }
}

impl From<HealthCounts> for Health {
    fn from(h: HealthCounts) -> Self {
        Self {
            samples: h.samples,
            dac_clipped: h.dac_clipped,
            dac_zero: h.dac_zero,
            tia_railed: h.tia_railed,
            adc_clipped: h.adc_clipped,
            adc_zero: h.adc_zero,
        }
    }
}

fn enc(v: &[Complex64; 2]) -> [String; 4] {
    [v[0].re, v[0].im, v[1].re, v[1].im].map(hex_f64)
}

fn dec(v: &[String; 4]) -> Result<[Complex64; 2], String> {
    let mut x = [0.0; 4];
    for (o, s) in x.iter_mut().zip(v) {
        *o = f64_hex(s)?;
    }
    Ok([Complex64::new(x[0], x[1]), Complex64::new(x[2], x[3])])
}

/// The harmonics of `table_z` out to the last non-zero one, per harmonic both modes.
fn enc_table(t: &[[Complex64; TABLE_HARMONICS]; 2]) -> Vec<[String; 4]> {
    let zero = Complex64::new(0.0, 0.0);
    let h = MAX_TABLE_HARMONIC;
    let Some(n) = (0..=h).rev().find(|&n| {
        [h - n, h + n]
            .iter()
            .any(|&i| t[0][i] != zero || t[1][i] != zero)
    }) else {
        return Vec::new();
    };
    (h - n..=h + n).map(|i| enc(&[t[0][i], t[1][i]])).collect()
}

fn dec_table(v: &[[String; 4]]) -> Result<[[Complex64; TABLE_HARMONICS]; 2], String> {
    if v.len() > TABLE_HARMONICS || v.len().is_multiple_of(2) && !v.is_empty() {
        return Err(format!(
            "table_z holds {} harmonics: must be an odd number up to {TABLE_HARMONICS}",
            v.len()
        ));
    }
    let mut t = [[Complex64::new(0.0, 0.0); TABLE_HARMONICS]; 2];
    let first = MAX_TABLE_HARMONIC - v.len() / 2;
    for (i, s) in v.iter().enumerate() {
        let [a, b] = dec(s)?;
        t[0][first + i] = a;
        t[1][first + i] = b;
    }
    Ok(t)
}

impl PointFile {
    /// The record of point `index` of the sweep named by `hash`.
    pub fn new(hash: &str, index: usize, rate_dps: f64, lane: &LaneResult) -> Self {
        Self {
            format: POINT_FORMAT.to_string(),
            config_sha256: hash.to_string(),
            index,
            rate_dps,
            z: enc(&lane.z),
            c: enc(&lane.c),
            s: enc(&lane.s),
            table_z: enc_table(&lane.table_z),
            health: lane.health.into(),
        }
    }

    /// The lane averages, bit for bit as they were computed.
    pub fn lane(&self) -> Result<LaneResult, String> {
        Ok(LaneResult {
            z: dec(&self.z)?,
            c: dec(&self.c)?,
            s: dec(&self.s)?,
            table_z: dec_table(&self.table_z)?,
            health: self.health.into(),
        })
    }
}

impl RecordFile for PointFile {
    const FORMAT: &'static str = POINT_FORMAT;
    const DIR: &'static str = POINTS_DIR;
    const STEM: &'static str = "point";
    fn format(&self) -> &str {
        &self.format
    }
    fn config_sha256(&self) -> &str {
        &self.config_sha256
    }
    fn index(&self) -> usize {
        self.index
    }
}

/// Atomically writes point `index` into `out/points/` (the folder is created).
pub fn write_point(
    out: &Path,
    hash: &str,
    index: usize,
    rate_dps: f64,
    lane: &LaneResult,
) -> Result<(), String> {
    write_record(out, &PointFile::new(hash, index, rate_dps, lane))
}

/// Every point file found in `out/points/`, with its path, or why it could not be read.
pub type PointScan = Scan<PointFile>;

impl Scan<PointFile> {
    /// The lane results of the sweep `hash` with `n_points` points, by index. Errors name a
    /// point present twice (two files with the same index), an index out of range, or a
    /// file whose data do not decode.
    pub fn lanes(
        &self,
        hash: &str,
        n_points: usize,
    ) -> Result<BTreeMap<usize, LaneResult>, String> {
        self.by_index(hash, n_points, false)?
            .into_iter()
            .map(|(i, (path, f))| {
                let lane = f.lane().map_err(|e| format!("`{}`: {e}", path.display()))?;
                Ok((i, lane))
            })
            .collect()
    }
}

/// A point file whose data do not decode: its path and why.
pub type Undecodable = (std::path::PathBuf, String);

impl Scan<PointFile> {
    /// Like [`Scan::lanes`], but a file whose data do not decode (a damaged value) is returned
    /// apart instead of failing the whole scan: for a resume, which recomputes it as it does a
    /// truncated file, where the point's shard runs (another shard just leaves it alone).
    pub fn decodable_lanes(
        &self,
        hash: &str,
        n_points: usize,
    ) -> Result<(BTreeMap<usize, LaneResult>, Vec<Undecodable>), String> {
        let mut lanes = BTreeMap::new();
        let mut damaged = Vec::new();
        for (i, (path, f)) in self.by_index(hash, n_points, false)? {
            match f.lane() {
                Ok(l) => {
                    lanes.insert(i, l);
                }
                Err(e) => damaged.push((path.to_path_buf(), e)),
            }
        }
        Ok((lanes, damaged))
    }
}

/// Reads every `*.json` file in `out/points/` (none when the folder does not exist; hidden
/// temporary files of an interrupted write are skipped).
pub fn scan_points(out: &Path) -> Result<PointScan, String> {
    scan_records(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sections named outside the hash are exactly those `result_config` drops.
    #[test]
    fn the_sections_outside_the_hash_are_those_result_config_drops() {
        let text = "[device]\nf0_hz = 15000.0\nq = 1000.0\nangular_gain = 1.0\n[drive]\nf1 = 1.0\n\
                    [experiment]\nkind = \"coriolis\"\nrates_dps = [50.0]\naverage_s = 0.1\n\
                    [dump]\n[selfcal]\n[sweep]\n[montecarlo]\nspec_abs_relative_error = 0.01\n";
        let cfg = gyroemu_config::parse_config(text).unwrap();
        let keys = |c: &Config| -> std::collections::BTreeSet<String> {
            toml::from_str::<toml::Table>(&canonical_toml(c))
                .unwrap()
                .keys()
                .cloned()
                .collect()
        };
        let dropped: Vec<String> = keys(&cfg)
            .difference(&keys(&result_config(&cfg)))
            .cloned()
            .collect();
        let mut named = SECTIONS_OUTSIDE_HASH.map(String::from).to_vec();
        named.sort();
        assert_eq!(dropped, named);
    }

    #[test]
    fn lane_bits_round_trip_exactly() {
        let odd = [
            0.1,
            -0.0,
            f64::MIN_POSITIVE / 3.0,
            1.0 / 3.0,
            f64::MAX,
            -2.5e-300,
            core::f64::consts::PI,
            7.0,
        ];
        let c = |i: usize| {
            [
                Complex64::new(odd[i], odd[7 - i]),
                Complex64::new(odd[i + 1], 1e-17),
            ]
        };
        let lane = LaneResult {
            z: c(0),
            c: c(1),
            s: c(2),
            table_z: core::array::from_fn(|md| {
                core::array::from_fn(|i| match i {
                    13..=17 => c(3)[md] * (i as f64 - 12.0),
                    _ => Complex64::new(0.0, 0.0),
                })
            }),
            health: Health {
                samples: 1 << 52,
                dac_clipped: [3, 0],
                dac_zero: [0, 7],
                tia_railed: [11, 13],
                adc_clipped: [17, 19],
                adc_zero: [(1 << 52) - 1, 2],
            },
        };
        let f = PointFile::new("abc", 3, 25.0, &lane);
        assert_eq!(f.table_z.len(), 5, "only harmonics -2..=2 are stored");
        let text = serde_json::to_string(&f).unwrap();
        let back: PointFile = serde_json::from_str(&text).unwrap();
        let l2 = back.lane().unwrap();
        let bits = |l: &LaneResult| {
            [l.z, l.c, l.s]
                .iter()
                .flat_map(|v| [v[0].re, v[0].im, v[1].re, v[1].im])
                .chain(l.table_z.iter().flatten().flat_map(|v| [v.re, v.im]))
                .map(f64::to_bits)
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&l2), bits(&lane));
        assert_eq!(l2.health, lane.health);
    }

    #[test]
    fn sha256_hex_matches_the_fips_180_example() {
        assert_eq!(
            hex(&Sha256::digest(b"abc")),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn hash_ignores_comments_and_spelling_but_not_values() {
        let base = gyroemu_config::presets::preset("m2tfg-coriolis").unwrap();
        let text = canonical_toml(&base);
        let reparsed = gyroemu_config::parse_config(&format!("# a comment\n{text}")).unwrap();
        assert_eq!(config_hash(&reparsed), config_hash(&base));
        let mut other = base.clone();
        other.device.q += 1.0;
        assert_ne!(config_hash(&other), config_hash(&base));
        assert_eq!(config_hash(&base).len(), 64);
    }

    #[test]
    fn hash_ignores_the_dump_and_the_selfcal_analyses() {
        let base = gyroemu_config::presets::preset("m2tfg-coriolis").unwrap();
        let text = canonical_toml(&base);
        let more = format!("{text}\n[dump]\nnodes = [\"tia\"]\n[selfcal]\nallan_record_s = 10.0\n");
        let dumped = gyroemu_config::parse_config(&more).unwrap();
        assert!(dumped.dump.is_some() && dumped.selfcal.is_some());
        assert_ne!(canonical_toml(&dumped), text);
        assert_eq!(config_hash(&dumped), config_hash(&base));
    }
}
