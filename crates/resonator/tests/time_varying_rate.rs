//! Time-varying rate: `tick_with_rate` against a fine-step RK4 integration of the ODE written
//! here, and against exact plants built at a constant rate.

use gyroemu_core::Stage;
use gyroemu_resonator::{Resonator, ResonatorParams};
use std::f64::consts::TAU;

const FS: f64 = 16_000.0;
const F0: f64 = 1_000.0;
const Q: f64 = 1_000.0;
const LAMBDA: f64 = 1.0;
const TABLE_HZ: f64 = 10.0;
const RATE_AMP: f64 = 3.0;
const SUBSTEPS: usize = 128;

fn rate(t: f64) -> f64 {
    RATE_AMP * (TAU * TABLE_HZ * t).sin()
}

fn drive(n: usize) -> [f64; 2] {
    let (s, c) = (TAU * (n % 16) as f64 / 16.0).sin_cos();
    [c, 0.8 * s]
}

/// The ODE of eq. 1 in physical units, written out directly.
fn deriv(x: [f64; 4], f: [f64; 2], om: f64) -> [f64; 4] {
    let w = TAU * F0;
    let b = 2.0 * LAMBDA * om;
    [
        x[2],
        x[3],
        f[0] - w * w * x[0] - w / Q * x[2] + b * x[3],
        f[1] - w * w * x[1] - w / Q * x[3] - b * x[2],
    ]
}

fn axpy(x: [f64; 4], h: f64, k: [f64; 4]) -> [f64; 4] {
    core::array::from_fn(|i| x[i] + h * k[i])
}

/// RK4 with `SUBSTEPS` steps per sample, force held over each sample. `held_rate` holds the
/// rate at its midpoint value over the sample too; otherwise it follows `rate(t)`.
fn rk4(n: usize, held_rate: bool) -> Vec<[f64; 4]> {
    let ts = 1.0 / FS;
    let h = ts / SUBSTEPS as f64;
    let mut x = [0.0; 4];
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        out.push(x);
        let f = drive(k);
        let mid = rate((k as f64 + 0.5) * ts);
        let om = |t: f64| if held_rate { mid } else { rate(t) };
        for j in 0..SUBSTEPS {
            let t = k as f64 * ts + j as f64 * h;
            let k1 = deriv(x, f, om(t));
            let k2 = deriv(axpy(x, 0.5 * h, k1), f, om(t + 0.5 * h));
            let k3 = deriv(axpy(x, 0.5 * h, k2), f, om(t + 0.5 * h));
            let k4 = deriv(axpy(x, h, k3), f, om(t + h));
            x = core::array::from_fn(|i| {
                x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
    }
    out
}

fn plant(omega_c: f64, n: usize) -> Vec<[f64; 4]> {
    let p = ResonatorParams::matched(F0, Q, LAMBDA, FS);
    let mut r = Resonator::<f64>::new(&p, omega_c).unwrap();
    (0..n)
        .map(|k| {
            let y = r.tick_with_rate(drive(k), rate((k as f64 + 0.5) / FS));
            [y.q[0], y.q[1], y.v[0], y.v[1]]
        })
        .collect()
}

/// Max error relative to the largest displacement / velocity of the reference.
fn rel(a: &[[f64; 4]], b: &[[f64; 4]]) -> f64 {
    let mut worst: f64 = 0.0;
    for g in 0..2 {
        let scale = b
            .iter()
            .map(|x| x[2 * g].abs().max(x[2 * g + 1].abs()))
            .fold(0.0, f64::max);
        for (x, y) in a.iter().zip(b) {
            for i in 0..2 {
                worst = worst.max((x[2 * g + i] - y[2 * g + i]).abs() / scale);
            }
        }
    }
    worst
}

#[test]
fn sinusoidal_rate_matches_fine_rk4() {
    let n = 8_000; // 0.5 s: 1.6 tau, 5 table periods, Coriolis phase up to ~4 degrees
    let ref_held = rk4(n, true);
    let ref_cont = rk4(n, false);
    for &omega_c in &[0.0, 1.0] {
        let sim = plant(omega_c, n);
        let e_held = rel(&sim, &ref_held);
        let e_cont = rel(&sim, &ref_cont);
        eprintln!("omega_c {omega_c}: vs RK4 held rate {e_held:e}, continuous rate {e_cont:e}");
        assert!(e_held < 1e-7, "{e_held:e}");
        assert!(e_cont < 1e-6, "{e_cont:e}");
    }
}

#[test]
fn constant_offset_rate_matches_plant_built_at_that_rate() {
    let p = ResonatorParams::matched(F0, Q, LAMBDA, FS);
    let mut base = Resonator::<f64>::new(&p, 0.0).unwrap();
    let n = 20_000;
    for &om in &[0.1, 1.0, 3.0] {
        let mut exact = Resonator::<f64>::new(&p, om).unwrap();
        base.reset();
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        for k in 0..n {
            let a = base.tick_with_rate(drive(k), om);
            let b = exact.tick(drive(k));
            for i in 0..2 {
                worst = worst.max((a.q[i] - b.q[i]).abs());
                scale = scale.max(b.q[i].abs());
            }
        }
        // The second-order expansion misses the cubic term of the Coriolis rotation,
        // (2 lambda d Ts)^3 / 6 per step, which accumulates coherently over ~tau / Ts steps.
        let ts = 1.0 / FS;
        let bound = (2.0 * LAMBDA * om * ts).powi(3) / 6.0 * (2.0 * Q / (TAU * F0)) / ts;
        eprintln!(
            "Omega offset {om}: rel err {:e} (estimate {bound:e})",
            worst / scale
        );
        assert!(worst / scale < bound.max(1e-13), "{:e}", worst / scale);
    }
    // At the design rate the expansion is not used at all: bit-identical to tick.
    let mut a = Resonator::<f64>::new(&p, 2.0).unwrap();
    let mut b = a.clone();
    for k in 0..1000 {
        let ya = a.tick_with_rate(drive(k), 2.0);
        let yb = b.tick(drive(k));
        assert_eq!(ya.q[0].to_bits(), yb.q[0].to_bits());
        assert_eq!(ya.v[1].to_bits(), yb.v[1].to_bits());
    }
}
