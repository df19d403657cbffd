//! A rate table whose output rate folds the stage-1 mixer's 2 f_c product near a harmonic it
//! demodulates: the warning bounds what the emulated run reads, in the amplitude (the two
//! harmonics of the fundamental each take an error: it had stated half of it) and in the lag
//! (453 mdeg read where nothing was stated), and does not advise removing a key that is
//! already derived.

mod common;

use common::{finished, number_after, table_errors_mdeg, warning};
use gyroemu_config::{parse_config, Config};

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

#[test]
fn the_alias_warning_bounds_the_tables_amplitude_and_lag() {
    let cfg = aliased();
    let warnings = cfg.validate().unwrap();
    let w = warning(&warnings, "2 f_c product");
    let amp_bound = number_after(w, "phase by up to ");
    let lag_bound = number_after(w, "table lag by up to ");
    assert!(!w.contains("remove the key"), "{w}");
    let (amp, lag) = table_errors_mdeg(&finished(&cfg));
    // The run is moved well past the threshold, within each bound, and not far inside the
    // lag's (the bound is the error's whole size turned across the amplitude).
    assert!(amp > 1.0 && lag > 100.0, "amplitude {amp}, lag {lag} mdeg");
    assert!(amp <= amp_bound, "amplitude {amp} mdeg, stated {amp_bound}");
    assert!(
        lag <= lag_bound && lag_bound < 3.0 * lag,
        "lag {lag} mdeg, stated {lag_bound}"
    );
}
