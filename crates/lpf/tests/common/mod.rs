//! Helpers shared by the integration tests (included with `mod common;`).
#![allow(dead_code)]

use gyroemu_core::Complex64;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustfft::FftPlanner;

/// Uniform noise in `[-scale/2, scale/2)`.
pub fn noise(n: usize, scale: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| scale * (rng.random::<f64>() - 0.5))
        .collect()
}

/// Random chunk lengths covering `n` (some zero).
pub fn chunks(n: usize, max: usize, seed: u64) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    let mut left = n;
    while left > 0 {
        let l = rng.random_range(0..max).min(left);
        out.push(l);
        left -= l;
    }
    out
}

/// DFT of a real sequence by rustfft.
pub fn fft(x: &[f64]) -> Vec<Complex64> {
    let mut buf: Vec<rustfft::num_complex::Complex<f64>> = x
        .iter()
        .map(|&v| rustfft::num_complex::Complex::new(v, 0.0))
        .collect();
    FftPlanner::new()
        .plan_fft_forward(x.len())
        .process(&mut buf);
    buf.iter().map(|c| Complex64::new(c.re, c.im)).collect()
}
