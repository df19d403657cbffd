//! Issue 14 point 1: the carrier is its own setting. A drive detuned from the resonance is
//! emulated and read out against the exact continuous-time steady state of the plant at the
//! carrier (the Coriolis shift and the rotating psi of a detuned drive), and the shift itself
//! follows the detuned circular mode of THEORY.md section 3: with F1 = F2 rotation detunes
//! the circular mode by lambda Omega, so the lag is atan(tau (D + lambda Omega)) - atan(tau D)
//! for a carrier D = w_c - w0 away (envelope model, relative error of order 1/Q).
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use std::f64::consts::PI;

#[test]
fn a_detuned_drive_reads_the_exact_theory_of_its_carrier() {
    let (f0, q) = (15e3, 2000.0);
    let half_bw = f0 / (2.0 * q); // 3.75 Hz
    for kind in ["coriolis", "rotating"] {
        let mut c = config(kind, f0, q, 1.0, 1.0, &[25.0, 100.0, 175.0], 8.0);
        c.drive.carrier_hz = Some(f0 + 2.0 * half_bw);
        c.validate().unwrap();
        let r = run(&c);
        assert!(r.problems.is_empty(), "{:?}", r.problems);
        // The 16-samples-per-period hold budget of the tuned board, 1e-3 mdeg.
        for k in 0..2 {
            assert!(r.max_abs_error_mdeg(k) < 1e-3, "{kind} mode {k}: {r:?}");
        }
        if kind == "coriolis" {
            let tau = q / (PI * f0);
            let d = 2.0 * PI * 2.0 * half_bw;
            for p in &r.points {
                let w = p.rate_dps.to_radians();
                let want = ((tau * (d + w)).atan() - (tau * d).atan()).to_degrees();
                assert!(
                    (p.phase_deg[0] / want - 1.0).abs() < 2e-3,
                    "{p:?} vs {want}"
                );
                // Detuning by a bandwidth shrinks the slope to a fifth of the tuned one.
                let tuned = theta_deg(f0, q, 1.0, 1.0, 1.0, p.rate_dps)[0];
                assert!(p.phase_deg[0] < 0.3 * tuned);
            }
        }
    }
}

#[test]
fn the_carrier_must_be_below_nyquist() {
    let mut c = config("coriolis", 15e3, 2000.0, 1.0, 1.0, &[25.0], 1.0);
    c.drive.carrier_hz = Some(130e3);
    let e = c.validate().unwrap_err();
    assert_eq!(e.key.as_deref(), Some("drive.carrier_hz"), "{e}");
    assert!(e.to_string().contains("Nyquist"), "{e}");
}
