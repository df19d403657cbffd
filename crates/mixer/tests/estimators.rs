//! The paper-style I-channel estimate and the Coriolis phase-lag read-out against closed forms.

mod common;

use common::{angle_err, exact_phase, Planted};
use core::f64::consts::{FRAC_PI_2, PI};
use gyroemu_core::{Complex64, Stage};
use gyroemu_mixer::{
    paper_i_channel_psi_rad, phase_lag_rad, sideband_estimate, Iq, Mode, Stage2Mixer,
};
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `(C, S)` through the stage-2 mixer averaged over one modulation period of 64 samples.
fn c_and_s(p: &Planted) -> (Complex64, Complex64) {
    let mut mix = Stage2Mixer::<f64>::new();
    let (mut c, mut s) = (Complex64::default(), Complex64::default());
    for n in 0..64 {
        let wt = exact_phase(n, 1, 64);
        let z = p.z(wt);
        let o = mix.tick((Iq::new(z.re, z.im), [wt.cos(), wt.sin()]));
        c += o.c.lane(0);
        s += o.s.lane(0);
    }
    (c / 64.0, s / 64.0)
}

#[test]
fn paper_estimate_equals_psi_when_alpha_is_zero() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for trial in 0..200 {
        let mode2 = trial % 2 == 1;
        let mode = if mode2 { Mode::Two } else { Mode::One };
        let imbalance = rng.random_range(-0.5..0.5);
        let psi = rng.random_range(-PI..PI);
        let p = Planted {
            amp: rng.random_range(0.1..5.0),
            psi,
            alpha: 0.0,
            imbalance,
            mode2,
        };
        let (c, s) = c_and_s(&p);
        assert!(angle_err(paper_i_channel_psi_rad(c, s, mode), psi) < 1e-12);
    }
}

#[test]
fn paper_estimate_is_off_by_atan_of_imbalance_times_tan_alpha() {
    // Derived: Re C1 = A(cos a cos psi - e sin a sin psi), Re S1 = A(cos a sin psi + e sin a cos psi)
    // (mode 2: -Re C2 and Re S2 are the same two), so
    // paper = psi + atan2(e sin alpha, cos alpha): zero error for balanced sidebands when
    // cos alpha > 0, pi when cos alpha < 0, atan(e tan alpha) in general.
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let mut worst: f64 = 0.0;
    let mut largest_gap: f64 = 0.0;
    for trial in 0..400 {
        let mode2 = trial % 2 == 1;
        let mode = if mode2 { Mode::Two } else { Mode::One };
        let imbalance = if trial % 3 == 0 {
            0.0
        } else {
            rng.random_range(-0.5..0.5)
        };
        let p = Planted {
            amp: rng.random_range(0.1..5.0),
            psi: rng.random_range(-FRAC_PI_2..FRAC_PI_2),
            alpha: rng.random_range(-PI..PI),
            imbalance,
            mode2,
        };
        let (c, s) = c_and_s(&p);
        let paper = paper_i_channel_psi_rad(c, s, mode);
        let e = sideband_estimate(c, s, mode);
        let gap = (imbalance * p.alpha.sin()).atan2(p.alpha.cos());
        worst = worst.max(angle_err(paper, p.psi + gap));
        // The sideband estimator stays exact.
        worst = worst.max(angle_err(e.psi_rad, p.psi));
        if p.alpha.cos() > 0.0 {
            largest_gap = largest_gap.max(gap.abs());
        }
    }
    println!("paper vs closed form: worst {worst:.2e} rad; largest gap seen {largest_gap:.3} rad");
    assert!(worst < 1e-12);
}

