//! Steady states: the held-input phasor against a simulation of the plant, and the
//! continuous phasor against THEORY.md section 3 and against an exactly sinusoidal drive
//! simulated in this test (drive oscillator appended to the state before exponentiating).

use gyroemu_core::{Complex64, Stage};
use gyroemu_resonator::{continuous_steady_state, ModeParams, Resonator, ResonatorParams};
use nalgebra::SMatrix;
use std::f64::consts::{PI, TAU};

const FS: f64 = 16_000.0;
const F0: f64 = 1_000.0;

fn c(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

/// `Re{X e^{j 2 pi k / 16}}` (f/fs = 1/16 exactly, so the phase is exact mod 1 turn).
fn phasor_at(x: Complex64, n: usize) -> f64 {
    let (s, co) = (TAU * (n % 16) as f64 / 16.0).sin_cos();
    (x * c(co, s)).re
}

/// Largest error of samples `n0..n0+len` against the phasors, relative to the largest phasor
/// of each group (displacements, velocities).
fn rel_err(xs: &[[f64; 4]], n0: usize, want: &[Complex64; 4]) -> f64 {
    let mut worst: f64 = 0.0;
    for (k, x) in xs.iter().enumerate() {
        for g in 0..2 {
            let scale = want[2 * g].norm().max(want[2 * g + 1].norm());
            for i in 0..2 {
                let e = (x[2 * g + i] - phasor_at(want[2 * g + i], n0 + k)).abs() / scale;
                worst = worst.max(e);
            }
        }
    }
    worst
}

fn general_params(q: f64) -> ResonatorParams {
    ResonatorParams {
        mode1: ModeParams { f0_hz: F0, q },
        mode2: ModeParams {
            f0_hz: 1.003 * F0,
            q: 1.6 * q,
        },
        angular_gain: 0.8,
        quadrature_coupling_rad2_s2: 1e4,
        transduction_a_s_per_m: 2.5,
        fs_hz: FS,
    }
}

#[test]
fn held_drive_settles_to_held_steady_state() {
    for &q in &[50.0, 1000.0] {
        let p = general_params(q);
        let omega = 20.0;
        let mut r = Resonator::<f64>::new(&p, omega).unwrap();
        let (f1, f2) = (1.0, 0.7);
        // u[n] = Re{F e^{j w n Ts}} with F = [F1, -j F2]: f1 = F1 cos, f2 = F2 sin.
        let force = [c(f1, 0.0), c(0.0, -f2)];
        let want = r.held_steady_state(F0, force);
        let tau_s = 2.0 * q.max(1.6 * q) / (TAU * F0);
        let n_settle = (40.0 * tau_s * FS) as usize;
        let mut tail = Vec::new();
        for n in 0..n_settle + 64 {
            let (s, co) = (TAU * (n % 16) as f64 / 16.0).sin_cos();
            let y = r.tick([f1 * co, f2 * s]);
            if n >= n_settle {
                tail.push([y.q[0], y.q[1], y.v[0], y.v[1]]);
                assert!((y.current[0] - 2.5 * y.v[0]).abs() <= 1e-15 * y.v[0].abs());
            }
        }
        let e = rel_err(&tail, n_settle, &want);
        eprintln!("Q = {q}: held steady state rel err {e:e}");
        assert!(e < 1e-9, "{e:e}");
    }
}

/// THEORY.md section 3: a = w0/Q, b = 2 lambda Omega, D = w0 (a^2 + b^2),
/// X1 = -(b F2 + j a F1)/D, X2 = (j b F1 - a F2)/D for f1 = F1 cos w0t, f2 = F2 sin w0t.
fn theory_phasors(q: f64, lambda: f64, omega: f64, f1: f64, f2: f64) -> [Complex64; 2] {
    let w0 = TAU * F0;
    let (a, b) = (w0 / q, 2.0 * lambda * omega);
    let d = w0 * (a * a + b * b);
    [-(c(b * f2, a * f1)) / d, (c(-a * f2, b * f1)) / d]
}

fn theta_expected(q: f64, lambda: f64, omega: f64, f1: f64, f2: f64) -> [f64; 2] {
    let w0 = TAU * F0;
    [
        (2.0 * f2 * q * lambda * omega / (f1 * w0)).atan(),
        (2.0 * f1 * q * lambda * omega / (f2 * w0)).atan(),
    ]
}

/// Lag of each mode against its own drive, relative to Omega = 0: arg(X(0) / X(Omega)).
fn theta_from(x0: [Complex64; 2], x: [Complex64; 2]) -> [f64; 2] {
    [(x0[0] / x[0]).arg(), (x0[1] / x[1]).arg()]
}

#[test]
fn continuous_steady_state_equals_theory_closed_form() {
    let lambda = 0.6;
    for &q in &[50.0, 1000.0, 36_000.0] {
        for &ratio in &[1.0, 0.5] {
            let (f1, f2) = (1.0, ratio);
            let p = ResonatorParams::matched(F0, q, lambda, FS);
            let force = [c(f1, 0.0), c(0.0, -f2)];
            let x0 = continuous_steady_state(&p, 0.0, F0, force);
            for &omega in &[-3.0, 0.5, 3.05, 50.0, 400.0] {
                let x = continuous_steady_state(&p, omega, F0, force);
                let t = theory_phasors(q, lambda, omega, f1, f2);
                let scale = t[0].norm().max(t[1].norm());
                let jw = c(0.0, TAU * F0);
                for k in 0..2 {
                    assert!(
                        (x[k] - t[k]).norm() / scale < 1e-9,
                        "q{k} {:?} {:?}",
                        x[k],
                        t[k]
                    );
                    let ev = (x[2 + k] - jw * t[k]).norm() / (TAU * F0 * scale);
                    assert!(ev < 1e-9, "v{k}");
                }
                let th = theta_from([x0[0], x0[1]], [x[0], x[1]]);
                let te = theta_expected(q, lambda, omega, f1, f2);
                for k in 0..2 {
                    assert!(
                        (th[k] - te[k]).abs() < 1e-9,
                        "theta{k} {} vs {}",
                        th[k],
                        te[k]
                    );
                }
            }
        }
    }
}

/// Exactly sinusoidal force: state [q1, q2, v1, v2, cos wt, sin wt], force = [F1 cos, F2 sin],
/// discretised here as one autonomous 6-state system (no hold anywhere).
fn simulate_true_sinusoid(
    q: f64,
    lambda: f64,
    omega: f64,
    f1: f64,
    f2: f64,
    n: usize,
) -> Vec<[f64; 4]> {
    let w0 = TAU * F0;
    let ts = 1.0 / FS;
    // Work in [w0 q, v, cos, sin] so the matrix is balanced; forces enter scaled by w0.
    let a = w0 / q;
    let b = 2.0 * lambda * omega;
    #[rustfmt::skip]
    let m = SMatrix::<f64, 6, 6>::from_row_slice(&[
        0.0, 0.0, w0, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0, w0, 0.0, 0.0,
        -w0, 0.0, -a, b, f1 * w0, 0.0,
        0.0, -w0, -b, -a, 0.0, f2 * w0,
        0.0, 0.0, 0.0, 0.0, 0.0, -w0,
        0.0, 0.0, 0.0, 0.0, w0, 0.0,
    ]) * ts;
    let ad = m.exp();
    // Drive states are scaled by 1/w0 (so f = F * w0 * state); start at cos = 1, sin = 0.
    let mut z = nalgebra::SVector::<f64, 6>::from([0.0, 0.0, 0.0, 0.0, 1.0 / w0, 0.0]);
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push([z[0] / w0, z[1] / w0, z[2], z[3]]);
        z = ad * z;
    }
    out
}

