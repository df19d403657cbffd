//! Stage 1 and the single mixer against closed forms, through an ideal boxcar low-pass over
//! whole carrier periods (which removes the 2 w0 image exactly).

mod common;

use common::{carrier, exact_phase, mean};
use core::f64::consts::{FRAC_PI_2, PI};
use gyroemu_core::{Complex64, Stage};
use gyroemu_mixer::{phase_lag_rad, Stage1Mixer};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// (k cycles, m samples): carrier tones whose 2 w0 image is not at DC.
const TONES: [(u64, u64); 4] = [(1, 16), (5, 37), (7, 1000), (3, 10)];

/// Every length-`m` moving average of the stage-1 output of `y[n]`, after the first `m` samples.
fn stage1_dc(phi: f64, k: u64, m: u64, y: impl Fn(f64) -> f64) -> Vec<Complex64> {
    let mut mix = Stage1Mixer::<f64>::new(phi).unwrap();
    let z: Vec<Complex64> = (0..4 * m)
        .map(|n| {
            let o = mix.tick((y(exact_phase(n, k, m)), carrier(n, k, m)));
            Complex64::new(o.i, o.q)
        })
        .collect();
    z.windows(m as usize).map(mean).collect()
}

#[test]
fn stage1_dc_is_a_e_minus_j_theta_plus_phi() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut worst: f64 = 0.0;
    for _ in 0..40 {
        let a = rng.random_range(0.1..10.0);
        let theta = rng.random_range(-PI..PI);
        let phi = rng.random_range(-PI..PI);
        for (k, m) in TONES {
            // y = A cos(w0 t - theta)  ->  DC z = A e^{-j(theta + phi)}.
            let want = Complex64::from_polar(a, -(theta + phi));
            for dc in stage1_dc(phi, k, m, |wt| a * (wt - theta).cos()) {
                worst = worst.max((dc - want).norm() / a);
            }
        }
    }
    println!("stage 1 DC worst relative error {worst:.2e}");
    assert!(worst < 1e-9);
}

#[test]
fn stage1_mode2_with_minus_half_pi_reference_reads_own_sin_drive() {
    // y = A sin(w0 t - theta) with phi = -pi/2  ->  z = A e^{-j theta}; lag read back as theta.
    let (a, k, m) = (2.5, 5, 37);
    let z0 = stage1_dc(-FRAC_PI_2, k, m, |wt| a * wt.sin())[0];
    for theta in [-1.2, -0.01, 0.0, 0.3, 1.5, 3.0] {
        let z = stage1_dc(-FRAC_PI_2, k, m, |wt| a * (wt - theta).sin())[5];
        assert!((z - Complex64::from_polar(a, -theta)).norm() < 1e-12);
        assert!((phase_lag_rad(z, z0) - theta).abs() < 1e-12);
    }
}

/// The paper's single real mixer, `2 y cos(w0 t - phi)`, is the I channel of a stage-1 mixer
/// with reference phase `-phi`.
#[test]
fn single_mixer_dc_is_a_cos_theta_minus_phi() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut worst: f64 = 0.0;
    for _ in 0..40 {
        let a = rng.random_range(0.1..10.0);
        let theta = rng.random_range(-PI..PI);
        let phi = rng.random_range(-PI..PI);
        for (k, m) in TONES {
            let mut mix = Stage1Mixer::<f64>::new(-phi).unwrap();
            let out: Vec<f64> = (0..3 * m)
                .map(|n| {
                    let wt = exact_phase(n, k, m);
                    let carrier = Complex64::from_polar(1.0, wt);
                    mix.tick((a * (wt - theta).cos(), carrier)).i
                })
                .collect();
            let want = a * (theta - phi).cos();
            for w in out.windows(m as usize) {
                let dc = w.iter().sum::<f64>() / m as f64;
                worst = worst.max((dc - want).abs() / a);
            }
        }
    }
    println!("single mixer DC worst relative error {worst:.2e}");
    assert!(worst < 1e-9);
}

#[test]
fn single_mixer_mode2_sin_reference_is_even_in_theta() {
    // y = A sin(w0 t - theta), r = sin w0 t = cos(w0 t - pi/2): DC = A cos theta (even: no
    // sign of the rate).
    let (a, k, m) = (1.5, 7, 1000);
    for theta in [-0.7, 0.2, 0.7, 2.0] {
        let mut mix = Stage1Mixer::<f64>::new(-PI / 2.0).unwrap();
        let dc = (0..m)
            .map(|n| {
                let wt = exact_phase(n, k, m);
                mix.tick((a * (wt - theta).sin(), Complex64::from_polar(1.0, wt)))
                    .i
            })
            .sum::<f64>()
            / m as f64;
        assert!((dc - a * theta.cos()).abs() < 1e-12);
    }
}

#[test]
fn the_reported_reference_phase_is_the_one_the_factors_use() {
    // The board shares one mixer's factors between its two channels when their reported
    // phases are equal, so the report must be the phase the factors rotate by.
    for phi in [0.0, -FRAC_PI_2, 0.3, PI, 7.25, -40.0] {
        let m = Stage1Mixer::<f64>::new(phi).unwrap();
        assert_eq!(m.ref_phase_rad().to_bits(), phi.to_bits());
        let (c2, s2) = m.factors(Complex64::new(1.0, 0.0));
        assert!((c2 - 2.0 * phi.cos()).abs() < 1e-14, "{phi}");
        assert!((s2 + 2.0 * phi.sin()).abs() < 1e-14, "{phi}");
    }
}
