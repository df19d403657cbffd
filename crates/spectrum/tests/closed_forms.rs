//! Welch spectra and tones against closed forms: sinusoids of known amplitude and frequency,
//! the density of seeded white Gaussian noise, Parseval, and a naive DFT.

use gyroemu_spectrum::{default_segment_len, find_tones, hann, tone_near, welch, SpectrumError};
use num_complex::Complex64;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

fn sines(n: usize, fs: f64, dc: f64, tones: &[(f64, f64, f64)]) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let t = i as f64 / fs;
            dc + tones
                .iter()
                .map(|&(a, f, ph)| a * (2.0 * PI * f * t + ph).sin())
                .sum::<f64>()
        })
        .collect()
}

/// Standard normals by Box-Muller from a seeded ChaCha stream.
fn gaussian(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let u1: f64 = 1.0 - rng.random::<f64>();
            let u2: f64 = rng.random::<f64>();
            sigma * (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
        })
        .collect()
}

#[test]
fn tones_of_a_sum_of_sinusoids_have_their_frequencies_and_levels() {
    let (n, fs, l) = (1 << 15, 240_000.0, 2048);
    let bin = fs / l as f64;
    // Off-bin fractions from 0 to 1/2 (the worst scalloping), 40 bins or more apart.
    let tones = [
        (1.0, 15_000.0 + 0.5 * bin, 0.3),
        (0.01, 30_000.0 + 0.23 * bin, 1.1),
        (0.3, 45_000.0 + 0.0 * bin, -0.4),
        (1e-4, 60_000.0 + 0.41 * bin, 2.0),
    ];
    let x = sines(n, fs, 0.25, &tones);
    let psd = welch(&x, fs, Some(l)).unwrap();
    let found = find_tones(&psd, 5, 20.0);
    assert_eq!(found.len(), 5, "{found:?}");
    // Strongest first by mean square: 1.0 (0.5), DC 0.25 (0.0625), 0.3 (0.045), 0.01, 1e-4.
    assert_eq!(found[0].bin, (tones[0].1 / bin).round() as usize);
    assert_eq!(found[1].freq_hz, 0.0);
    assert!((found[1].amplitude() - 0.25).abs() < 1e-6, "{:?}", found[1]);
    assert!(found[2].amplitude() > found[3].amplitude());
    for &(a, f, _) in &tones {
        let t = found
            .iter()
            .find(|t| (t.freq_hz - f).abs() < bin)
            .unwrap_or_else(|| panic!("tone at {f} Hz not found in {found:?}"));
        let level = 10.0 * (a * a / 2.0).log10();
        assert!(
            (t.level_db() - level).abs() < 0.01,
            "{f} Hz: {} dB, expected {level} dB",
            t.level_db()
        );
        assert!((t.freq_hz - f).abs() < 0.01 * bin, "{} vs {f}", t.freq_hz);
        assert!((t.amplitude() / a - 1.0).abs() < 2e-3);
    }
}

#[test]
fn scalloping_is_corrected_at_every_offset() {
    // One tone swept across a bin: the raw peak bin loses up to 1.42 dB, the tone never.
    let (n, fs, l) = (8192, 1000.0, 1024);
    let bin = fs / l as f64;
    for j in 0..=10 {
        let f = 100.0 * bin + j as f64 * 0.1 * bin;
        let x = sines(n, fs, 0.0, &[(2.0, f, 0.7)]);
        let psd = welch(&x, fs, Some(l)).unwrap();
        let t = tone_near(&psd, f, 2).unwrap();
        assert!(
            (t.level_db() - 10.0 * 2f64.log10()).abs() < 0.01,
            "{j}: {t:?}"
        );
        assert!(
            (t.freq_hz - f).abs() < 1e-3 * bin,
            "{j}: {} vs {f}",
            t.freq_hz
        );
    }
}

#[test]
fn white_noise_density_is_two_sigma_squared_over_fs_for_any_segment() {
    // Expected one-sided density 2 s^2 / fs. Each averaged bin is a scaled chi-square with
    // about 2 K dof (K segments; Hann at 50 % overlap loses ~5 %); neighbouring bins correlate
    // (Hann: power correlation 4/9 at one bin, 1/36 at two), so the mean over M interior bins
    // has relative std ~ sqrt(1.94 / (0.95 K M)): 0.6 % at L = 1024 (K = 127, M = 511) and
    // 0.7 % at L = 64 (K = 2047, M = 31). The bound is 5 of those.
    let (n, fs, sigma) = (1 << 16, 48_000.0, 0.3);
    let x = gaussian(n, sigma, 7);
    let expected = 2.0 * sigma * sigma / fs;
    for l in [64usize, 1024] {
        let psd = welch(&x, fs, Some(l)).unwrap();
        let d = psd.density();
        let interior = &d[1..d.len() - 1];
        let mean = interior.iter().sum::<f64>() / interior.len() as f64;
        let k = psd.segments as f64;
        let rel_std = (1.94 / (0.95 * k * interior.len() as f64)).sqrt();
        assert!(
            (mean / expected - 1.0).abs() < 5.0 * rel_std,
            "L = {l}: mean density {mean:e}, expected {expected:e} (5 sigma = {})",
            5.0 * rel_std
        );
        assert!((psd.enbw_hz - 1.5 * fs / l as f64).abs() < 1e-9 * fs);
    }
    // Noise gives no tones 20 dB above its floor.
    let psd = welch(&x, fs, None).unwrap();
    assert!(find_tones(&psd, 5, 20.0).is_empty());
}

