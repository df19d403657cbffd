//! Spectra of samples far from 1: a power-of-two scaling of the samples scales every bin's
//! power by its square exactly (floating-point arithmetic commutes with powers of two), also
//! where the plain sums would overflow or underflow on the way; a spectrum whose powers are
//! beyond f64's range is refused, never read as inf or as silence.

use gyroemu_spectrum::{scale_exponent, welch, SpectrumError};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Seeded samples in -1 .. 1 with a tone, so bins differ widely.
fn signal(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|i| 0.5 * (i as f64 * 0.3).sin() + 0.5 * (rng.random::<f64>() - 0.5))
        .collect()
}

fn pow2(k: i32) -> f64 {
    2f64.powi(k)
}

#[test]
fn a_power_of_two_scaling_scales_every_bin_exactly() {
    for seed in 0..4 {
        let x = signal(1000 + 37 * seed as usize, seed);
        let plain = welch(&x, 1000.0, None).unwrap();
        // 510: the plain sums of squares overflow (|X|^2 near 2^1032), the powers do not.
        for k in [-480, -301, -300, -1, 1, 299, 300, 301, 480, 510] {
            let xs: Vec<f64> = x.iter().map(|v| v * pow2(k)).collect();
            let p = welch(&xs, 1000.0, None).unwrap_or_else(|e| panic!("2^{k}: {e}"));
            for (i, (a, b)) in p.power.iter().zip(&plain.power).enumerate() {
                let want = b * pow2(k) * pow2(k);
                assert_eq!(a.to_bits(), want.to_bits(), "2^{k}, seed {seed}, bin {i}");
            }
        }
    }
}

#[test]
fn ordinary_samples_are_not_scaled() {
    for peak in [1e-90, 1e-5, 1.0, 3.3e4, 1e90] {
        assert_eq!(scale_exponent(peak), 0, "{peak}");
    }
    for (peak, e) in [
        (1e100, 332),
        (1e-100, -333),
        (f64::MAX, 1000),
        (5e-324, -1000),
    ] {
        assert_eq!(scale_exponent(peak), e, "{peak}");
    }
}

#[test]
fn powers_beyond_f64_are_refused() {
    let x = signal(1000, 7);
    for k in [600, 1000, -600, -1000] {
        let xs: Vec<f64> = x.iter().map(|v| v * pow2(k)).collect();
        match welch(&xs, 1000.0, None) {
            Err(SpectrumError::OutOfRange { peak }) => {
                let want = xs.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
                assert_eq!(peak, want);
            }
            other => panic!("2^{k}: expected OutOfRange, got {other:?}"),
        }
    }
    // Silence is a spectrum of zeros, not out of range; so is a sample in the tail that no
    // segment reaches (65 samples: segments of 16 every 8 end at sample 64).
    let p = welch(&[0.0; 64], 1000.0, None).unwrap();
    assert!(p.power.iter().all(|&v| v == 0.0));
    let mut tail = [0.0; 65];
    tail[64] = 1.0;
    let p = welch(&tail, 1000.0, None).unwrap();
    assert_eq!(p.segment_len, 16);
    assert!(p.power.iter().all(|&v| v == 0.0));
}
