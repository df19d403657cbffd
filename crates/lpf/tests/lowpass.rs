//! The low-pass cascades against closed forms (the FFT of their impulse responses and their
//! latency are checked by the shared harness in tests/contract.rs).

mod common;

use gyroemu_core::{Complex64, Response, Stage};
use gyroemu_lpf::{DecimateMode, Decimator, LowPass, LowPassDesign};
use std::f64::consts::{PI, TAU};

fn bw(order: usize, cutoff_hz: f64) -> LowPassDesign {
    LowPassDesign::Butterworth { order, cutoff_hz }
}

#[test]
fn butterworth_magnitude_equals_the_prewarped_closed_form() {
    let fs = 1000.0;
    let mut worst: f64 = 0.0;
    for order in 1..=8 {
        for fc in [1.0, 20.0, 100.0, 250.0, 300.0, 450.0] {
            let lp = LowPass::<f64>::new(bw(order, fc), fs).unwrap();
            assert_eq!(lp.sections(), order.div_ceil(2));
            assert_eq!(lp.fs_hz(), fs);
            for i in 0..=997 {
                let f = i as f64 * 0.5;
                let r = ((PI * f / fs).tan() / (PI * fc / fs).tan()).powi(2 * order as i32);
                let truth = 1.0 / (1.0 + r).sqrt();
                let err = (lp.response(f).norm() - truth).abs();
                worst = worst.max(err);
                assert!(
                    err < 1e-10,
                    "N={order} fc={fc} f={f}: |H| {} vs {truth}",
                    lp.response(f).norm()
                );
            }
            let h3 = lp.response(fc).norm();
            assert!(
                (h3 - 0.5f64.sqrt()).abs() < 1e-10,
                "-3 dB point N={order} fc={fc}"
            );
        }
    }
    eprintln!("butterworth |H| vs closed form: worst abs error {worst:e}");
}

#[test]
fn lock_in_response_and_step_equal_their_closed_forms() {
    let fs = 1e5;
    for (order, tau) in [(1, 1e-3), (2, 3e-4), (4, 1e-2), (8, 2e-5), (3, 10.0)] {
        let lp = LowPass::<f64>::new(LowPassDesign::LockIn { order, tau_s: tau }, fs).unwrap();
        assert_eq!(lp.sections(), order);
        let a = (-1.0 / (fs * tau)).exp();
        for f in [0.0, 0.01, 1.0, 37.0, 1e3, 2e4, 4.99e4] {
            let z = Complex64::from_polar(1.0, -TAU * f / fs);
            let truth = ((1.0 - a) / (1.0 - a * z)).powi(order as i32);
            let err = (lp.response(f) - truth).norm() / truth.norm();
            // the closed form itself is evaluated with cancellation in 1 - a z near DC
            let tol = 1e-14 * order as f64 / (1.0 - a).min(1.0);
            assert!(
                err < tol.max(1e-13),
                "N={order} tau={tau} f={f}: rel {err:e}"
            );
        }
        assert!(
            (lp.latency_samples() - order as f64 * a / (1.0 - a)).abs()
                < 1e-9 * lp.latency_samples().max(1.0)
        );
    }
    // One RC stage is exact for a held input: y[n] = 1 - exp(-(n+1) Ts/tau).
    let tau = 2.5e-4;
    let mut lp = LowPass::<f64>::new(
        LowPassDesign::LockIn {
            order: 1,
            tau_s: tau,
        },
        fs,
    )
    .unwrap();
    for n in 0..2000 {
        let y = lp.tick(1.0);
        let truth = 1.0 - (-((n + 1) as f64) / (fs * tau)).exp();
        assert!((y - truth).abs() < 1e-14, "n={n}: {y} vs {truth}");
    }
    // and settles on the held value, to within the rounding stall |x - y| <= ulp/(2k)
    for _ in 0..20_000 {
        lp.tick(0.1);
    }
    let k = 1.0 - (-1.0 / (fs * tau)).exp();
    assert!((lp.tick(0.1) - 0.1).abs() <= 0.5 * 1.39e-17 / k);
}

