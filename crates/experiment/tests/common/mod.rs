//! Shared helpers of the experiment tests that run a config's sweep past its rules and read
//! its warnings' figures.
#![allow(dead_code)]

use gyroemu_config::Config;
use gyroemu_experiment::{finish_sweep, run_sweep_with, SweepOptions, SweepResult};

/// The sweep of `cfg`, emulated and read out (its rules are not applied: a test weighs them).
pub fn finished(cfg: &Config) -> SweepResult {
    let run = run_sweep_with(cfg, &|_, _| {}, None, SweepOptions::default()).unwrap();
    finish_sweep(cfg, &run.lanes).unwrap()
}

/// The number written right after `key` in `text` (up to the next space).
pub fn number_after(text: &str, key: &str) -> f64 {
    let rest = text
        .split(key)
        .nth(1)
        .unwrap_or_else(|| panic!("no `{key}` in {text}"));
    rest.split(' ').next().unwrap().parse().unwrap()
}

/// The first warning holding `needle`.
pub fn warning<'a>(warnings: &'a [String], needle: &str) -> &'a str {
    warnings
        .iter()
        .find(|w| w.contains(needle))
        .unwrap_or_else(|| panic!("no warning with `{needle}`: {warnings:?}"))
}

/// A rate table's largest |reading - theory| over the points and modes, mdeg: of the phase
/// amplitude, and of the lag.
pub fn table_errors_mdeg(res: &SweepResult) -> (f64, f64) {
    let (mut amp, mut lag) = (0.0f64, 0.0f64);
    for p in &res.points {
        let (l, lt) = (p.table_lag_deg.unwrap(), p.table_lag_theory_deg.unwrap());
        for k in 0..2 {
            amp = amp.max((p.phase_deg[k] - p.theory_deg[k]).abs() * 1e3);
            lag = lag.max((l[k] - lt[k]).abs() * 1e3);
        }
    }
    (amp, lag)
}
