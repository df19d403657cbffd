//! The quantiser's bias bound against the expectation computed by quadrature level by level,
//! and its phase bound against quantised carriers' fundamentals measured by a direct DFT.

use gyroemu_theory::{quantiser_bias_bound, quantiser_phase_bound_rad};
use std::f64::consts::{PI, TAU};

/// Integral of the unit normal density over [a, b] by composite Simpson (the density is
/// smooth, so 64 panels per level leave errors near 1e-13).
fn normal_mass(a: f64, b: f64) -> f64 {
    let n = 64;
    let h = (b - a) / n as f64;
    let phi = |x: f64| (-0.5 * x * x).exp() / TAU.sqrt();
    let mut s = phi(a) + phi(b);
    for i in 1..n {
        s += phi(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

/// E[step * round((x + n) / step)] - x for n ~ N(0, sigma^2), summed level by level.
fn bias(x: f64, step: f64, sigma: f64) -> f64 {
    let lo = ((x - 12.0 * sigma) / step).floor() as i64 - 1;
    let hi = ((x + 12.0 * sigma) / step).ceil() as i64 + 1;
    let mean: f64 = (lo..=hi)
        .map(|m| {
            let (a, b) = ((m as f64 - 0.5) * step - x, (m as f64 + 0.5) * step - x);
            m as f64 * step * normal_mass(a / sigma, b / sigma)
        })
        .sum();
    mean - x
}

#[test]
fn the_bias_bound_holds_and_is_tight_where_one_harmonic_dominates() {
    let step = 0.37;
    for ratio in [0.15, 0.25, 0.35, 0.5, 0.7] {
        let sigma = ratio * step;
        let worst = (0..400)
            .map(|i| bias(3.0 + i as f64 * step / 400.0, step, sigma).abs())
            .fold(0.0, f64::max);
        let bound = quantiser_bias_bound(step, sigma);
        assert!(worst <= bound * (1.0 + 1e-6), "{ratio}: {worst} > {bound}");
        if ratio >= 0.25 {
            assert!(
                bound <= worst * 1.05,
                "{ratio}: {bound} loose against {worst}"
            );
        }
    }
    // No noise: the sawtooth's half step; a vanishing noise cannot exceed it.
    assert_eq!(quantiser_bias_bound(step, 0.0), 0.5 * step);
    assert_eq!(quantiser_bias_bound(step, 1e-9), 0.5 * step);
    // An LSB of noise leaves about step/pi exp(-2 pi^2): 2.7e-9 of a step.
    let one = quantiser_bias_bound(1.0, 1.0);
    assert!(
        (one / ((-2.0 * PI * PI).exp() / PI) - 1.0).abs() < 1e-6,
        "{one}"
    );
}

#[test]
fn the_phase_bound_covers_every_quantised_carrier() {
    // Carriers of 16 samples per period (the board's default), at amplitudes of 1.3 to 400
    // steps and any phase: the fundamental's phase moves by no more than the bound, and the
    // worst case comes within a factor of 5 of it.
    let step = 1.0;
    for amp in [1.3, 2.6, 7.9, 40.0, 400.0] {
        let bound = quantiser_phase_bound_rad(quantiser_bias_bound(step, 0.0), amp);
        let mut worst: f64 = 0.0;
        for j in 0..997 {
            let phase = TAU * j as f64 / 997.0;
            let (mut re, mut im) = (0.0, 0.0);
            for n in 0..16 {
                let w = TAU * n as f64 / 16.0;
                let q = step * (amp * (w + phase).cos() / step).round();
                re += q * w.cos();
                im -= q * w.sin();
            }
            let err = (im.atan2(re) - phase + PI).rem_euclid(TAU) - PI;
            worst = worst.max(err.abs());
        }
        assert!(worst <= bound, "A = {amp}: {worst} > {bound}");
        assert!(worst >= bound / 5.0, "A = {amp}: {worst} far below {bound}");
    }
}