/// (The phase slope at DC against `latency_samples` is checked by the shared harness in
/// tests/contract.rs.)
#[test]
fn dc_gain_is_one_and_butterworth_latency_is_its_analogue_limit() {
    let fs = 1e6;
    for d in [
        bw(1, 100.0),
        bw(4, 1e3),
        bw(7, 5e3),
        bw(8, 2e5),
        LowPassDesign::LockIn {
            order: 5,
            tau_s: 1e-3,
        },
    ] {
        let lp = LowPass::<f64>::new(d, fs).unwrap();
        assert!(
            (lp.response(0.0) - 1.0).norm() < 1e-9,
            "{d:?}: DC {}",
            lp.response(0.0)
        );
    }
    // Butterworth N=2 prototype: group delay at DC is sqrt(2)/wc in the analogue limit.
    let lp = LowPass::<f64>::new(bw(2, 100.0), 1e6).unwrap();
    let analogue = 2f64.sqrt() / (TAU * 100.0) * 1e6;
    assert!((lp.latency_samples() / analogue - 1.0).abs() < 1e-6);
}

/// Direct-form coefficients near `z = 1` are quantised: `a1 ~ -2` carries an absolute error
/// ~eps while `A(1) = 1 + a1 + a2 ~ w^2`, so the built filter's DC gain (and shape) is off
/// the design by ~eps/w^2 (w = 2 pi fc/fs). Pin that scaling; Response stays exact for it.
#[test]
fn narrow_filters_dc_gain_error_scales_as_eps_over_w_squared() {
    for fc_over_fs in [1e-2, 1e-3, 1e-4, 1e-5] {
        let w = TAU * fc_over_fs;
        let bound = 4.0 * f64::EPSILON / (w * w);
        let mut worst: f64 = 0.0;
        for order in 1..=8 {
            let lp = LowPass::<f64>::new(bw(order, fc_over_fs * 1e6), 1e6).unwrap();
            worst = worst.max((lp.response(0.0).norm() - 1.0).abs());
        }
        eprintln!(
            "butterworth fc/fs = {fc_over_fs:e}: worst |H(0)| - 1 = {worst:e} (eps/w^2 = {:e})",
            bound / 4.0
        );
        assert!(worst < bound.max(1e-14));
    }
}

#[test]
fn bad_parameters_are_named_errors() {
    let fs = 1000.0;
    let cases: [(LowPassDesign, f64, &str); 10] = [
        (bw(0, 10.0), fs, "order"),
        (bw(9, 10.0), fs, "order"),
        (bw(2, 500.0), fs, "cutoff_hz"),
        (bw(2, 600.0), fs, "cutoff_hz"),
        (bw(2, 0.0), fs, "cutoff_hz"),
        (bw(2, f64::NAN), fs, "cutoff_hz"),
        (bw(2, 10.0), f64::NAN, "fs_hz"),
        (
            LowPassDesign::LockIn {
                order: 9,
                tau_s: 1.0,
            },
            fs,
            "order",
        ),
        (
            LowPassDesign::LockIn {
                order: 1,
                tau_s: 0.0,
            },
            fs,
            "tau_s",
        ),
        (
            LowPassDesign::LockIn {
                order: 1,
                tau_s: f64::NAN,
            },
            fs,
            "tau_s",
        ),
    ];
    for (d, fs, name) in cases {
        let e = LowPass::<f64>::new(d, fs).unwrap_err();
        assert_eq!((e.stage, e.param), ("lpf", name), "{d:?}: {e}");
    }
    let e = LowPass::<f64>::new(bw(2, 500.0), fs).unwrap_err();
    assert!(e.to_string().contains("Nyquist"), "{e}");
    let e = LowPass::<f64>::new(
        LowPassDesign::LockIn {
            order: 1,
            tau_s: 1e300,
        },
        fs,
    )
    .unwrap_err();
    assert_eq!(e.param, "tau_s");
    let e = Decimator::<f64>::new(DecimateMode::IntegrateDump, 0, fs).unwrap_err();
    assert_eq!((e.stage, e.param), ("lpf", "factor"));
    let e = Decimator::<f64>::new(DecimateMode::Filter(bw(0, 1.0)), 4, fs).unwrap_err();
    assert_eq!(e.param, "order");
    let e = Decimator::<f64>::new(DecimateMode::IntegrateDump, 4, f64::NAN).unwrap_err();
    assert_eq!(e.param, "fs_in_hz");
}

