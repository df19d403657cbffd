//! The start phase, parameter errors and the phase shifter's closed forms (block processing
//! and reset are checked by the shared harness in tests/contract.rs).

use gyroemu_core::Stage;
use gyroemu_nco::{Nco, PhaseShifter};
use num_complex::Complex64;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{FRAC_PI_2, TAU};

#[test]
fn start_phase_and_phasor_without_advance() {
    let nco = Nco::new(1000.0, 48_000.0, 1.0).unwrap();
    assert!((nco.phase_rad() - 1.0).abs() < 1e-15);
    let p = nco.phasor();
    assert!((p - Complex64::new(1f64.cos(), 1f64.sin())).norm() < 1e-15);
    assert_eq!(nco.phasor(), p);
    let neg = Nco::new(0.0, 1.0, -FRAC_PI_2).unwrap();
    assert_eq!(neg.phase_word(), 3 << 62);
}

#[test]
fn bad_parameters_are_refused() {
    let nyq = Nco::new(500.0, 1000.0, 0.0).unwrap_err();
    assert_eq!((nyq.stage, nyq.param), ("nco", "f_hz"));
    assert!(Nco::new(-500.0, 1000.0, 0.0).is_err());
    assert!(Nco::new(600.0, 1000.0, 0.0).is_err());
    assert!(Nco::new(f64::NAN, 1000.0, 0.0).is_err());
    assert!(Nco::new(f64::INFINITY, 1000.0, 0.0).is_err());
    for fs in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = Nco::new(1.0, fs, 0.0).unwrap_err();
        assert_eq!(e.param, "fs_hz");
    }
    let e = Nco::new(1.0, 1000.0, f64::NAN).unwrap_err();
    assert_eq!(e.param, "phase_rad");
    assert!(Nco::new(499.999_999, 1000.0, 0.0).is_ok());
    assert!(Nco::new(0.0, 1000.0, 0.0).is_ok());
    let e = PhaseShifter::new(f64::NAN).unwrap_err();
    assert_eq!((e.stage, e.param), ("phase_shifter", "shift_rad"));
}

#[test]
fn quadrature_shifter_turns_cos_into_sin_exactly() {
    let q = PhaseShifter::quadrature();
    let mut nco = Nco::new(15_000.123, 1e6, 0.4).unwrap();
    for _ in 0..100_000 {
        let p = nco.tick(());
        let y = q.apply(p);
        assert_eq!(y.re, p.im); // Re(out) = sin(phi), bit for bit
        assert_eq!(y.im, -p.re);
    }
}

#[test]
fn general_shift_matches_closed_form() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..1000 {
        let shift = rng.random_range(-20.0..20.0);
        let phi = rng.random_range(0.0..TAU);
        let mut s = PhaseShifter::new(shift).unwrap();
        let y = s.tick(Complex64::new(phi.cos(), phi.sin()));
        assert!((y.re - (phi - shift).cos()).abs() < 1e-14);
        assert!((y.im - (phi - shift).sin()).abs() < 1e-14);
        s.reset();
    }
    let nominal = PhaseShifter::new(FRAC_PI_2).unwrap();
    assert!((nominal.rotation() - PhaseShifter::quadrature().rotation()).norm() < 1e-16);
}

#[test]
fn shifter_reports_the_rotation_it_applies() {
    for shift in [0.0, 0.25, core::f64::consts::FRAC_PI_2, -2.0, 9.0] {
        let sh = PhaseShifter::new(shift).unwrap();
        let rot = sh.rotation();
        // e^{-j shift}, and what apply multiplies by (the image of 1).
        assert!(
            (rot - Complex64::from_polar(1.0, -shift)).norm() < 1e-15,
            "{shift}"
        );
        assert_eq!(sh.apply(Complex64::new(1.0, 0.0)), rot);
    }
    assert_eq!(
        PhaseShifter::quadrature().rotation(),
        Complex64::new(0.0, -1.0)
    );
}
