//! Consecutive outputs differ by the expected rotation everywhere, including across the wrap
//! of the phase word, and every output is a unit phasor close to libm.

use gyroemu_core::Stage;
use gyroemu_nco::Nco;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// `e^{j 2 pi w / 2^64}` from libm: quadrant from the top two bits (exact), the rest as an
/// angle below pi/2 so its f64 rounding stays near 1e-16.
fn libm_phasor(w: u64) -> Complex64 {
    let a = (w & ((1u64 << 62) - 1)) as f64 * (TAU / 2f64.powi(64));
    let rot = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][(w >> 62) as usize];
    Complex64::new(a.cos(), a.sin()) * Complex64::new(rot.0, rot.1)
}

/// `|p|^2 - 1` evaluated with fused multiply-adds, so the check measures the phasor and not
/// the rounding of the check itself (plain `re*re + im*im` near 1 rounds in steps of 2.2e-16).
fn norm_sqr_minus_one(p: Complex64) -> f64 {
    p.re.mul_add(p.re, p.im.mul_add(p.im, -1.0))
}

#[test]
fn constant_rotation_across_wraps() {
    for &(f, phase) in &[
        (123_456.789_012_345, TAU - 1e-12),
        (-98_765.432_101_234_5, 0.0),
        (499_999.999_999, 3.0),
        (0.001_234_567, TAU - 1e-7),
    ] {
        let fs = 1e6;
        let mut nco = Nco::new(f, fs, phase).unwrap();
        let turns = nco.step_word() as i64 as f64 / 2f64.powi(64);
        let rot = Complex64::new((TAU * turns).cos(), (TAU * turns).sin());
        let mut prev = nco.tick(());
        let mut prev_word = nco.phase_word();
        let (mut wraps, mut worst) = (0u32, 0.0f64);
        for _ in 0..1_000_000 {
            let w = nco.phase_word();
            let y = nco.tick(());
            worst = worst.max((y - prev * rot).norm());
            if (f > 0.0 && w < prev_word) || (f < 0.0 && w > prev_word) {
                wraps += 1;
            }
            prev = y;
            prev_word = w;
        }
        println!("f = {f}: {wraps} wraps, worst rotation error {worst:.2e}");
        assert!(worst < 1e-14, "f = {f}: {worst}");
        assert!(wraps >= 1, "f = {f}: test never crossed the wrap");
    }
}

#[test]
fn unit_modulus_and_agreement_with_libm() {
    let mut nco = Nco::new(12_345.678_901_234_5, 1e6, 0.3).unwrap();
    let (mut worst_unit, mut worst_libm) = (0.0f64, 0.0f64);
    for _ in 0..2_000_000 {
        let w = nco.phase_word();
        let p = nco.tick(());
        worst_unit = worst_unit.max(norm_sqr_minus_one(p).abs());
        let want = libm_phasor(w);
        worst_libm = worst_libm
            .max((p.re - want.re).abs())
            .max((p.im - want.im).abs());
    }
    // Hard words: every table cell edge, quadrant points and their neighbours.
    for k in 0u64..4096 {
        for d in [0u64, 1, u64::MAX, 1 << 52, (1 << 53) - 1, 1 << 53] {
            let w = (k << 52).wrapping_add(d);
            let p = gyroemu_nco::phasor_of_word(w);
            worst_unit = worst_unit.max(norm_sqr_minus_one(p).abs());
            let want = libm_phasor(w);
            worst_libm = worst_libm
                .max((p.re - want.re).abs())
                .max((p.im - want.im).abs());
        }
    }
    println!("|p|^2 - 1 worst {worst_unit:.2e}, vs libm worst {worst_libm:.2e}");
    assert!(worst_unit <= 4e-16, "{worst_unit}");
    assert!(worst_libm <= 1e-15);
}

#[test]
fn phase_rad_stays_in_range() {
    let mut nco = Nco::new(0.0, 1.0, -1e-300).unwrap();
    assert!((0.0..TAU).contains(&nco.phase_rad()));
    nco = Nco::new(0.1, 1.0, TAU - 1e-15).unwrap();
    for _ in 0..100 {
        nco.tick(());
        assert!((0.0..TAU).contains(&nco.phase_rad()));
    }
    let mut top = Nco::new(0.0, 1.0, 0.0).unwrap();
    top.jump(0);
    assert_eq!(top.phase_rad(), 0.0);
    let last = Nco::new(1e-20, 1.0, TAU * (1.0 - 1e-17)).unwrap();
    assert!(last.phase_rad() < TAU);
}
