//! The Butterworth low-pass ticking a unit step against the golden vectors of
//! `fixtures/lowpass_step`: the step response of the prewarped bilinear Butterworth by partial
//! fractions in mpmath at 60 digits (`fixtures/generate.py`), which fixes the whole transfer
//! function (poles, zeros at z = -1, unit DC gain) whatever the section order or coefficient
//! convention.

#[path = "../../../fixtures/load.rs"]
mod load;

use gyroemu_core::Stage;
use gyroemu_lpf::{LowPass, LowPassDesign};
use load::{nums, Fixture};
use std::f64::consts::TAU;

/// Bound on `|y - y_exact|`: direct-form sections with poles next to `z = 1` lose about
/// `eps / (2 pi fc/fs)^2` of relative accuracy (the pole positions are differences of
/// coefficients near 2 and 1), plus a few eps of plain rounding. The constant leaves a margin
/// of several times over the worst measured (see the test's output).
fn tolerance(fc: f64, fs: f64) -> f64 {
    let w = TAU * fc / fs;
    4.0 * f64::EPSILON / (w * w) + 16.0 * f64::EPSILON
}

/// Largest error of the filter `(order, fc, fs)` on the fixture's step, over its indices.
fn step_error(order: usize, fc: f64, fs: f64, f: &Fixture) -> f64 {
    let ns = nums(&f.doc["n"]);
    let ys = nums(&f.doc["y"]);
    let design = LowPassDesign::Butterworth {
        order,
        cutoff_hz: fc,
    };
    let mut lp = LowPass::<f64>::new(design, fs).unwrap();
    let (mut n, mut err) = (0usize, 0.0f64);
    for (&at, &want) in ns.iter().zip(&ys) {
        let mut y = f64::NAN;
        while n <= at as usize {
            y = lp.tick(1.0);
            n += 1;
        }
        err = err.max((y - want).abs());
    }
    err
}

#[test]
fn butterworth_step_matches_the_exact_partial_fractions() {
    for f in load::family(env!("CARGO_MANIFEST_DIR"), "lowpass_step", 9) {
        let order = f.num("params/order") as usize;
        let (fc, fs) = (f.num("params/cutoff_hz"), f.num("params/fs_hz"));
        assert_eq!(
            nums(&f.doc["n"]).len(),
            nums(&f.doc["y"]).len(),
            "{}",
            f.name
        );
        let err = step_error(order, fc, fs, &f);
        let tol = tolerance(fc, fs);
        eprintln!(
            "{}: max |y - exact| {err:e} (tolerance {tol:e}, {:.2} of it)",
            f.name,
            err / tol
        );
        assert!(err < tol, "{}: {err:e} >= {tol:e}", f.name);
        // The tolerance resolves the design: a cutoff 1e-6 higher, or the neighbouring order,
        // must fail it.
        let off = step_error(order, fc * (1.0 + 1e-6), fs, &f);
        assert!(
            off > 10.0 * tol,
            "{}: fc * (1 + 1e-6) gives {off:e}",
            f.name
        );
        let other = if order > 1 { order - 1 } else { 2 };
        let off = step_error(other, fc, fs, &f);
        assert!(off > 1e3 * tol, "{}: order {other} gives {off:e}", f.name);
    }
}
