//! A settling, hand-set or the default, states what the plant's and the stage-1 low-pass's
//! start-up leave in the averaging window (a bound that holds and is not loose by more than
//! 10x), and a rate table whose output rate aliases two demodulated harmonics onto each other
//! is refused before any sample (it read degrees off with exit 0).

mod common;
use common::*;
use gyroemu::config::parse_config;

/// The number the settling warning states between `before` and `unit` (None: no settling
/// warning).
fn stated(warnings: &[String], before: &str, unit: &str) -> Option<f64> {
    let w = warnings
        .iter()
        .find(|w| w.starts_with("experiment.settle_s") || w.starts_with("the default settling"))?;
    let rest = &w[w.find(before)? + before.len()..];
    rest[..rest.find(unit)?].parse().ok()
}

/// The bound, mdeg, the settling warning states (None: no settling warning).
fn stated_bound_mdeg(warnings: &[String]) -> Option<f64> {
    stated(warnings, "by up to ", " mdeg")
}

/// Rotating run, Q = 200 at 15 kHz (tau = 4.2 ms), `settle_s` by hand; the largest error of
/// psi against THEORY.md section 4's closed form, mdeg, and the stated bound.
fn rotating(lpf: &str, settle_s: f64, average_s: f64) -> (f64, Option<f64>) {
    let text = format!(
        r#"
[device]
f0_hz = 15000.0
q = 200.0
angular_gain = 1.0
[drive]
f1 = 1.0
[board]
fs_hz = 240000.0
tia_pole_hz = 60000.0
{lpf}
[experiment]
kind = "rotating"
rates_dps = [360.0, 540.0]
average_s = {average_s}
settle_s = {settle_s}
"#
    );
    let cfg = parse_config(&text).unwrap();
    let bound = stated_bound_mdeg(&cfg.validate().unwrap());
    let r = run(&cfg);
    let mut worst: f64 = 0.0;
    for p in &r.points {
        for k in 0..2 {
            worst = worst.max(((p.phase_deg[k] - psi_deg(15000.0, 200.0, p.rate_dps)) * 1e3).abs());
        }
    }
    (worst, bound)
}

/// An 8th-order low-pass at 3 Hz after 0.5 s (118 tau, far past the old 10.6 tau rule): psi
/// was 0.38 deg off with no warning. The start-up left is now stated, it holds, and it is
/// within 10x of the error.
#[test]
fn a_slow_lowpass_start_up_is_stated_with_a_bound_that_holds() {
    for settle in [0.5, 1.0] {
        let (err, bound) = rotating(
            "lpf_order = 8\nlpf_cutoff_hz = 3.0\ndecimation = 1000",
            settle,
            1.0,
        );
        let bound = bound.expect("a settling warning");
        assert!(err > 10.0, "the case must show the defect: {err} mdeg");
        assert!(
            err <= bound && bound <= 10.0 * err,
            "settle {settle}: {err} mdeg against the stated {bound}"
        );
    }
}

/// The plant alone (a fast low-pass) at 7 tau: the old warning claimed "above 1 mdeg remain"
/// whatever the size; the bound e^(-settle/tau) tau/T now holds and is within 10x.
#[test]
fn the_plant_start_up_bound_holds_at_seven_tau() {
    let tau = 200.0 / (std::f64::consts::PI * 15000.0);
    let (err, bound) = rotating(
        "lpf_order = 4\nlpf_cutoff_hz = 200.0\ndecimation = 100",
        7.0 * tau,
        0.5,
    );
    let bound = bound.expect("a settling warning");
    assert!(
        err <= bound && bound <= 10.0 * err,
        "{err} mdeg against the stated {bound}"
    );
}

/// The default settling states nothing.
#[test]
fn the_default_settling_states_no_start_up() {
    let text = "[device]\nf0_hz = 15000.0\nq = 200.0\nangular_gain = 1.0\n[drive]\nf1 = 1.0\n[board]\nfs_hz = 240000.0\nlpf_order = 8\nlpf_cutoff_hz = 3.0\ndecimation = 1000\n[experiment]\nkind = \"rotating\"\nrates_dps = [360.0]\naverage_s = 1.0\n";
    let w = parse_config(text).unwrap().validate().unwrap();
    assert_eq!(stated_bound_mdeg(&w), None, "{w:?}");
}

