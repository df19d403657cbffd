//! The sweep's line is fitted to the readings on their theory's branch: a rotating psi that
//! steps by more than a quarter turn between two rates (Q = 36000, -100 -> 100 deg/s: -53.1
//! -> +53.1 deg) is not moved a half turn before the fit (the summary's slope had read -0.19
//! for +0.42, its intercept -90 deg).

mod common;

use common::finished;
use gyroemu_config::{presets::preset, Config};
use gyroemu_experiment::fit::fit_line;

fn high_q() -> Config {
    let mut c = preset("m2tfg-rotating").unwrap();
    c.device.q = 36_000.0;
    c.experiment.settle_s = None;
    c.experiment.rates_dps = vec![-175.0, -100.0, 100.0, 175.0];
    c.experiment.average_s = 1.8;
    c.validate().unwrap();
    c
}

#[test]
fn a_steep_rotating_sweep_is_fitted_as_its_readings_lie() {
    let cfg = high_q();
    let res = finished(&cfg);
    assert!(res.problems.is_empty(), "{:?}", res.problems);
    let xs: Vec<f64> = res.points.iter().map(|p| p.rate_dps).collect();
    for k in 0..2 {
        let ys: Vec<f64> = res.points.iter().map(|p| p.phase_deg[k]).collect();
        let theory: Vec<f64> = res.points.iter().map(|p| p.theory_deg[k]).collect();
        // Each reading is its theory's (and on its branch), and the middle step is steep.
        for (y, t) in ys.iter().zip(&theory) {
            assert!((y - t).abs() < 1e-3, "mode {}: {y} against {t}", k + 1);
        }
        assert!(ys[2] - ys[1] > 90.0, "{ys:?}");
        // The summary's line is the least-squares line of the readings as written, and
        // the theory's line within what the readings differ from it.
        let plain = fit_line(&xs, &ys);
        let f = res.fit[k];
        assert_eq!(f.slope.to_bits(), plain.slope.to_bits(), "{f:?} {plain:?}");
        assert_eq!(f.r2.to_bits(), plain.r2.to_bits());
        let want = fit_line(&xs, &theory);
        assert!(
            (f.slope - want.slope).abs() < 1e-5 * want.slope,
            "{f:?} {want:?}"
        );
        assert!(f.slope > 0.0 && f.intercept.abs() < 1e-3, "{f:?}");
    }
}
