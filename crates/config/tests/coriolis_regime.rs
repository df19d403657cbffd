//! A Coriolis or rate-table rate whose Coriolis coupling `2 lambda |Omega_z|` passes
//! `MAX_CORIOLIS_COUPLING` times the lower resonance is refused before any sample, naming the
//! rate and the rule: at 1e50 deg/s (or a gain of 1e50) validation had never returned (the
//! hold rule's plant exponential), and at 5e19 deg/s a run printed a phase 115 000 mdeg off
//! its theory with exit 0.

use gyroemu_config::{parse_config, MAX_CORIOLIS_COUPLING};

fn config(kind: &str, gain: f64, rates: &str, extra: &str) -> String {
    format!(
        "[device]\nf0_hz = 15000.0\nq = 2000.0\nangular_gain = {gain:e}\nmode2_f0_offset_hz = -2.0\n\
         [drive]\nf1 = 1.0\nf2 = 1.0\n\
         [board]\nfs_hz = 240000.0\ntia_gain_ohm = 1e6\ntia_pole_hz = 60000.0\nlpf_cutoff_hz = 200.0\n\
         [experiment]\nkind = \"{kind}\"\nrates_dps = [{rates}]\naverage_s = 0.05\n{extra}"
    )
}

/// The bound in deg/s for a gain, from the rule's statement (the lower resonance is mode 2's,
/// 2 Hz below f0).
fn bound_dps(gain: f64) -> f64 {
    MAX_CORIOLIS_COUPLING * core::f64::consts::TAU * 14998.0 / (2.0 * gain) / 1f64.to_radians()
}

fn refusal(text: &str) -> Option<String> {
    parse_config(text)
        .and_then(|c| c.validate().map(|_| ()))
        .err()
        .map(|e| e.to_string())
}

#[test]
fn absurd_rates_and_gains_are_refused_naming_the_rate_and_the_rule() {
    for (gain, rates) in [(1.0, "5e19"), (1.0, "25.0, 1e50"), (1e50, "25.0")] {
        let e = refusal(&config("coriolis", gain, rates, "")).expect("refused");
        assert!(
            e.contains("experiment.rates_dps[") && e.contains("Coriolis coupling"),
            "{e}"
        );
    }
    // The rate table's amplitude likewise.
    let table = "rate_table = \"sinusoid\"\ntable_freq_hz = 2.0\n";
    let e = refusal(&config("coriolis", 1.0, "1e50", table)).expect("refused");
    assert!(e.contains("Coriolis coupling"), "{e}");
}

#[test]
fn the_bound_sits_where_the_rule_states_it() {
    for gain in [1.0, 0.37, 2e3] {
        let b = bound_dps(gain);
        let within = refusal(&config("coriolis", gain, &format!("{:e}", 0.999 * b), ""));
        assert!(
            !within
                .as_deref()
                .unwrap_or("")
                .contains("Coriolis coupling"),
            "{within:?}"
        );
        let beyond = refusal(&config("coriolis", gain, &format!("{:e}", -1.001 * b), ""));
        assert!(
            beyond
                .as_deref()
                .unwrap_or("")
                .contains("Coriolis coupling"),
            "{beyond:?}"
        );
    }
}

#[test]
fn a_rotating_run_is_not_judged_by_it() {
    // Its rates turn the drive, not the device: the gain only rescales Fig. 6's axis.
    let e = refusal(&config("rotating", 1e50, "25.0", ""));
    assert!(
        !e.as_deref().unwrap_or("").contains("Coriolis coupling"),
        "{e:?}"
    );
}
