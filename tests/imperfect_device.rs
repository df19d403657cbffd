//! A mismatched device (mode frequency offset, unequal Q, stiffness coupling): the emulated
//! phases match the exact linear theory of the imperfect plant, computed here independently
//! by solving (j w I - A) X = B F for the 2-DOF model of THEORY.md section 2.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use gyroemu::config::parse_config;
use gyroemu::experiment::run_sweep;
use gyroemu::Complex64;
use std::f64::consts::PI;

/// Velocity phasors [v1, v2] of the continuous plant at angular frequency w (Cramer's rule on
/// the 2x2 system in displacement, then v = j w x).
fn velocities(
    w: f64,
    w1: f64,
    w2: f64,
    q1: f64,
    q2: f64,
    k12: f64,
    g: f64,
    f: [Complex64; 2],
) -> [Complex64; 2] {
    let j = Complex64::new(0.0, 1.0);
    // rows: (-w^2 + j w w1/q1 + w1^2) x1 + (-g j w + k12) x2 = f1 ; (g j w + k12) x1 + (...) x2 = f2
    let a11 = Complex64::new(w1 * w1 - w * w, w * w1 / q1);
    let a22 = Complex64::new(w2 * w2 - w * w, w * w2 / q2);
    let a12 = -j * g * w + k12;
    let a21 = j * g * w + k12;
    let det = a11 * a22 - a12 * a21;
    let x1 = (f[0] * a22 - a12 * f[1]) / det;
    let x2 = (a11 * f[1] - a21 * f[0]) / det;
    [j * w * x1, j * w * x2]
}

const BASE: &str = r#"
[device]
f0_hz = 15000.0
q = 1000.0
angular_gain = 1.0
mode2_f0_offset_hz = 2.0
q_mode2 = 800.0
quadrature_coupling_rad2_s2 = 3.0e5
[drive]
f1 = 1.0
f2 = 0.7
[board]
fs_hz = 240000.0
tia_pole_hz = 60000.0
lpf_cutoff_hz = 200.0
decimation = 100
"#;

#[test]
fn coriolis_on_a_mismatched_device_matches_the_linear_solve() {
    let text = format!(
        "{BASE}[experiment]\nkind = \"coriolis\"\nrates_dps = [50.0, 150.0]\naverage_s = 0.1\n"
    );
    let cfg = parse_config(&text).unwrap();
    cfg.validate().unwrap();
    let r = run_sweep(&cfg, &|_, _| {}, None).unwrap();
    let (w1, w2) = (2.0 * PI * 15000.0, 2.0 * PI * 15002.0);
    let f = [Complex64::new(1.0, 0.0), Complex64::new(0.0, -0.7)];
    let v0 = velocities(w1, w1, w2, 1000.0, 800.0, 3.0e5, 0.0, f);
    for p in &r.points {
        let g = 2.0 * p.rate_dps.to_radians();
        let v = velocities(w1, w1, w2, 1000.0, 800.0, 3.0e5, g, f);
        for k in 0..2 {
            let lag = (v0[k] / v[k]).arg().to_degrees();
            assert!(
                (p.phase_deg[k] - lag).abs() * 1e3 < 1.0,
                "rate {} mode {}: {} vs {lag}",
                p.rate_dps,
                k + 1,
                p.phase_deg[k]
            );
            assert!(
                (p.theory_deg[k] - lag).abs() < 1e-9,
                "reported theory {} vs {lag}",
                p.theory_deg[k]
            );
        }
    }
}

#[test]
fn rotating_on_a_mismatched_device_matches_the_sideband_solve() {
    let text = format!(
        "{BASE}[experiment]\nkind = \"rotating\"\nrates_dps = [90.0, 180.0]\naverage_s = 2.0\n"
    );
    let cfg = parse_config(&text).unwrap();
    cfg.validate().unwrap();
    let r = run_sweep(&cfg, &|_, _| {}, None).unwrap();
    let (w1, w2) = (2.0 * PI * 15000.0, 2.0 * PI * 15002.0);
    let j = Complex64::new(0.0, 1.0);
    for p in &r.points {
        let om = p.rate_dps.to_radians();
        // Sidebands of eq. 4: F1/2 at both on mode 1; -j F2/2 at w0+Omega, +j F2/2 at w0-Omega on mode 2.
        let vp = velocities(
            w1 + om,
            w1,
            w2,
            1000.0,
            800.0,
            3.0e5,
            0.0,
            [Complex64::new(0.5, 0.0), -j * 0.35],
        );
        let vm = velocities(
            w1 - om,
            w1,
            w2,
            1000.0,
            800.0,
            3.0e5,
            0.0,
            [Complex64::new(0.5, 0.0), j * 0.35],
        );
        let m = [
            (Complex64::new(1.0, 0.0), Complex64::new(1.0, 0.0)),
            (-j, j),
        ];
        for k in 0..2 {
            let psi = 0.5 * ((vm[k] / m[k].1).arg() - (vp[k] / m[k].0).arg());
            let psi = psi.to_degrees();
            assert!(
                (p.phase_deg[k] - psi).abs() * 1e3 < 1.0,
                "rate {} mode {}: {} vs {psi}",
                p.rate_dps,
                k + 1,
                p.phase_deg[k]
            );
        }
        // Unequal modes read different phases: the theory must not be the matched closed form.
        assert!((p.phase_deg[0] - p.phase_deg[1]).abs() > 1e-3);
    }
}
