//! Shared helpers of the run-lifecycle tests: a reporter that keeps what it is told, and
//! readers of an output folder.
#![allow(dead_code)]

use gyroemu_experiment::{Quiet, Reporter, Task};
use serde_json::Value;
use std::path::Path;
use std::sync::Mutex;

/// Keeps the notes and warnings.
#[derive(Default)]
pub struct Record(pub Mutex<Vec<String>>);

impl Reporter for Record {
    fn task(&self, _: &str) -> Box<dyn Task + '_> {
        Box::new(Quiet)
    }
    fn note(&self, text: &str) {
        self.0.lock().unwrap().push(text.to_string());
    }
    fn warn(&self, text: &str) {
        self.0.lock().unwrap().push(format!("warning: {text}"));
    }
}

pub fn json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// The manifest in `out` says `failed`, its `next` holding each of `next_has`; returns it.
pub fn assert_failed(out: &Path, next_has: &[&str]) -> Value {
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "failed", "{m}");
    let next = m["next"].as_str().unwrap();
    for s in next_has {
        assert!(next.contains(s), "{s}: {next}");
    }
    m
}

/// The names of the files in `out/dir`, sorted (none when it does not exist).
pub fn files_in(out: &Path, dir: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(out.join(dir))
        .map(|d| {
            d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// A Coriolis sweep with every noise source (so each point's random stream matters): nine
/// listed rates plus the implicit zero, three lane groups.
pub const NOISY: &str = r#"
[device]
f0_hz = 15000.0
q = 1000.0
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
[board]
fs_hz = 240000.0
lpf_cutoff_hz = 200.0
decimation = 100
adc_bits = 14
adc_full_scale_v = 0.1
[experiment]
kind = "coriolis"
rates_dps = [25.0, 50.0, 75.0, 100.0, 125.0, 150.0, 175.0, 200.0, 225.0]
average_s = 0.2
settle_s = 0.25
[noise]
seed = 7
effective_mass_kg = 1e-9
tia_current_noise_a_per_rthz = 1e-13
tia_voltage_noise_v_per_rthz = 2e-8
"#;

/// [`NOISY`], parsed and validated.
pub fn config() -> gyroemu_config::Config {
    let c = gyroemu_config::parse_config(NOISY).unwrap();
    c.validate().unwrap();
    c
}

/// [`config`] without noise, with a `[pll]` that locks for 5 s (12000 blocks of 100 input
/// samples at 2400 outputs/s). Q is 2000: at 1000 no loop fits this board's low-pass.
pub fn pll_config() -> gyroemu_config::Config {
    let mut cfg = config();
    cfg.noise = None;
    cfg.device.q = 2000.0;
    cfg.pll = Some(gyroemu_config::PllConfig {
        natural_hz: None,
        damping: core::f64::consts::FRAC_1_SQRT_2,
        lock_s: Some(5.0),
        mode: 1,
    });
    cfg.resolve();
    cfg.validate().unwrap();
    cfg
}
