//! Phi and Gamma of uncoupled modes against the closed-form discretised damped oscillator.

use gyroemu_resonator::{ModeParams, Resonator, ResonatorParams};
use std::f64::consts::TAU;

/// Closed-form ZOH step of `q'' + 2 s q' + w0^2 q = f` over `t`: (Phi 2x2, Gamma 2x1).
fn closed_form(f0_hz: f64, q: f64, t: f64) -> ([[f64; 2]; 2], [f64; 2]) {
    let w0 = TAU * f0_hz;
    let s = w0 / (2.0 * q);
    let wd = (w0 * w0 - s * s).sqrt();
    let (sn, cs) = (wd * t).sin_cos();
    let e = (-s * t).exp();
    let phi = [
        [e * (cs + s / wd * sn), e * sn / wd],
        [-e * w0 * w0 / wd * sn, e * (cs - s / wd * sn)],
    ];
    // Gamma = A^-1 (Phi - I) B with A = [[0, 1], [-w0^2, -2s]], B = [0, 1].
    let gamma = [
        (1.0 - phi[1][1] - 2.0 * s * phi[0][1]) / (w0 * w0),
        phi[0][1],
    ];
    (phi, gamma)
}

#[test]
fn phi_and_gamma_match_closed_form_over_q_and_frequency() {
    let fs = 48_000.0;
    let mut worst: f64 = 0.0;
    for &q in &[10.0, 100.0, 1e3, 1e4, 1e5, 1e6] {
        for &ratio in &[
            1.0 / 16.0,
            1.0 / 10.0,
            1.0 / 7.0,
            1.0 / 5.0,
            1.0 / 4.0,
            1.0 / 3.0,
        ] {
            // Mode 2 differs from mode 1 so both blocks are exercised independently.
            let m1 = ModeParams {
                f0_hz: ratio * fs,
                q,
            };
            let m2 = ModeParams {
                f0_hz: 0.93 * ratio * fs,
                q: 0.5 * q,
            };
            let p = ResonatorParams {
                mode1: m1,
                mode2: m2,
                angular_gain: 0.6,
                quadrature_coupling_rad2_s2: 0.0,
                transduction_a_s_per_m: 1.0,
                fs_hz: fs,
            };
            let r = Resonator::<f64>::new(&p, 0.0).unwrap();
            let (phi, gamma) = (r.phi(), r.gamma());
            for (k, m) in [m1, m2].iter().enumerate() {
                let (pc, gc) = closed_form(m.f0_hz, m.q, 1.0 / fs);
                let w = TAU * m.f0_hz;
                // Compare in balanced units [w q, v] (input scaled by w), where every entry
                // is O(1): a 1e-12 bound there is 1e-12 of the matrix norm.
                let scale = [w, 1.0];
                for i in 0..2 {
                    for j in 0..2 {
                        let got = phi[2 * i + k][2 * j + k] * scale[i] / scale[j];
                        let want = pc[i][j] * scale[i] / scale[j];
                        worst = worst.max((got - want).abs());
                        // Uncoupled: no leakage into the other mode.
                        let other = phi[2 * i + k][2 * j + 1 - k] * scale[i] / scale[j];
                        assert!(other.abs() < 1e-14, "cross term {other}");
                    }
                    let got = gamma[2 * i + k][k] * scale[i] * w;
                    let want = gc[i] * scale[i] * w;
                    worst = worst.max((got - want).abs());
                    assert!(gamma[2 * i + k][1 - k].abs() * scale[i] * w < 1e-14);
                }
            }
        }
    }
    eprintln!("worst balanced |Phi, Gamma - closed form| = {worst:e}");
    assert!(worst < 1e-12, "worst {worst:e}");
}
