//! A signal dump to record during a sweep: which operating point, which window, which nodes,
//! and the operating point's description written into the recordings' metadata.

use gyroemu_board::{Probe, Shape};
use gyroemu_config::Config;
use std::collections::BTreeMap;

/// One operating point's nodes over a window.
#[derive(Clone, Debug, PartialEq)]
pub struct DumpPlan {
    /// The operating point, deg/s (one of the emulated rates).
    pub rate_dps: f64,
    /// Start of both windows, s from the start of the run.
    pub start_s: f64,
    /// Length of the full-rate window, s.
    pub duration_s: f64,
    /// Length of the decimated window, s (the same as `duration_s` for a `[dump]` section).
    pub decimated_duration_s: f64,
    /// Nodes recorded (names of `gyroemu_board::DUMP_NODES`).
    pub nodes: Vec<String>,
}

impl DumpPlan {
    /// The config's `[dump]` with its defaults filled in, if it has one.
    pub fn from_config(cfg: &Config) -> Option<Self> {
        let d = cfg.dump_resolved()?;
        let duration_s = d.duration_s.unwrap_or(0.0);
        Some(DumpPlan {
            rate_dps: d.rate_dps.unwrap_or(f64::NAN),
            start_s: d.start_s.unwrap_or(0.0),
            duration_s,
            decimated_duration_s: duration_s,
            nodes: d.nodes.unwrap_or_default(),
        })
    }

    /// The probe recording this plan on `lane` of a board built from `cfg`.
    pub fn probe(&self, cfg: &Config, lane: usize) -> Probe {
        Probe::new(
            &self.nodes,
            cfg.fs_hz(),
            cfg.decimation(),
            self.start_s,
            self.duration_s,
            lane,
        )
        .with_decimated_duration(self.decimated_duration_s)
        .with_extra(dump_extra(cfg, self.rate_dps))
    }
}

/// The operating point of a dump at `rate_dps`, as the numbers its SigMF metadata carries
/// (`gyroemu:<key>`): the resonances `f0_hz` (mode 1) and `f0_mode2_hz`, the drive's
/// `carrier_hz`, `rate_dps`, the rotating excitation's `omega_hz` (sidebands at carrier_hz +-
/// omega_hz) or the rate table's `table_freq_hz`, and the read-out's `lpf_cutoff_hz`,
/// `lpf_order` and `decimation`.
pub fn dump_extra(cfg: &Config, rate_dps: f64) -> BTreeMap<String, f64> {
    let mut m = BTreeMap::from([
        ("f0_hz".to_string(), cfg.device.f0_hz),
        // The drive's carrier (a PLL's locked one): where the driven tones sit.
        ("carrier_hz".to_string(), cfg.carrier_hz()),
        ("f0_mode2_hz".to_string(), cfg.f0_mode2_hz()),
        ("rate_dps".to_string(), rate_dps),
        ("lpf_cutoff_hz".to_string(), cfg.lpf_cutoff_hz()),
        ("lpf_order".to_string(), cfg.board.lpf_order as f64),
        ("decimation".to_string(), cfg.decimation() as f64),
    ]);
    match cfg.shape() {
        Shape::Rotating => {
            m.insert("omega_hz".into(), rate_dps.abs() / 360.0);
        }
        Shape::RateTable { freq_hz } => {
            m.insert("table_freq_hz".into(), freq_hz);
        }
        Shape::Coriolis => {}
    }
    m
}
