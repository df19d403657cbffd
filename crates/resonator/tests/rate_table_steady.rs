//! The harmonic-balance steady state on a sinusoidal rate table against an independent
//! carrier-level RK4 integration of the ODE written here (continuous drive and rate), at a
//! 40-degree phase swing, on a matched and on an imperfect device.

use gyroemu_core::Complex64;
use gyroemu_resonator::{rate_table_steady_state, ModeParams, ResonatorParams};
use std::f64::consts::TAU;

const F0: f64 = 1_000.0;
const TABLE_HZ: f64 = 20.0;
/// RK4 steps per carrier period: the scheme's frequency error (h w)^4/120 is then 2e-10.
const STEPS_PER_PERIOD: usize = 512;

fn device(mismatch_hz: f64, q2: f64, k12: f64) -> ResonatorParams {
    ResonatorParams {
        mode1: ModeParams { f0_hz: F0, q: 50.0 },
        mode2: ModeParams {
            f0_hz: F0 + mismatch_hz,
            q: q2,
        },
        angular_gain: 0.8,
        quadrature_coupling_rad2_s2: k12,
        transduction_a_s_per_m: 1.0,
        fs_hz: 16.0 * F0,
    }
}

/// The ODE of eq. 1 (general device), written out directly.
fn deriv(p: &ResonatorParams, x: [f64; 4], f: [f64; 2], om: f64) -> [f64; 4] {
    let (w1, w2) = (TAU * p.mode1.f0_hz, TAU * p.mode2.f0_hz);
    let b = 2.0 * p.angular_gain * om;
    let k = p.quadrature_coupling_rad2_s2;
    [
        x[2],
        x[3],
        f[0] - w1 * w1 * x[0] - k * x[1] - w1 / p.mode1.q * x[2] + b * x[3],
        f[1] - k * x[0] - w2 * w2 * x[1] - w2 / p.mode2.q * x[3] - b * x[2],
    ]
}

/// Integrates from rest for `settle_periods` table periods, then demodulates one more period
/// at each harmonic: `X_n = (2/P) sum x(t) e^{-j (w0 + n w_t) t}` (an integer number of
/// carrier cycles per table period makes the rectangle rule exact for these tones).
fn rk4_harmonics(
    p: &ResonatorParams,
    amp: f64,
    force: [Complex64; 2],
    settle_periods: usize,
    n: isize,
) -> Vec<[Complex64; 4]> {
    let per_table = STEPS_PER_PERIOD * (F0 / TABLE_HZ) as usize;
    let h = 1.0 / (F0 * STEPS_PER_PERIOD as f64);
    let f = |t: f64| {
        let e = Complex64::from_polar(1.0, TAU * F0 * t);
        [(force[0] * e).re, (force[1] * e).re]
    };
    let om = |t: f64| amp * (TAU * TABLE_HZ * t).sin();
    let axpy = |x: [f64; 4], a: f64, k: [f64; 4]| -> [f64; 4] {
        core::array::from_fn(|i| x[i] + a * k[i])
    };
    let mut x = [0.0; 4];
    let mut acc = vec![[Complex64::new(0.0, 0.0); 4]; (2 * n + 1) as usize];
    for step in 0..(settle_periods + 1) * per_table {
        let t = step as f64 * h;
        if step >= settle_periods * per_table {
            for (b, a) in acc.iter_mut().enumerate() {
                let k = b as f64 - n as f64;
                let e =
                    Complex64::from_polar(2.0 / per_table as f64, -TAU * (F0 + k * TABLE_HZ) * t);
                for i in 0..4 {
                    a[i] += x[i] * e;
                }
            }
        }
        let k1 = deriv(p, x, f(t), om(t));
        let k2 = deriv(p, axpy(x, 0.5 * h, k1), f(t + 0.5 * h), om(t + 0.5 * h));
        let k3 = deriv(p, axpy(x, 0.5 * h, k2), f(t + 0.5 * h), om(t + 0.5 * h));
        let k4 = deriv(p, axpy(x, h, k3), f(t + h), om(t + h));
        x = core::array::from_fn(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    acc
}

#[test]
fn harmonic_balance_matches_a_carrier_level_integration() {
    // Envelope time constant 2Q/w0 = 16 ms; 30 table periods (1.5 s) settle it to e^-94.
    // amp = 110 rad/s swings the phase by about 40 degrees at this table frequency.
    let force = [Complex64::new(1.0, 0.0), Complex64::new(0.0, -1.0)];
    for (name, p) in [
        ("matched", device(0.0, 50.0, 0.0)),
        ("imperfect", device(0.7, 60.0, 0.02 * (TAU * F0).powi(2))),
    ] {
        let n = 10;
        let hb = rate_table_steady_state(&p, 110.0, TABLE_HZ, F0, force, n as usize);
        let ode = rk4_harmonics(&p, 110.0, force, 30, n);
        let scale = hb[n as usize][2].norm();
        // The phase swing is large: harmonics beyond the first carry real content.
        assert!(hb[n as usize + 2][2].norm() > 1e-3 * scale, "{name}");
        for (b, (a, o)) in hb.iter().zip(&ode).enumerate() {
            for i in 2..4 {
                let err = (a[i] - o[i]).norm() / scale;
                assert!(
                    err < 2e-8,
                    "{name}: harmonic {b}, state {i}: {} vs {} ({err:e})",
                    a[i],
                    o[i]
                );
            }
        }
    }
}

#[test]
fn harmonics_fall_off_and_the_truncation_converges() {
    let p = device(0.0, 50.0, 0.0);
    let force = [Complex64::new(1.0, 0.0), Complex64::new(0.0, -1.0)];
    let coarse = rate_table_steady_state(&p, 110.0, TABLE_HZ, F0, force, 12);
    let fine = rate_table_steady_state(&p, 110.0, TABLE_HZ, F0, force, 24);
    let scale = coarse[12][2].norm();
    for n in -12isize..=12 {
        let (a, b) = (coarse[(n + 12) as usize][2], fine[(n + 24) as usize][2]);
        assert!((a - b).norm() < 1e-12 * scale, "harmonic {n}");
    }
    assert!(fine[24 + 12][2].norm() < 1e-9 * scale);
}

#[test]
fn a_zero_amplitude_table_is_the_constant_rate_steady_state() {
    let p = device(0.7, 60.0, 1e5);
    let force = [Complex64::new(1.0, 0.0), Complex64::new(0.3, -0.9)];
    let hb = rate_table_steady_state(&p, 0.0, TABLE_HZ, F0 + 0.2, force, 3);
    let cs = gyroemu_resonator::continuous_steady_state(&p, 0.0, F0 + 0.2, force);
    for i in 0..4 {
        assert!((hb[3][i] - cs[i]).norm() <= 1e-14 * cs[i].norm());
        assert_eq!(hb[2][i], Complex64::new(0.0, 0.0));
    }
}
