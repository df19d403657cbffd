//! The rule that states a Coriolis run's phases unresolved (`MIN_RESOLVED_PHASE_MDEG`) sits
//! above the floor the emulated chain actually reads to, and fires where the readings are
//! that floor rather than the rotation.

mod common;

use common::finished;
use gyroemu_config::{presets::preset, Config, MIN_RESOLVED_PHASE_MDEG};

fn coriolis(rates: &[f64], gain: f64) -> Config {
    let mut c = preset("m2tfg-coriolis").unwrap();
    c.experiment.rates_dps = rates.to_vec();
    c.experiment.average_s = 0.05;
    c.device.angular_gain = gain;
    c
}

fn stated(c: &Config) -> bool {
    c.validate()
        .unwrap()
        .iter()
        .any(|w| w.contains("the largest phase the rates give"))
}

/// The largest |reading - theory| (mdeg) and the largest |theory| (mdeg) of a run.
fn errors(c: &Config) -> (f64, f64) {
    let res = finished(c);
    let (mut err, mut th) = (0.0f64, 0.0f64);
    for p in &res.points {
        for k in 0..2 {
            err = err.max((p.phase_deg[k] - p.theory_deg[k]).abs() * 1e3);
            th = th.max(p.theory_deg[k].abs() * 1e3);
        }
    }
    (err, th)
}

#[test]
fn phases_at_the_bound_are_read_to_a_per_cent_and_far_below_it_are_rounding() {
    // Rates whose phases are ten times the bound: not stated, and read to 1 %.
    let c = coriolis(&[1.2e-7, 2.4e-7], 1.0);
    let (err, th) = errors(&c);
    assert!(th > 5.0 * MIN_RESOLVED_PHASE_MDEG && th < 20.0 * MIN_RESOLVED_PHASE_MDEG);
    assert!(!stated(&c));
    assert!(err < 0.01 * th, "error {err:e} mdeg of {th:e}");
    // A thousand times below the bound: stated, and the readings are mostly rounding.
    let c = coriolis(&[1.2e-11, 2.4e-11], 1.0);
    let (err, th) = errors(&c);
    assert!(stated(&c));
    assert!(
        err > 0.5 * th,
        "error {err:e} mdeg of {th:e}: resolved after all"
    );
}

#[test]
fn a_vanishing_gain_is_stated_and_rate_zero_alone_is_not() {
    assert!(stated(&coriolis(&[25.0, 175.0], 1e-30)));
    assert!(!stated(&coriolis(&[25.0, 175.0], 1.0)));
    // A null measurement at rest has no phase to resolve.
    assert!(!stated(&coriolis(&[0.0], 1.0)));
}
