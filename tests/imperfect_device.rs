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

/// Mode k's psi from the velocity sidebands of eq. 4 (THEORY.md section 6), known modulo a half
/// turn, degrees.
fn sideband_psi_deg(w0: f64, w2: f64, q: [f64; 2], k12: f64, f2: f64, rate_dps: f64) -> [f64; 2] {
    let j = Complex64::new(0.0, 1.0);
    let om = rate_dps.to_radians();
    let one = Complex64::new(0.5, 0.0);
    let vp = velocities(w0 + om, w0, w2, q[0], q[1], k12, 0.0, [one, -j * 0.5 * f2]);
    let vm = velocities(w0 - om, w0, w2, q[0], q[1], k12, 0.0, [one, j * 0.5 * f2]);
    let m = [
        (Complex64::new(1.0, 0.0), Complex64::new(1.0, 0.0)),
        (-j, j),
    ];
    [0, 1].map(|k| (0.5 * ((vm[k] / m[k].1).arg() - (vp[k] / m[k].0).arg())).to_degrees())
}

#[test]
fn psi_past_90_degrees_on_a_strongly_coupled_device_is_read_on_its_theorys_branch() {
    // k12 Q / w0^2 = 2 with the modes 7.5 Hz apart: mode 2's psi is about 91 to 96 degrees.
    // It was read as -89 to -84 (folded into (-90, 90]) beside a theory column of +91 to +96,
    // an error of -180 000 mdeg, exit 0.
    let text = r#"
[device]
f0_hz = 15000.0
q = 2000.0
angular_gain = 1.0
mode2_f0_offset_hz = 7.5
quadrature_coupling_rad2_s2 = 8882644.0
[drive]
f1 = 1.0
[experiment]
kind = "rotating"
rates_dps = [25.0, 100.0, 175.0]
average_s = 8.0
"#;
    let cfg = parse_config(text).unwrap();
    cfg.validate().unwrap();
    let r = run_sweep(&cfg, &|_, _| {}, None).unwrap();
    let (w0, w2) = (2.0 * PI * 15000.0, 2.0 * PI * 15007.5);
    for p in &r.points {
        let want = sideband_psi_deg(w0, w2, [2000.0; 2], 8_882_644.0, 1.0, p.rate_dps);
        for k in 0..2 {
            // The same psi modulo a half turn (the DAC hold moves it by about 1.3 mdeg here),
            // and on the same branch as the reported theory.
            let d = p.phase_deg[k] - want[k];
            let off = (d - 180.0 * (d / 180.0).round()) * 1e3;
            assert!(
                off.abs() < 2.0,
                "rate {} mode {}: {off} mdeg",
                p.rate_dps,
                k + 1
            );
            let err = (p.phase_deg[k] - p.theory_deg[k]) * 1e3;
            assert!(
                err.abs() < 2.0,
                "rate {} mode {}: {err} mdeg",
                p.rate_dps,
                k + 1
            );
        }
        assert!(p.phase_deg[1] > 90.0, "{p:?}");
    }
}

#[test]
fn the_theory_slope_of_a_q_mismatched_device_is_its_own() {
    // Mode-matched, Q1 = 2000, Q2 = 1000, F1 = F2. Solving the phasor equations at w0 to first
    // order in b = 2 lambda Omega: X1 = X1(0) (1 - j b Q2 / w0), X2 = X2(0) (1 - j b Q1 / w0), so
    // mode 1's Coriolis slope is 2 Q2 lambda / w0 and mode 2's 2 Q1 lambda / w0; each rotating
    // psi is its own mode's atan(2 Q Omega / w0). The ideal-device formula (Q1 for both) had
    // reported -50 % slope errors for these exact emulations.
    let w0 = 2.0 * PI * 15000.0;
    // At the Coriolis run's 1 and 2 deg/s the curve is straight; the rotating run's 90 and 180
    // deg/s (its averaging must span half a period) bend its chord by (x1^2 + x1 x2 + x2^2) / 3
    // = 1.04 % (x = 2 Q Omega / w0 of atan x).
    for (kind, want, rates, average, bend) in [
        (
            "coriolis",
            [2.0 * 1000.0 / w0, 2.0 * 2000.0 / w0],
            "[1.0, 2.0]",
            0.9,
            1e-4,
        ),
        (
            "rotating",
            [2.0 * 2000.0 / w0, 2.0 * 1000.0 / w0],
            "[90.0, 180.0]",
            2.0,
            2e-2,
        ),
    ] {
        let text = format!(
            "[device]\nf0_hz = 15000.0\nq = 2000.0\nq_mode2 = 1000.0\nangular_gain = 1.0\n\
             [drive]\nf1 = 1.0\n[experiment]\nkind = \"{kind}\"\nrates_dps = {rates}\n\
             average_s = {average}\n"
        );
        let cfg = parse_config(&text).unwrap();
        cfg.validate().unwrap();
        let r = run_sweep(&cfg, &|_, _| {}, None).unwrap();
        for k in 0..2 {
            let s = r.theory_slope_deg_per_dps[k];
            let theory = s / want[k] - 1.0;
            assert!(
                theory.abs() < 1e-6,
                "{kind} mode {}: {s} vs {}",
                k + 1,
                want[k]
            );
            let fit = r.fit[k].slope / s - 1.0;
            assert!(
                fit.abs() < bend,
                "{kind} mode {}: fit / theory - 1 = {fit}",
                k + 1
            );
        }
    }
}
