//! A rate table's DAC-hold warning states what the board reads, exactly: the periodic steady
//! state of its own recursion (held drive, second-order step) against the continuous plant's.
//! Judged at a constant rate of +A it had missed 0.42 mdeg on a split, detuned device with
//! unequal drives (its +A shift crosses zero at 940 deg/s), and 9.7 mdeg of a detuned
//! table's amplitude (the hold's images scale the swing, at any rate).

mod common;

use common::{finished, number_after, table_errors_mdeg, warning};
use gyroemu_config::{parse_config, Config};

fn asymmetric() -> Config {
    parse_config(
        r#"
[device]
f0_hz = 4981.563
q = 2108.4
angular_gain = 1.0423
mode2_f0_offset_hz = -1.95146
q_mode2 = 1401.5
[drive]
f1 = 1.0
f2 = 2.0034
carrier_hz = 4978.791398
[board]
phase_shifter_error_deg = -1.1501
tia_pole_hz = 16104.9
[experiment]
kind = "coriolis"
rate_table = "sinusoid"
table_freq_hz = 0.6666
rates_dps = [940.0]
average_s = 3.0003
"#,
    )
    .unwrap()
}

/// A Q-50 device at 1 kHz driven 3 half-bandwidths off resonance (1030 Hz), a 40 Hz table,
/// the default board (16 samples per carrier period).
fn detuned() -> Config {
    parse_config(
        r#"
[device]
f0_hz = 1000.0
q = 50.0
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
carrier_hz = 1030.0
[experiment]
kind = "coriolis"
rate_table = "sinusoid"
table_freq_hz = 40.0
rates_dps = [500.0, 2000.0]
average_s = 0.5
"#,
    )
    .unwrap()
}

/// Q = 5 under a 200 Hz table of up to 3e5 deg/s at 240 kHz: the plant's step, second order in
/// the rate, is off by most of the figure (2 lambda Omega Ts = 0.044).
fn fast() -> Config {
    parse_config(
        r#"
[device]
f0_hz = 15000.0
q = 5.0
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
[board]
fs_hz = 240000.0
[experiment]
kind = "coriolis"
rate_table = "sinusoid"
table_freq_hz = 200.0
rates_dps = [100000.0, 300000.0]
average_s = 0.05
"#,
    )
    .unwrap()
}

#[test]
fn the_hold_warning_states_what_the_board_reads() {
    for cfg in [asymmetric(), detuned(), fast()] {
        let warnings = cfg.validate().unwrap();
        let (amp, lag) = table_errors_mdeg(&finished(&cfg));
        // The emulated board reads the hold well above the warning threshold (0.01 mdeg) ...
        assert!(amp > 0.1, "{amp}");
        // ... and the warning gives it: the board's steady state, to what the run's settling
        // and read-out leave (1e-3 of the figure, plus 1e-4 mdeg).
        let w = warning(&warnings, "zero-order hold");
        let (s_amp, s_lag) = (
            number_after(w, "by up to "),
            number_after(w, "amplitude and "),
        );
        assert!(
            (s_amp - amp).abs() < 1e-3 * amp + 1e-4,
            "stated {s_amp}, read {amp}"
        );
        assert!(
            (s_lag - lag).abs() < 1e-3 * lag + 1e-4,
            "stated {s_lag}, read {lag}"
        );
    }
}