#[test]
fn paper_estimate_small_angle_example() {
    // 1 % sideband imbalance and alpha = 10 degrees: about 0.1 degree of error, psi exact.
    let p = Planted {
        amp: 1.0,
        psi: 0.05,
        alpha: 10f64.to_radians(),
        imbalance: 0.01,
        mode2: false,
    };
    let (c, s) = c_and_s(&p);
    let err = paper_i_channel_psi_rad(c, s, Mode::One) - p.psi;
    let want = (0.01 * p.alpha.tan()).atan();
    println!(
        "paper error at e = 1 %, alpha = 10 deg: {:.4} mdeg",
        err.to_degrees() * 1e3
    );
    assert!((err - want).abs() < 1e-12);
    assert!((sideband_estimate(c, s, Mode::One).psi_rad - p.psi).abs() < 1e-12);
}

#[test]
fn phase_lag_is_positive_for_a_lagging_phasor() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..1000 {
        let z0 = Complex64::from_polar(rng.random_range(0.1..10.0), rng.random_range(-PI..PI));
        let theta = rng.random_range(-PI + 1e-9..PI);
        let z = z0 * Complex64::from_polar(rng.random_range(0.1..2.0), -theta);
        assert!((phase_lag_rad(z, z0) - theta).abs() < 1e-12);
    }
    // Branch end: a half-turn reads +pi, never -pi.
    let z0 = Complex64::new(1.0, 0.0);
    assert_eq!(phase_lag_rad(Complex64::new(-1.0, 0.0), z0), PI);
    assert_eq!(phase_lag_rad(Complex64::new(-1.0, -0.0), z0), PI);
    assert_eq!(phase_lag_rad(z0, z0), 0.0);
}

proptest! {
    /// For any (C, S), the estimate is on its documented branch and reproduces both sideband
    /// arguments: arg(Z+/M+) = alpha - psi and arg(Z-/M-) = alpha + psi (mod 2 pi).
    #[test]
    fn estimate_is_consistent_on_its_branch(
        cr in -10.0f64..10.0, ci in -10.0f64..10.0, sr in -10.0f64..10.0, si in -10.0f64..10.0,
        two in any::<bool>(),
    ) {
        let (c, s) = (Complex64::new(cr, ci), Complex64::new(sr, si));
        let mode = if two { Mode::Two } else { Mode::One };
        let e = sideband_estimate(c, s, mode);
        let j = Complex64::new(0.0, 1.0);
        prop_assert!((e.z_plus - (c - j * s) / 2.0).norm() < 1e-14 * (1.0 + c.norm() + s.norm()));
        prop_assume!(e.z_plus.norm() > 1e-6 && e.z_minus.norm() > 1e-6);
        prop_assert!(e.psi_rad > -FRAC_PI_2 && e.psi_rad <= FRAC_PI_2);
        prop_assert!(e.alpha_rad > -PI && e.alpha_rad <= PI);
        let (mp, mm) = if two { (-j, j) } else { (Complex64::new(1.0, 0.0), Complex64::new(1.0, 0.0)) };
        prop_assert!(angle_err((e.z_plus / mp).arg(), e.alpha_rad - e.psi_rad) < 1e-9);
        prop_assert!(angle_err((e.z_minus / mm).arg(), e.alpha_rad + e.psi_rad) < 1e-9);
    }
}

#[test]
fn sideband_phasors_are_the_halves_of_c_and_s_they_are_defined_as() {
    // C = Z+ + Z- and S = j (Z+ - Z-) invert Z+- = (C -+ j S) / 2: planted sidebands of any
    // size and phase come back as planted, in both modes.
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    let j = Complex64::new(0.0, 1.0);
    for _ in 0..200 {
        let mut draw = || {
            let r = 10f64.powf(rng.random_range(-6.0..3.0));
            Complex64::from_polar(r, rng.random_range(-PI..PI))
        };
        let (zp, zm) = (draw(), draw());
        let (c, s) = (zp + zm, j * (zp - zm));
        for mode in [Mode::One, Mode::Two] {
            let e = sideband_estimate(c, s, mode);
            let scale = zp.norm().max(zm.norm());
            assert!(
                (e.z_plus - zp).norm() < 1e-15 * scale,
                "{:?} {zp}",
                e.z_plus
            );
            assert!(
                (e.z_minus - zm).norm() < 1e-15 * scale,
                "{:?} {zm}",
                e.z_minus
            );
        }
    }
}