#[test]
fn true_sinusoid_simulation_settles_to_continuous_steady_state() {
    let lambda = 0.6;
    for &q in &[50.0, 1000.0] {
        let p = ResonatorParams::matched(F0, q, lambda, FS);
        let tau_s = 2.0 * q / (TAU * F0);
        let n_settle = (40.0 * tau_s * FS / 16.0).ceil() as usize * 16;
        for &ratio in &[1.0, 0.5] {
            let (f1, f2) = (1.0, ratio);
            let force = [c(f1, 0.0), c(0.0, -f2)];
            // Omega giving a theta1 of about 30 degrees at F2 = F1.
            let omega = (PI / 6.0).tan() * TAU * F0 / (2.0 * q * lambda);
            let mut sim_phasors = Vec::new();
            for &om in &[0.0, omega] {
                let xs = simulate_true_sinusoid(q, lambda, om, f1, f2, n_settle + 16);
                let want = continuous_steady_state(&p, om, F0, force);
                let e = rel_err(&xs[n_settle..], n_settle, &want);
                eprintln!("Q = {q}, F2/F1 = {ratio}, Omega = {om:.3}: sim vs phasor {e:e}");
                assert!(e < 1e-9, "{e:e}");
                // Phasors from the simulation: one 16-point DFT bin over a whole period.
                let ph: [Complex64; 2] = core::array::from_fn(|k| {
                    (0..16)
                        .map(|i| {
                            let (s, co) = (TAU * i as f64 / 16.0).sin_cos();
                            xs[n_settle + i][k] * c(co, -s)
                        })
                        .sum::<Complex64>()
                        / 8.0
                });
                sim_phasors.push(ph);
            }
            let th = theta_from(sim_phasors[0], sim_phasors[1]);
            let te = theta_expected(q, lambda, omega, f1, f2);
            eprintln!(
                "  theta sim {:?} deg, theory {:?} deg",
                th.map(f64::to_degrees),
                te.map(f64::to_degrees)
            );
            for k in 0..2 {
                assert!((th[k] - te[k]).abs() < 1e-9, "theta{k}");
            }
        }
    }
}

/// THEORY.md section 6: the hold moves the absolute carrier phase, but the Coriolis phase
/// *shift* (relative to Omega = 0) of the held plant stays within 0.0062 mdeg of theta_k.
#[test]
fn hold_barely_changes_the_coriolis_phase_shift() {
    let (f0, q, lambda) = (15_000.0, 36_000.0, 0.6);
    let p = ResonatorParams::matched(f0, q, lambda, 16.0 * f0);
    let force = [c(1.0, 0.0), c(0.0, -1.0)];
    let x0 = Resonator::<f64>::new(&p, 0.0)
        .unwrap()
        .held_steady_state(f0, force);
    let mut worst: f64 = 0.0;
    for deg_s in [1.0, 10.0, 50.0, 100.0, 175.0] {
        let om = f64::to_radians(deg_s);
        let x = Resonator::<f64>::new(&p, om)
            .unwrap()
            .held_steady_state(f0, force);
        let th = theta_from([x0[0], x0[1]], [x[0], x[1]]);
        let w0 = TAU * f0;
        let te = (2.0 * q * lambda * om / w0).atan();
        for t in th {
            worst = worst.max((t - te).abs().to_degrees() * 1e3);
        }
    }
    eprintln!("held vs continuous Coriolis phase shift: worst {worst:e} mdeg");
    assert!(worst < 0.0062, "{worst} mdeg");
}