/// A Butterworth's slowest pole decays at 2 pi fc sin(pi/(2 order)): an eighth-order one at
/// half a fourth-order one's rate. After the old default (16 tau plus 40 low-pass time
/// constants, whatever the order) a rotating reading behind an eighth-order 0.5 Hz low-pass was
/// 4.6 mdeg off, and a rate table behind a sixth-order one tens of degrees, with no word: the
/// rule judged only a hand-set settle_s. The default now gives every order the fourth order's
/// decay, and the rule judges it too: the reading is within 0.01 mdeg of the closed form, or
/// the bound it states holds.
#[test]
fn the_default_settling_holds_for_every_low_pass_order() {
    let rotating = parse_config(
        "[device]\nf0_hz = 15000.0\nq = 2000.0\nangular_gain = 1.0\n[drive]\nf1 = 1.0\n[board]\nfs_hz = 240000.0\ntia_pole_hz = 60000.0\nlpf_order = 8\nlpf_cutoff_hz = 0.5\n[experiment]\nkind = \"rotating\"\nrates_dps = [25.0, 100.0, 150.0, 170.0]\naverage_s = 8.0\n",
    )
    .unwrap();
    assert_eq!(rotating.experiment.settle_s, None);
    let w = rotating.validate().unwrap();
    assert_eq!(stated_bound_mdeg(&w), None, "{w:?}");
    let r = run(&rotating);
    for p in &r.points {
        for k in 0..2 {
            let err = (p.phase_deg[k] - psi_deg(15000.0, 2000.0, p.rate_dps)) * 1e3;
            assert!(err.abs() < 0.01, "{} deg/s: {err} mdeg", p.rate_dps);
        }
    }
    // A sixth-order 2.2 Hz low-pass before a 2 Hz table and swings up to 2000 deg/s: the
    // read-out divides up to 15 harmonics by the filter's small gains there, so what is left
    // of its start-up is stated, and holds (it read 22.6 deg for 6.5 at 175 deg/s before).
    let table = parse_config(
        "[device]\nf0_hz = 15000.0\nq = 2000.0\nangular_gain = 1.0\n[drive]\nf1 = 1.0\nf2 = 1.0\n[board]\nfs_hz = 240000.0\ntia_pole_hz = 60000.0\nlpf_order = 6\nlpf_cutoff_hz = 2.2\n[experiment]\nkind = \"coriolis\"\nrate_table = \"sinusoid\"\ntable_freq_hz = 2.0\nrates_dps = [175.0, 1000.0, 2000.0]\naverage_s = 2.0\n",
    )
    .unwrap();
    let w = table.validate().unwrap();
    let bound = stated_bound_mdeg(&w).expect("a settling warning");
    let lag_bound = stated_lag_deg(&w).expect("a lag bound");
    let (amp, lag) = table_errors(&table);
    assert!(
        amp <= bound && lag <= lag_bound,
        "{amp} mdeg / {lag} deg against {bound} / {lag_bound}"
    );
    // And the default grows with the order only above the fourth (the presets' order keeps
    // its settling, and so its bits).
    let share = |order: usize| {
        let mut c = rotating.clone();
        c.board.lpf_order = order;
        c.lowpass_settle_s() * 2.0 * std::f64::consts::PI * 0.5
    };
    for order in 1..=4 {
        assert_eq!(share(order), 40.0, "order {order}");
    }
    // e-folds of the slowest pole at the default: the fourth order's 40 sin(pi/8) = 15.3.
    for order in 4..=8 {
        let folds = share(order) * (std::f64::consts::PI / (2.0 * order as f64)).sin();
        assert!((folds - 15.307).abs() < 1e-3, "order {order}: {folds}");
    }
}