#[test]
fn psd_integrates_to_the_windowed_mean_square() {
    // Parseval per segment: sum_k density_k * fs/L = sum(w^2 x^2) / sum(w^2), averaged.
    let fs = 1e3;
    let x: Vec<f64> = gaussian(3000, 1.7, 11)
        .iter()
        .zip(sines(3000, fs, 0.4, &[(1.0, 123.4, 0.2)]))
        .map(|(a, b)| a + b)
        .collect();
    for l in [256usize, 255, 3000] {
        let psd = welch(&x, fs, Some(l)).unwrap();
        let integral: f64 = psd.density().iter().sum::<f64>() * psd.bin_hz();
        let w = hann(l);
        let s2: f64 = w.iter().map(|v| v * v).sum();
        let hop = l - l / 2;
        let mut acc = 0.0;
        let mut k = 0;
        while k * hop + l <= x.len() {
            let seg = &x[k * hop..k * hop + l];
            acc += seg
                .iter()
                .zip(&w)
                .map(|(a, b)| (a * b).powi(2))
                .sum::<f64>()
                / s2;
            k += 1;
        }
        assert_eq!(k, psd.segments);
        let windowed = acc / k as f64;
        assert!(
            (integral / windowed - 1.0).abs() < 1e-12,
            "L = {l}: {integral} vs {windowed}"
        );
        // And close to the plain mean square (the variance of the noise plus the tone and DC).
        let ms = x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64;
        assert!((integral / ms - 1.0).abs() < 0.1, "{integral} vs {ms}");
    }
}

#[test]
fn fft_path_equals_a_naive_dft() {
    let fs = 10.0;
    for (n, l) in [(16usize, 16usize), (40, 16), (97, 30), (200, 7), (256, 64)] {
        let x = gaussian(n, 1.0, n as u64);
        let psd = welch(&x, fs, Some(l)).unwrap();
        let w = hann(l);
        let s1: f64 = w.iter().sum();
        let hop = l - l / 2;
        let mut naive = vec![0.0; l / 2 + 1];
        let mut segs = 0;
        let mut s = 0;
        while s + l <= n {
            for (k, acc) in naive.iter_mut().enumerate() {
                let xk: Complex64 = (0..l)
                    .map(|i| {
                        Complex64::from_polar(
                            x[s + i] * w[i],
                            -2.0 * PI * (k * i) as f64 / l as f64,
                        )
                    })
                    .sum();
                *acc += xk.norm_sqr();
            }
            segs += 1;
            s += hop;
        }
        assert_eq!(psd.segments, segs);
        for (k, &p) in psd.power.iter().enumerate() {
            let doubled = k > 0 && 2 * k != l;
            let want = naive[k] / (segs as f64 * s1 * s1) * if doubled { 2.0 } else { 1.0 };
            assert!(
                (p - want).abs() <= 1e-12 * want.abs().max(1e-12),
                "n {n} L {l} bin {k}: {p} vs {want}"
            );
        }
    }
}

#[test]
fn bad_requests_are_refused_with_reasons() {
    assert!(matches!(
        welch(&[1.0, 2.0], 1.0, None),
        Err(SpectrumError::TooShort { got: 2, .. })
    ));
    assert!(matches!(
        welch(&[0.0; 10], 0.0, None),
        Err(SpectrumError::Rate(_))
    ));
    assert!(matches!(
        welch(&[0.0; 10], 1.0, Some(11)),
        Err(SpectrumError::Segment { .. })
    ));
    let mut x = vec![0.0; 10];
    x[3] = f64::NAN;
    let e = welch(&x, 1.0, None).unwrap_err();
    assert!(e.to_string().contains("sample 3 is NaN"), "{e}");
    assert_eq!(default_segment_len(4096), 1024);
    assert_eq!(default_segment_len(5000), 1024);
    assert_eq!(default_segment_len(10), 10);
    assert_eq!(default_segment_len(4), 4);
}

#[test]
fn low_passed_noise_gives_no_tones_but_a_tone_in_its_pass_band_is_found() {
    // White noise through four 16-sample boxcars (|H| = |sinc|^4 of the 1/16 band): most bins
    // lie in the stop band, so the pass band stood far above the whole spectrum's median and its
    // noise was listed as tones. Against the median of its neighbours it is just noise.
    let (n, fs) = (1 << 16, 240_000.0);
    let mut x = gaussian(n + 64, 1.0, 3);
    for _ in 0..4 {
        x = x
            .windows(16)
            .map(|w| w.iter().sum::<f64>() / 16.0)
            .collect();
    }
    x.truncate(n);
    let psd = welch(&x, fs, Some(2048)).unwrap();
    let median = {
        let mut s = psd.power.clone();
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    };
    assert!(
        psd.power[10] > 1e4 * median,
        "the pass band is 40 dB above the median"
    );
    assert!(
        find_tones(&psd, 5, 20.0).is_empty(),
        "{:?}",
        find_tones(&psd, 5, 20.0)
    );
    // A sine in the pass band 30 dB above the noise there is a tone.
    let bin = fs / 2048.0;
    let level = psd.density()[20] * bin;
    let f = 20.3 * bin;
    let a = (2.0 * 1e3 * level).sqrt();
    let y: Vec<f64> = x
        .iter()
        .zip(sines(n, fs, 0.0, &[(a, f, 0.1)]))
        .map(|(u, v)| u + v)
        .collect();
    let found = find_tones(&welch(&y, fs, Some(2048)).unwrap(), 5, 20.0);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!((found[0].freq_hz - f).abs() < bin, "{found:?}");
}
