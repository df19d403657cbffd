//! The plant's eigenmodes and held response against their definitions: each reported (f0, Q)
//! is a root of the coupled modes' characteristic equation, uncoupled modes come back as
//! configured, and the held response with the hold divided out tends to the continuous one.

use core::f64::consts::TAU;
use gyroemu_resonator::{continuous_steady_state, ModeParams, Resonator, ResonatorParams};
use gyroemu_theory::{coupled_modes, held_response};
use num_complex::Complex64;

fn plant(m1: (f64, f64), m2: (f64, f64), k12: f64, fs_hz: f64) -> ResonatorParams {
    ResonatorParams {
        mode1: ModeParams {
            f0_hz: m1.0,
            q: m1.1,
        },
        mode2: ModeParams {
            f0_hz: m2.0,
            q: m2.1,
        },
        angular_gain: 0.8,
        quadrature_coupling_rad2_s2: k12,
        transduction_a_s_per_m: 1e-6,
        fs_hz,
    }
}

#[test]
fn uncoupled_modes_come_back_as_configured_and_named_for_themselves() {
    for (m1, m2) in [
        ((15e3, 2000.0), (15.1e3, 900.0)),
        ((15e3, 2000.0), (14.2e3, 50.0)), // mode 2 below mode 1
        ((1e3, 10.0), (1e3, 400.0)),      // matched, different Q
    ] {
        let got = coupled_modes(&plant(m1, m2, 0.0, 240e3));
        for (g, want) in got.iter().zip([m1, m2]) {
            assert!((g.0 - want.0).abs() <= 1e-9 * want.0, "{got:?}");
            assert!((g.1 - want.1).abs() <= 1e-8 * want.1, "{got:?}");
        }
    }
}

#[test]
fn each_coupled_mode_is_a_root_of_the_characteristic_equation() {
    // (s^2 + w1 s / Q1 + w1^2)(s^2 + w2 s / Q2 + w2^2) = k^2 at each eigenvalue s, rebuilt
    // from the reported f0 and Q: |s| = 2 pi f0, Re s = -|s| / (2 Q). Near a root the
    // residual is ill-conditioned, so the check is the Newton step to the root.
    for (m1, m2, k) in [
        ((15e3, 2000.0), (15.05e3, 1500.0), 4e5),
        ((15e3, 2000.0), (15e3, 2000.0), 2e6),
        ((1e3, 20.0), (1.3e3, 35.0), -3e5),
    ] {
        let p = plant(m1, m2, k, 240e3);
        let (w1, w2) = (TAU * m1.0, TAU * m2.0);
        let d = |s: Complex64, w: f64, q: f64| s * s + s * (w / q) + w * w;
        let modes = coupled_modes(&p);
        for &(f0, q) in &modes {
            let r = TAU * f0;
            let re = -r / (2.0 * q);
            let s = Complex64::new(re, (r * r - re * re).sqrt());
            let (a, b) = (d(s, w1, m1.1), d(s, w2, m2.1));
            // One Newton step from s to the root: its size, relative to |s|, is how far the
            // reported mode is from an exact eigenvalue.
            let da = s * 2.0 + w1 / m1.1;
            let db = s * 2.0 + w2 / m2.1;
            let step = (a * b - k * k) / (da * b + a * db);
            assert!(
                step.norm() <= 1e-12 * s.norm(),
                "{m1:?} {m2:?} k {k}: mode ({f0}, {q}) is {} off a root",
                step.norm() / s.norm()
            );
        }
        // Two distinct modes, the first dominated by mode 1: nearer its own frequency.
        assert!((modes[0].0 - modes[1].0).abs() > 0.0, "{modes:?}");
        if m1.0 != m2.0 {
            assert!(
                (modes[0].0 - m1.0).abs() < (modes[0].0 - m2.0).abs(),
                "{modes:?}"
            );
        }
    }
    // Matched and nearly undamped: the coupling splits them to sqrt(w0^2 -+ k).
    let (w0, k) = (TAU * 15e3, 2e6);
    let modes = coupled_modes(&plant((15e3, 1e9), (15e3, 1e9), k, 240e3));
    let mut f: Vec<f64> = modes.iter().map(|m| m.0).collect();
    f.sort_by(f64::total_cmp);
    let want = [(w0 * w0 - k).sqrt() / TAU, (w0 * w0 + k).sqrt() / TAU];
    for (g, w) in f.iter().zip(want) {
        assert!((g - w).abs() <= 1e-9 * w, "{f:?} against {want:?}");
    }
}

#[test]
fn the_held_response_with_the_hold_divided_out_tends_to_the_continuous_one() {
    // At 256 samples per period the exactly discretised plant under a held drive, over the
    // hold's own response, differs from the continuous plant by the hold's images only.
    let f0 = 1e3;
    let p = plant((f0, 200.0), (1.01 * f0, 150.0), 3e4, 256.0 * f0);
    let r = Resonator::<f64>::new(&p, 0.0).unwrap();
    for m in 0..2 {
        for f in [0.97 * f0, f0, 1.012 * f0] {
            let got = held_response(&r, f, m);
            let mut force = [Complex64::new(0.0, 0.0); 2];
            force[m] = Complex64::new(1.0, 0.0);
            let x = continuous_steady_state(&p, 0.0, f, force);
            for k in 0..2 {
                let want = x[2 + k];
                assert!(
                    (got[k] - want).norm() <= 1e-3 * want.norm().max(x[2 + m].norm() * 1e-3),
                    "force on mode {}, {f} Hz, mode {}: {} against {want}",
                    m + 1,
                    k + 1,
                    got[k]
                );
            }
        }
    }
}