fn table(table_hz: f64, decimation: usize) -> String {
    format!(
        r#"
[device]
f0_hz = 15000.0
q = 2000.0
angular_gain = 1.0
[drive]
f1 = 1.0
[board]
fs_hz = 240000.0
tia_pole_hz = 60000.0
lpf_order = 2
lpf_cutoff_hz = 60.0
decimation = {decimation}
[experiment]
kind = "coriolis"
rate_table = "sinusoid"
table_freq_hz = {table_hz:?}
rates_dps = [300.0, 600.0, 900.0]
average_s = 0.4
"#
    )
}

/// fs_out = 200 Hz = 8 x 25 Hz and 250 Hz = 10 x 25 Hz: harmonics n and n + 8 (or 10) are one
/// frequency at the output instants and the read-out demodulates -5 ..= 5: refused, naming
/// board.decimation (they read 3.989 deg against 1.889 and -1591 mdeg, exit 0).
#[test]
fn an_output_rate_that_aliases_table_harmonics_together_is_refused() {
    for (m, d) in [(1200, 8), (960, 10)] {
        let e = parse_config(&table(25.0, m))
            .unwrap()
            .validate()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("board.decimation") && e.contains(&format!("n + {d}")),
            "{e}"
        );
    }
}

/// Just outside the threshold (alias distance 4e-5 cycles of the window, 4x the refusal's
/// 1e-5) the table is read right: the amplitude matches the exact harmonic-balance theory
/// to within the 0.01 mdeg the other rules state (the 2 f_c product's alias).
#[test]
fn a_table_just_off_the_alias_is_accepted_and_read_right() {
    // delta = 8 (ft - 25) = 1e-4 Hz over the 0.4 s window: 4e-5 cycles.
    let cfg = parse_config(&table(25.0 + 1e-4 / 8.0, 1200)).unwrap();
    cfg.validate().unwrap();
    let r = run(&cfg);
    for p in &r.points {
        for k in 0..2 {
            let err = (p.phase_deg[k] - p.theory_deg[k]) * 1e3;
            assert!(
                err.abs() < 0.02,
                "{} deg/s mode {}: {err} mdeg",
                p.rate_dps,
                k + 1
            );
        }
    }
}

/// The settling warning names the low-pass's order plainly (it had printed "8th", "1th",
/// "2th", "3th order").
#[test]
fn the_settle_warning_names_the_low_pass_order_plainly() {
    for order in [1, 2, 3, 8] {
        let text = format!(
            "[device]\nf0_hz = 15000.0\nq = 200.0\nangular_gain = 1.0\n[drive]\nf1 = 1.0\n[board]\nfs_hz = 240000.0\nlpf_order = {order}\nlpf_cutoff_hz = 3.0\ndecimation = 1000\n[experiment]\nkind = \"rotating\"\nrates_dps = [360.0]\naverage_s = 1.0\nsettle_s = 0.3\n"
        );
        let w = parse_config(&text).unwrap().validate().unwrap();
        let s = w
            .iter()
            .find(|w| w.starts_with("experiment.settle_s"))
            .unwrap_or_else(|| panic!("order {order}: {w:?}"));
        assert!(s.contains(&format!("(order {order} at 3 Hz)")), "{s}");
        assert!(!s.contains("th order"), "{s}");
    }
}

/// The m2tfg rate table (tau = 0.764 s) with 2 s windows and `settle_s` by hand.
fn m2tfg_table(settle_s: f64, lpf: &str, q: f64) -> gyroemu::config::Config {
    parse_config(&format!(
        r#"
[device]
f0_hz = 15000.0
q = {q:?}
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
[board]
fs_hz = 240000.0
tia_pole_hz = 60000.0
{lpf}
decimation = 100
[experiment]
kind = "coriolis"
rate_table = "sinusoid"
table_freq_hz = 2.0
rates_dps = [25.0, 175.0]
average_s = 2.0
settle_s = {settle_s:?}
"#
    ))
    .unwrap()
}

