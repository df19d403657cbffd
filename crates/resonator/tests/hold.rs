//! The zero-order hold the plant realises on its force input: its response against the hold's
//! defining integral and its closed form, a null at fs and half a sample of delay at DC.

use gyroemu_resonator::hold_response;
use num_complex::Complex64;
use std::f64::consts::{PI, TAU};

#[test]
fn dac_hold_response_matches_the_hold_integral() {
    let fs = 1e6;
    let ts = 1.0 / fs;
    for f in [
        0.0, 1.0, 15_000.0, 123_456.7, 499_999.0, -300_000.0, 1.3e6, 2.0e6,
    ] {
        let h = hold_response(f, fs);
        // (1/Ts) * integral_0^Ts e^{-j 2 pi f t} dt, the hold's average, by 20 000-point
        // midpoint rule, which is exact enough here (error ~ (2 pi f Ts / M)^2 / 24).
        let m = 20_000;
        let mut acc = Complex64::new(0.0, 0.0);
        for i in 0..m {
            let t = (i as f64 + 0.5) / m as f64 * ts;
            acc += Complex64::from_polar(1.0, -TAU * f * t);
        }
        let want = acc / m as f64;
        assert!((h - want).norm() < 1e-7, "f = {f}: {h} vs {want}");
        // And the closed form (1 - e^{-j w Ts}) / (j w Ts)
        if f != 0.0 {
            let w = TAU * f * ts;
            let cf = (Complex64::new(1.0, 0.0) - Complex64::from_polar(1.0, -w))
                / Complex64::new(0.0, w);
            // (the closed form cancels at small w, losing ~1e-16 / w)
            assert!((h - cf).norm() < 1e-13 + 1e-15 / w.abs(), "f = {f}");
        }
    }
    assert_eq!(hold_response(0.0, fs), Complex64::new(1.0, 0.0));
    assert!(hold_response(fs, fs).norm() < 1e-16); // null at fs
                                                   // Group delay at DC: -d arg H / d omega = Ts/2.
    let df = 1.0;
    let gd = -(hold_response(df, fs).arg() - hold_response(-df, fs).arg()) / (TAU * 2.0 * df) * fs;
    assert!((gd - 0.5).abs() < 1e-9);
    // Gain at a 16-samples-per-period carrier: sinc(1/16).
    let g = hold_response(fs / 16.0, fs).norm();
    assert!((g - (PI / 16.0).sin() / (PI / 16.0)).abs() < 1e-15);
}
