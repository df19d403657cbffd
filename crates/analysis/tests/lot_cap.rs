//! The work cap of a lot, checked while its devices are validated: a lot is refused without
//! `--force` exactly when its devices' work (as `lot_work` sums it for the run) passes
//! `MAX_POINT_SAMPLES`; a large lot is refused after the pass of devices that crosses the cap,
//! naming how many were validated, not after validating every device; a refused device still
//! comes first; `--force` lifts the cap.

use gyroemu_analysis::montecarlo::{lot_work, validate_lot_capped, LotRefusal};
use gyroemu_config::presets::preset;
use gyroemu_config::Config;
use gyroemu_experiment::MAX_POINT_SAMPLES;

/// The lot preset with a short settling and Q, three rates and 200 s of averaging: about 3e8
/// point-samples a device, so a few hundred devices pass the cap.
fn heavy() -> Config {
    let mut c = preset("m2tfg-montecarlo").unwrap();
    c.device.q = 200.0;
    c.experiment.rates_dps = vec![900.0, 1800.0, 2700.0];
    c.experiment.average_s = 200.0;
    c.experiment.settle_s = Some(0.1);
    c
}

fn lot(n: u64) -> Vec<u64> {
    (0..n).collect()
}

fn cap_message(r: Result<Vec<String>, LotRefusal>) -> String {
    match r {
        Err(LotRefusal::Cap(m)) => m,
        other => panic!("expected the cap's refusal, got {other:?}"),
    }
}

/// The smallest lot (devices 0..n) whose work passes the cap.
fn crossing(cfg: &Config) -> u64 {
    let per_device = lot_work(cfg, &[0]).0.point_samples;
    assert!(per_device > 0 && per_device < MAX_POINT_SAMPLES / 50);
    // Devices differ a little in work (their Q sets the settling); search near the mean.
    let guess = MAX_POINT_SAMPLES / per_device;
    let mut n = guess.saturating_sub(20).max(1);
    while lot_work(cfg, &lot(n)).0.point_samples <= MAX_POINT_SAMPLES {
        n += 1;
    }
    assert!(
        n > guess.saturating_sub(20).max(1),
        "search started past the crossing"
    );
    n
}

#[test]
fn a_lot_is_refused_exactly_when_its_work_passes_the_cap() {
    let cfg = heavy();
    let n = crossing(&cfg);
    validate_lot_capped(&cfg, &lot(n - 1), false).expect("at the cap or below: accepted");
    let m = cap_message(validate_lot_capped(&cfg, &lot(n), false));
    // Every device validated: the whole plan, in the figures the run would print.
    let work = lot_work(&cfg, &lot(n)).0;
    let expected = work.check_cap(false).unwrap_err();
    assert_eq!(m, expected);
    assert!(m.contains(&format!("{:.3e} point-samples", work.point_samples as f64)));
    assert!(m.contains("--force"), "{m}");
    validate_lot_capped(&cfg, &lot(n), true).expect("--force lifts the cap");
}

#[test]
fn a_large_lot_is_refused_after_the_pass_that_crosses_the_cap() {
    let cfg = heavy();
    let n = crossing(&cfg);
    let total = 1_000_000u64;
    let m = cap_message(validate_lot_capped(&cfg, &lot(total), false));
    let head = format!("of these {total} devices alone run ");
    let at = m.find(&head).unwrap_or_else(|| panic!("{m}"));
    let validated: u64 = m[..at]
        .trim_end()
        .rsplit(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap_or_else(|_| panic!("{m}"));
    assert!(
        validated >= n && validated < total / 100,
        "validated {validated} devices (crossing at {n}): {m}"
    );
    // The lower bound it states is the validated devices' own work.
    let bound = lot_work(&cfg, &lot(validated)).0.point_samples as f64;
    assert!(
        m.contains(&format!("alone run {bound:.3e} point-samples")),
        "{m}"
    );
    let mean = bound / validated as f64 * total as f64;
    assert!(
        m.contains(&format!("about {mean:.3e} for all {total}")),
        "{m}"
    );
}

#[test]
fn a_refused_device_comes_before_the_cap() {
    let mut cfg = heavy();
    // Devices drawn beyond 90 degrees of phase-shifter error are not valid boards.
    cfg.montecarlo.as_mut().unwrap().phase_shifter_sigma_deg = 50.0;
    let n = 2 * crossing(&heavy());
    match validate_lot_capped(&cfg, &lot(n), false) {
        Err(LotRefusal::Config(e)) => {
            let t = e.to_string();
            assert!(t.contains("board.phase_shifter_error_deg"), "{t}");
            assert!(t.contains(" of the lot, drawn from [montecarlo])"), "{t}");
        }
        other => panic!("expected the device's refusal, got {other:?}"),
    }
}