/// The largest amplitude error (mdeg) and lag error (deg) of a table run against the exact
/// harmonic-balance theory.
fn table_errors(cfg: &gyroemu::config::Config) -> (f64, f64) {
    let r = run(cfg);
    let (mut amp, mut lag): (f64, f64) = (0.0, 0.0);
    for p in &r.points {
        for k in 0..2 {
            amp = amp.max(((p.phase_deg[k] - p.theory_deg[k]) * 1e3).abs());
            let l = p.table_lag_deg.unwrap()[k] - p.table_lag_theory_deg.unwrap()[k];
            lag = lag.max(l.abs());
        }
    }
    (amp, lag)
}

/// The table lag bound, deg, the settling warning states.
fn stated_lag_deg(warnings: &[String]) -> Option<f64> {
    stated(warnings, "table lag by up to ", " deg")
}

/// The rate-table bound had charged the whole plant start-up to every demodulated harmonic:
/// settle_s equal to the derived default (a run identical to leaving it out) warned "up to
/// 0.046 mdeg", and 13 s warned 0.017 mdeg against 1.7e-6 measured. At or above the default
/// nothing is stated now, and the run is within 0.01 mdeg of theory. Below it, and with a slow
/// low-pass whose start-up is real (degrees), the stated bounds hold against the runs.
#[test]
fn a_table_settle_at_or_above_the_default_is_not_warned_and_shorter_ones_hold() {
    let lpf = "lpf_cutoff_hz = 200.0";
    let tau = 36000.0 / (std::f64::consts::PI * 15000.0);
    let default = 16.0 * tau + 40.0 / (2.0 * std::f64::consts::PI * 200.0);
    for settle in [default, 13.0, 20.0] {
        let cfg = m2tfg_table(settle, lpf, 36000.0);
        let w = cfg.validate().unwrap();
        assert_eq!(stated_bound_mdeg(&w), None, "settle {settle}: {w:?}");
    }
    let (amp, _) = table_errors(&m2tfg_table(13.0, lpf, 36000.0));
    assert!(amp < 0.01, "{amp} mdeg");
    // Plant start-up (8 and 10 s), and a 2.5 Hz low-pass's own start-up after 0.5 and 1.5 s
    // (Q = 2000: the plant settles fast; measured up to 1.5 deg amplitude and 2.6 deg lag).
    for (settle, lpf, q) in [
        (8.0, lpf, 36000.0),
        (10.0, lpf, 36000.0),
        (0.5, "lpf_cutoff_hz = 2.5", 2000.0),
        (1.5, "lpf_cutoff_hz = 2.5", 2000.0),
    ] {
        let cfg = m2tfg_table(settle, lpf, q);
        let w = cfg.validate().unwrap();
        let bound = stated_bound_mdeg(&w).expect("a settling warning");
        let lag_bound = stated_lag_deg(&w).expect("a lag bound");
        let (amp, lag) = table_errors(&cfg);
        assert!(
            amp <= bound && lag <= lag_bound,
            "settle {settle}, {lpf}: {amp} mdeg / {lag} deg against {bound} / {lag_bound}"
        );
    }
}

/// The table-alias refusal offers removing board.decimation only with the derived value it
/// would give, which then differs from the hand-set one.
#[test]
fn the_alias_refusal_names_the_derived_decimation() {
    let e = parse_config(&table(25.0, 1200))
        .unwrap()
        .validate()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("or remove the key for the derived one (196)"),
        "{e}"
    );
}

