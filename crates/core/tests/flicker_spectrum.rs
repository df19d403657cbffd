//! The spectrum of a generated flicker record against the exact density of the design: a
//! Welch average of Hann-windowed periodograms, compared band by band with its exact
//! expectation (the design's autocovariance seen through the window), within the
//! periodogram's statistical spread.

mod flicker_common;

use flicker_common::Gauss;
use gyroemu_core::flicker::{Flicker, FlickerDesign, FlickerParams};
use gyroemu_core::{f64x4, Complex64, Stage};
use rustfft::FftPlanner;

/// Segment length and segments per lane (4 lanes: 256 averaged periodograms).
const L: usize = 1 << 16;
const SEGMENTS: usize = 64;

fn hann() -> Vec<f64> {
    (0..L)
        .map(|n| (core::f64::consts::PI * n as f64 / L as f64).sin().powi(2))
        .collect()
}

/// The exact autocovariance of the output, `R(0)` the variance and, for `tau >= 1`,
/// `R(tau) = sum_j beta_j a_j^tau` with `beta_j = rho_j (D + sum_i rho_i C_ij)`: the modal
/// state j decays as `a_j^tau` and meets `y[n]` with covariance `D + sum_i rho_i C_ij`
/// (it holds `w[n]` with weight 1).
fn autocovariance(d: &FlickerDesign, len: usize) -> Vec<f64> {
    let (a, rho) = (d.pole_radii(), d.residues());
    let beta: Vec<f64> = (0..a.len())
        .map(|j| {
            let cross: f64 = (0..a.len()).map(|i| rho[i] * d.mode_covariance(i, j)).sum();
            rho[j] * (d.direct() + cross)
        })
        .collect();
    let mut r = vec![d.variance()];
    let mut pow: Vec<f64> = a.to_vec();
    for _ in 1..len {
        r.push(beta.iter().zip(&pow).map(|(b, p)| b * p).sum());
        pow.iter_mut().zip(a).for_each(|(p, a)| *p *= a);
    }
    r
}

/// The exact expectation of the one-sided windowed periodogram at bins `0..L/2`:
/// `E|X_k|^2 = sum_tau R(tau) r_w(tau) e^{-2 pi i k tau / L}` (r_w the window's
/// autocorrelation), from FFTs of length 2L, scaled by `2 / (fs sum w^2)`.
fn expected_periodogram(d: &FlickerDesign, w: &[f64]) -> Vec<f64> {
    let mut planner = FftPlanner::new();
    let (fwd, inv) = (
        planner.plan_fft_forward(2 * L),
        planner.plan_fft_inverse(2 * L),
    );
    let mut rw: Vec<Complex64> = w.iter().map(|&v| Complex64::new(v, 0.0)).collect();
    rw.resize(2 * L, Complex64::new(0.0, 0.0));
    fwd.process(&mut rw);
    rw.iter_mut()
        .for_each(|v| *v = Complex64::new(v.norm_sqr(), 0.0));
    inv.process(&mut rw);
    let r = autocovariance(d, L);
    let mut g: Vec<Complex64> = (0..2 * L)
        .map(|i| {
            let tau = if i < L { i } else { 2 * L - i };
            let rr = if tau < L { r[tau] } else { 0.0 };
            Complex64::new(rr * rw[i].re / (2 * L) as f64, 0.0)
        })
        .collect();
    fwd.process(&mut g);
    let norm = 2.0 / (d.fs_hz() * w.iter().map(|v| v * v).sum::<f64>());
    (0..L / 2).map(|k| g[2 * k].re * norm).collect()
}

#[test]
fn welch_spectrum_matches_the_exact_density() {
    let p = FlickerParams {
        fs_hz: 1.0,
        psd_at_1hz: 1.0,
        f_lo_hz: 1e-4,
        f_hi_hz: 0.5,
    };
    let w = hann();
    let mut g = Gauss::new([7, 8, 9, 10]);
    let mut f = Flicker::<f64x4>::stationary(&p, || g.next()).unwrap();
    let fft = FftPlanner::new().plan_fft_forward(L);
    let mut avg = vec![0.0; L / 2];
    let mut bufs: [Vec<Complex64>; 4] = core::array::from_fn(|_| vec![Complex64::default(); L]);
    for _ in 0..SEGMENTS {
        for n in 0..L {
            let y = f.tick(g.next()).to_array();
            for (b, v) in bufs.iter_mut().zip(y) {
                b[n] = Complex64::new(v * w[n], 0.0);
            }
        }
        for b in bufs.iter_mut() {
            fft.process(b);
            avg.iter_mut()
                .zip(b.iter())
                .for_each(|(a, x)| *a += x.norm_sqr());
        }
    }
    let k_avg = (4 * SEGMENTS) as f64;
    let norm = 2.0 / (p.fs_hz * w.iter().map(|v| v * v).sum::<f64>() * k_avg);
    avg.iter_mut().for_each(|a| *a *= norm);
    let want = expected_periodogram(f.design(), &w);
    // The window barely biases this spectrum above a few bins: the expectation is within 1 %
    // of the density itself from bin 8 up (a check of the expectation's construction).
    for (k, &e) in want.iter().enumerate().skip(8) {
        let s = f.design().psd(k as f64 / L as f64);
        assert!((e / s - 1.0).abs() < 0.01, "bin {k}: {e} vs {s}");
    }
    // Octave bands from bin 1 (f_lo = 6.6 bins) to Nyquist. Each averaged bin has relative
    // variance 1/K (K = 256 periodograms of a Gaussian sequence); Hann bins one apart are
    // correlated by (2/3)^2 in power, two apart by (1/6)^2, so the band mean of B bins has
    // variance (1 / (K B^2)) sum_{i,j} c(|i - j|). Five standard errors.
    let c = |d: usize| match d {
        0 => 1.0,
        1 => 4.0 / 9.0,
        2 => 1.0 / 36.0,
        _ => 0.0,
    };
    let mut worst: f64 = 0.0;
    for j in 0..15 {
        let (lo, hi) = (1usize << j, (2usize << j).min(L / 2));
        let bins = lo..hi;
        let got = avg[bins.clone()].iter().sum::<f64>();
        let exp = want[bins.clone()].iter().sum::<f64>();
        let b = bins.len();
        let cov: f64 = (0..b)
            .flat_map(|i| (0..b).map(move |k| c(i.abs_diff(k))))
            .sum();
        let se = (cov / (k_avg * (b * b) as f64)).sqrt();
        let z = (got / exp - 1.0) / se;
        worst = worst.max(z.abs());
        eprintln!(
            "bins [{lo:5}, {hi:5}): Welch / exact = {:.4} ({z:+.2} se, se = {:.2} %)",
            got / exp,
            100.0 * se
        );
        assert!(z.abs() < 5.0, "bins [{lo}, {hi}): {got} vs {exp}, z = {z}");
    }
    eprintln!("worst band: {worst:.2} standard errors");
}
