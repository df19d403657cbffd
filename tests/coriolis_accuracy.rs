//! Issue 3 accuracy: the emulated Coriolis phase shifts (Figs. 4 and 8) against the exact
//! theta_k of THEORY.md section 3, noise off, to 1 millidegree.
#![allow(clippy::needless_range_loop)] // mode indices address parallel arrays

mod common;
use common::*;

const TOL_MDEG: f64 = 1.0;

fn check(f0: f64, q: f64, lambda: f64, ratio: f64, rates: &[f64]) {
    let cfg = config("coriolis", f0, q, lambda, ratio, rates, 0.05);
    let r = run(&cfg);
    assert_eq!(r.points.len(), rates.len());
    for p in &r.points {
        let th = theta_deg(f0, q, lambda, 1.0, ratio, p.rate_dps);
        for k in 0..2 {
            let err = (p.phase_deg[k] - th[k]) * 1e3;
            assert!(
                err.abs() < TOL_MDEG,
                "f0 {f0} Q {q} F2/F1 {ratio} rate {} mode {}: {} vs {} deg ({err} mdeg)",
                p.rate_dps,
                k + 1,
                p.phase_deg[k],
                th[k]
            );
        }
    }
}

#[test]
fn tuning_fork_q_1e3_to_4e4_equal_and_unequal_drives() {
    for &q in &[1e3, 2e3, 1e4, 4e4] {
        for &ratio in &[1.0, 0.5] {
            check(15e3, q, 1.0, ratio, &[25.0, 100.0, 175.0]);
        }
    }
}

#[test]
fn baw_disk_up_to_2100_dps() {
    for &ratio in &[1.0, 0.5] {
        check(3e6, 1e4, 0.6, ratio, &[300.0, 1200.0, 2100.0]);
    }
}

#[test]
fn large_angles_stay_exact_not_linear() {
    // Q = 36 000 at 175 deg/s: theta = 66.80141 deg (THEORY.md section 8), far from a line.
    let cfg = config("coriolis", 15e3, 36_000.0, 1.0, 1.0, &[175.0], 0.05);
    let p = &run(&cfg).points[0];
    assert!(
        (p.phase_deg[0] - 66.80141).abs() < 1e-3,
        "{}",
        p.phase_deg[0]
    );
    assert!(
        (p.phase_deg[1] - 66.80141).abs() < 1e-3,
        "{}",
        p.phase_deg[1]
    );
}

#[test]
fn negative_rates_lag_negatively() {
    let cfg = config("coriolis", 15e3, 2e3, 1.0, 1.0, &[-100.0, 100.0], 0.05);
    let r = run(&cfg);
    assert!((r.points[0].phase_deg[0] + r.points[1].phase_deg[0]).abs() < 1e-6);
    assert!((r.points[1].phase_deg[0] - 4.23639).abs() < 1e-5);
}