/// A rate table on a carrier 0.01 Hz off 15000 Hz at 240 kHz: the DAC's 16-sample rounding
/// pattern drifts through every offset every 6 s, and the drives' phases and ratio wobble at
/// harmonics of that beat, some near the table frequency, which the read-out takes as the
/// table's. Reviewers measured 22 mdeg (8 bits) and 1074 mdeg (4 bits) against the run without
/// the DAC, with no warning. Now stated, and the change stays within the bound, in the table
/// response's amplitude and in its lag: the lag is the fundamental's angle, so a slow rate's
/// small swing turns by far more (the bound had been stated as if the amplitude's change were
/// the lag's: 12.9 deg of lag moved at 5 deg/s, 1.2 deg stated). A 12-bit DAC at 15000.0002
/// Hz moved the lag 612 mdeg at 5 deg/s, 27.8 stated.
#[test]
fn a_rate_table_on_a_drifting_dac_pattern_is_stated_and_holds() {
    for (bits, carrier, rates) in [
        (4, 15000.01, "[30.0, 120.0]"),
        (8, 15000.01, "[30.0, 120.0]"),
        (12, 15000.0002, "[5.0, 25.0]"),
    ] {
        let text = |dac: &str| {
            format!(
                "[device]\nf0_hz = 15000.0\nq = 2000.0\nangular_gain = 1.0\n[drive]\nf1 = 1.0\nf2 = 1.0\ncarrier_hz = {carrier:?}\n[board]\nfs_hz = 240000.0\ntia_gain_ohm = 1e6\ntia_pole_hz = 60000.0\nlpf_order = 4\nlpf_cutoff_hz = 200.0\ndecimation = 100\ndac_full_scale = 1.5\n{dac}\n[experiment]\nkind = \"coriolis\"\nrate_table = \"sinusoid\"\ntable_freq_hz = 2.0\nrates_dps = {rates}\naverage_s = 2.0\n"
            )
        };
        let cfg = parse_config(&text(&format!("dac_bits = {bits}"))).unwrap();
        let w = cfg.validate().unwrap();
        let s = w
            .iter()
            .find(|s| s.starts_with("board.dac_bits"))
            .unwrap_or_else(|| panic!("{bits} bits: {w:?}"));
        let rest = &s[s.find("by up to ").unwrap() + 9..];
        let bound: f64 = rest[..rest.find(" mdeg").unwrap()].parse().unwrap();
        let (a, b) = (run(&cfg), run(&parse_config(&text("")).unwrap()));
        let mut change: f64 = 0.0;
        for (p, q) in a.points.iter().zip(&b.points) {
            let (lp, lq) = (p.table_lag_deg.unwrap(), q.table_lag_deg.unwrap());
            for k in 0..2 {
                change = change.max(((p.phase_deg[k] - q.phase_deg[k]) * 1e3).abs());
                change = change.max(((lp[k] - lq[k]) * 1e3).abs());
            }
        }
        assert!(
            change > 1.0,
            "{bits} bits: the case must show the effect: {change} mdeg"
        );
        assert!(change <= bound, "{bits} bits: {change} > {bound} mdeg");
    }
}

/// Within a cycle of the window of coinciding (but not refused), the read-out's leak solve is
/// ill-conditioned: a 100.01 Hz table at a 400 Hz output rate behind a 150 Hz low-pass read
/// 117.6 deg for a theory of 31.8 deg, exit 0, unwarned (a review's run at fs = 960 kHz). Now
/// warned; the same board at decimation 2000 (output 480 Hz, read right to 0.004 mdeg) is not.
#[test]
fn a_table_near_an_alias_is_warned() {
    let text = |decimation: usize| {
        format!(
            "[device]\nf0_hz = 15000.0\nq = 36000.0\nangular_gain = 1.0\n[drive]\nf1 = 1.0\nf2 = 1.0\n[board]\nfs_hz = 960000.0\ntia_pole_hz = 200000.0\nlpf_cutoff_hz = 150.0\ndecimation = {decimation}\n[experiment]\nkind = \"coriolis\"\nrate_table = \"sinusoid\"\ntable_freq_hz = 100.01\nrates_dps = [20000.0]\naverage_s = 0.2\n"
        )
    };
    let near = parse_config(&text(2400)).unwrap().validate().unwrap();
    assert!(
        near.iter()
            .any(|w| w.contains("board.decimation = 2400") && w.contains("ill-conditioned")),
        "{near:?}"
    );
    let clear = parse_config(&text(2000)).unwrap().validate().unwrap();
    assert!(
        !clear.iter().any(|w| w.contains("ill-conditioned")),
        "{clear:?}"
    );
}
