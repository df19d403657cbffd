//! A rate table whose output rate folds the stage-1 mixer's 2 f_c product near a harmonic it
//! demodulates: the warning bounds what the emulated run reads, in the amplitude (the two
//! harmonics of the fundamental each take an error: it had stated half of it) and in the lag
//! (453 mdeg read where nothing was stated), and does not advise removing a key that is
//! already derived.

use gyroemu_config::{parse_config, Config};
use gyroemu_experiment::{finish_sweep, run_sweep_with, SweepOptions};

/// A Q-66 device at 2236.9 Hz, a first-order low-pass and the derived decimation (8): 2 f_c
/// aliases to 4473.8 Hz at the 8985 Hz output rate, one table period averaged.
fn aliased() -> Config {
    parse_config(
        r#"
[device]
f0_hz = 2236.9
q = 66.0
angular_gain = 1.0
[drive]
f1 = 1.0
[board]
fs_hz = 71880.947
lpf_order = 1
[experiment]
kind = "coriolis"
rate_table = "sinusoid"
table_freq_hz = 28.5957
rates_dps = [300.0, 1500.0]
average_s = 0.0349703
"#,
    )
    .unwrap()
}

fn number_after(w: &str, key: &str) -> f64 {
    w.split(key)
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn the_alias_warning_bounds_the_tables_amplitude_and_lag() {
    let cfg = aliased();
    let warnings = cfg.validate().unwrap();
    let w = warnings
        .iter()
        .find(|w| w.contains("2 f_c product"))
        .unwrap_or_else(|| panic!("{warnings:?}"));
    let amp_bound = number_after(w, "phase by up to ");
    let lag_bound = number_after(w, "table lag by up to ");
    assert!(!w.contains("remove the key"), "{w}");
    let run = run_sweep_with(&cfg, &|_, _| {}, None, SweepOptions::default()).unwrap();
    let res = finish_sweep(&cfg, &run.lanes).unwrap();
    let (mut amp, mut lag) = (0.0f64, 0.0f64);
    for p in &res.points {
        let (l, lt) = (p.table_lag_deg.unwrap(), p.table_lag_theory_deg.unwrap());
        for k in 0..2 {
            amp = amp.max((p.phase_deg[k] - p.theory_deg[k]).abs() * 1e3);
            lag = lag.max((l[k] - lt[k]).abs() * 1e3);
        }
    }
    // The run is moved well past the threshold, within each bound, and not far inside the
    // lag's (the bound is the error's whole size turned across the amplitude).
    assert!(amp > 1.0 && lag > 100.0, "amplitude {amp}, lag {lag} mdeg");
    assert!(amp <= amp_bound, "amplitude {amp} mdeg, stated {amp_bound}");
    assert!(
        lag <= lag_bound && lag_bound < 3.0 * lag,
        "lag {lag} mdeg, stated {lag_bound}"
    );
}
