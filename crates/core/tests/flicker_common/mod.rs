//! Shared by the flicker tests: a unit-Gaussian feed from the seeded streams, the integral of
//! a density against a kernel, and the overlapping Allan deviation written from its
//! definition.

#![allow(dead_code)]

use gyroemu_core::f64x4;
use gyroemu_core::noise::NoiseRng;

/// Unit Gaussians per lane from [`NoiseRng::normal_pair`], both halves of each pair in turn.
pub struct Gauss {
    rng: NoiseRng,
    spare: Option<f64x4>,
}

impl Gauss {
    pub fn new(lane_seeds: [u64; 4]) -> Self {
        Self {
            rng: NoiseRng::new(lane_seeds),
            spare: None,
        }
    }

    pub fn next(&mut self) -> f64x4 {
        match self.spare.take() {
            Some(v) => v,
            None => {
                let (a, b) = self.rng.normal_pair();
                self.spare = Some(b);
                a
            }
        }
    }
}

/// `int_0^{fs/2} s(f) k(f) df` by 8-point Gauss-Legendre on panels: log-spaced from 1e-14 fs
/// up to `f_osc` (below the kernel's first oscillation), then `per_osc` panels per
/// `fs / m` (the kernel's period) up to fs/2.
pub fn integrate(
    fs: f64,
    m: f64,
    s: impl Fn(f64) -> f64,
    k: impl Fn(f64) -> f64,
    per_osc: f64,
) -> f64 {
    const X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let panel = |a: f64, b: f64| -> f64 {
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        X.iter()
            .zip(&W)
            .map(|(&x, &w)| {
                let (f1, f2) = (mid - half * x, mid + half * x);
                w * (s(f1) * k(f1) + s(f2) * k(f2))
            })
            .sum::<f64>()
            * half
    };
    let f_osc = 0.25 * fs / m;
    let f_min = 1e-14 * fs;
    let n_log = 400;
    let mut total = 0.0;
    for i in 0..n_log {
        let a = f_min * (f_osc / f_min).powf(i as f64 / n_log as f64);
        let b = f_min * (f_osc / f_min).powf((i + 1) as f64 / n_log as f64);
        total += panel(a, b);
    }
    let n_lin = ((0.5 * fs - f_osc) / (fs / m) * per_osc).ceil() as usize;
    let step = (0.5 * fs - f_osc) / n_lin as f64;
    for i in 0..n_lin {
        total += panel(f_osc + i as f64 * step, f_osc + (i + 1) as f64 * step);
    }
    total
}

/// The exact Allan variance at `m` samples of a sequence of one-sided density `s`:
/// `int_0^{fs/2} s(f) 2 sin^4(pi f m / fs) / (m sin(pi f / fs))^2 df` (half the power of
/// the difference of two adjacent m-sample means).
pub fn exact_avar(fs: f64, m: usize, s: impl Fn(f64) -> f64) -> f64 {
    let mf = m as f64;
    let k = |f: f64| {
        let x = core::f64::consts::PI * f / fs;
        let num = (mf * x).sin().powi(2);
        2.0 * num * num / (mf * x.sin()).powi(2)
    };
    integrate(fs, mf, s, k, 8.0)
}

/// The overlapping Allan deviation at `m` samples, from the definition:
/// `sigma^2 = 1 / (2 (N - 2m + 1)) sum_k (mean(y[k+m..k+2m]) - mean(y[k..k+m]))^2`, the
/// means from prefix sums of the mean-removed series.
pub fn overlapping_avar(y: &[f64], m: usize) -> f64 {
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let mut prefix = Vec::with_capacity(y.len() + 1);
    prefix.push(0.0);
    let mut acc = 0.0;
    for &v in y {
        acc += v - mean;
        prefix.push(acc);
    }
    let terms = y.len() - 2 * m + 1;
    let mf = m as f64;
    let sum: f64 = (0..terms)
        .map(|k| {
            let a = (prefix[k + m] - prefix[k]) / mf;
            let b = (prefix[k + 2 * m] - prefix[k + m]) / mf;
            (b - a) * (b - a)
        })
        .sum();
    sum / (2.0 * terms as f64)
}
