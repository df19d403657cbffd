//! The discrete-time harmonic balance of the board's rate-table recursion
//! (`held_table_steady_state`) against that recursion itself: `tick_with_rate` run to its
//! periodic steady state, each harmonic read by an exact DFT over whole periods. Then against
//! the continuous theory: at 16 samples per period the hold and the step move the envelope.

use gyroemu_core::Complex64;
use gyroemu_resonator::{
    held_table_steady_state, rate_table_steady_state, ModeParams, Resonator, ResonatorParams,
};
use std::f64::consts::TAU;

const FS: f64 = 16_000.0;
/// Carrier 1040 Hz and table 40 Hz: every harmonic fc + k ft is a whole number of cycles in
/// 400 samples, so the DFT over whole such periods reads each one exactly.
const FC: f64 = 1_040.0;
const FT: f64 = 40.0;
const PERIOD: usize = 400;
const N: usize = 12;

fn device(coupling: f64) -> ResonatorParams {
    ResonatorParams {
        mode1: ModeParams {
            f0_hz: 1_000.0,
            q: 50.0,
        },
        mode2: ModeParams {
            f0_hz: 1_012.0,
            q: 35.0,
        },
        angular_gain: 0.8,
        quadrature_coupling_rad2_s2: coupling,
        transduction_a_s_per_m: 1.0,
        fs_hz: FS,
    }
}

/// The recursion at its steady state: harmonics -N ..= N of each state, by DFT.
fn emulated(p: &ResonatorParams, amp: f64, force: [Complex64; 2]) -> Vec<[Complex64; 4]> {
    let mut plant = Resonator::<f64>::new(p, 0.0).unwrap();
    let u = |n: usize| {
        let (s, c) = (TAU * FC * n as f64 / FS).sin_cos();
        let e = Complex64::new(c, s);
        [(force[0] * e).re, (force[1] * e).re]
    };
    let rate = |n: usize| amp * (TAU * FT * (n as f64 + 0.5) / FS).sin();
    // Q = 50: tau = 16 ms; 2 s of settling is 125 time constants.
    let settle = 80 * PERIOD;
    for n in 0..settle {
        plant.tick_with_rate(u(n), rate(n));
    }
    let len = 20 * PERIOD;
    let mut acc = vec![[Complex64::new(0.0, 0.0); 4]; 2 * N + 1];
    for n in settle..settle + len {
        let x = plant.state();
        for (b, a) in acc.iter_mut().enumerate() {
            let f = FC + (b as f64 - N as f64) * FT;
            let (s, c) = (TAU * f * n as f64 / FS).sin_cos();
            for i in 0..4 {
                a[i] += Complex64::new(c, -s) * x[i];
            }
        }
        plant.tick_with_rate(u(n), rate(n));
    }
    acc.iter()
        .map(|a| core::array::from_fn(|i| a[i] * (2.0 / len as f64)))
        .collect()
}

#[test]
fn the_balance_is_the_recursions_steady_state() {
    let force = [Complex64::new(1.0, 0.0), Complex64::new(0.0, -0.7)];
    for (coupling, amp) in [(0.0, 30.0), (2e4, 60.0)] {
        let p = device(coupling);
        let plant = Resonator::<f64>::new(&p, 0.0).unwrap();
        let held = held_table_steady_state(&plant, amp, FT, FC, force, N);
        let run = emulated(&p, amp, force);
        let scale: f64 = held
            .iter()
            .flatten()
            .skip(2)
            .step_by(4)
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        for (b, (h, r)) in held.iter().zip(&run).enumerate() {
            for i in 2..4 {
                assert!(
                    (h[i] - r[i]).norm() < 1e-9 * scale,
                    "coupling {coupling}, harmonic {}, v{}: {} against {}",
                    b as i32 - N as i32,
                    i - 1,
                    h[i],
                    r[i]
                );
            }
        }
        // The continuous theory is another steady state: the hold's half-sample delay and
        // its images, which the board's figure carries.
        let cont = rate_table_steady_state(&p, amp, FT, FC, force, N);
        let d = held
            .iter()
            .zip(&cont)
            .map(|(h, c)| (h[2] - c[2]).norm())
            .fold(0.0, f64::max);
        assert!(d > 1e-3 * scale, "{d}");
    }
}