#[test]
fn lowpass_new_refuses_cutoffs_whose_poles_round_onto_the_unit_circle() {
    let fs = 240_000.0;
    // cos(2 pi fc/fs) rounds to 1: the biquad's pole lands on z = 1 and its numerator on 0.
    for (order, fc) in [(4, 1e-6), (1, 1e-14), (8, 0.5 * fs * (1.0 - 1e-12))] {
        let e = LowPass::<f64>::new(bw(order, fc), fs).expect_err("unrealisable design");
        assert_eq!((e.stage, e.param), ("lpf", "cutoff_hz"), "{e}");
        assert!(e.to_string().contains(&fc.to_string()), "{e}");
    }
    // The accepted neighbours are stable: the impulse response decays.
    for (order, fc) in [(4, 1.0), (8, 0.5 * fs * (1.0 - 1e-6))] {
        let mut lp = LowPass::<f64>::new(bw(order, fc), fs).unwrap();
        let mut h = vec![lp.tick(1.0)];
        h.extend((0..1 << 22).map(|_| lp.tick(0.0)));
        let tail = h[h.len() - 1000..]
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let peak = h.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            tail.is_finite() && tail < 1e-3 * peak,
            "{order} {fc}: {tail} vs {peak}"
        );
    }
}

/// The cascade runs biquad's sections with unit numerators and one gain, which relies on
/// biquad designing `b1 = 2 b0`, `b2 = b0` (first order: `b1 = b0`) bit for bit. Check the
/// claim on a sweep of cutoffs and Q, then the cascade against biquad's own transposed
/// direct form II cascade (an independent implementation) on random input.
#[test]
fn unit_numerator_cascade_equals_biquads_own_sections() {
    use biquad::{Biquad, Coefficients, DirectForm2Transposed, ToHertz, Type};
    use rand::{RngExt, SeedableRng};
    let fs = 48_000.0;
    for fc in [0.05, 1.0, 37.0, 480.0, 4_000.0, 17_000.0, 23_900.0] {
        for q in [0.5001, 0.54, 0.7, 1.3, 2.56] {
            let c = Coefficients::<f64>::from_params(Type::LowPass, fs.hz(), fc.hz(), q).unwrap();
            assert_eq!((c.b1, c.b2), (2.0 * c.b0, c.b0), "fc {fc} q {q}");
        }
        let c = Coefficients::<f64>::from_params(Type::SinglePoleLowPass, fs.hz(), fc.hz(), 1.0)
            .unwrap();
        assert_eq!((c.b1, c.b2), (c.b0, 0.0), "first order fc {fc}");
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    for order in 1..=8 {
        for fc in [120.0, 2_400.0, 15_000.0] {
            let mut lp = LowPass::<f64>::new(bw(order, fc), fs).unwrap();
            // The same sections from biquad: the first-order one first, then Q ascending.
            let mut secs = Vec::new();
            if order % 2 == 1 {
                let c = Coefficients::from_params(Type::SinglePoleLowPass, fs.hz(), fc.hz(), 1.0)
                    .unwrap();
                secs.push(DirectForm2Transposed::<f64>::new(c));
            }
            for m in (1..=order / 2).rev() {
                let psi = PI * (order - 2 * m + 1) as f64 / (2 * order) as f64;
                let q = 1.0 / (2.0 * psi.cos());
                let c = Coefficients::from_params(Type::LowPass, fs.hz(), fc.hz(), q).unwrap();
                secs.push(DirectForm2Transposed::<f64>::new(c));
            }
            let (mut worst, mut scale) = (0.0f64, 0.0f64);
            for _ in 0..4_000 {
                let x: f64 = rng.random_range(-1.0..1.0);
                let want = secs.iter_mut().fold(x, |v, s| s.run(v));
                worst = worst.max((lp.tick(x) - want).abs());
                scale = scale.max(want.abs());
            }
            // Rounding of two orderings of the same recursion: a few eps per section,
            // amplified by the poles' closeness to z = 1 (w = 2 pi fc/fs).
            let w = TAU * fc / fs;
            let tol = 64.0 * f64::EPSILON * order as f64 / (w * w).min(1.0);
            assert!(
                worst <= tol * scale,
                "N={order} fc={fc}: {worst:e} vs {:e}",
                tol * scale
            );
        }
    }
}
