//! The tone finder and the spectrum's own queries at their edges: the Nyquist bin, a search
//! window at the top of the spectrum, flat-topped peaks, and the bins' frequencies and
//! median density against their definitions. Hand-made spectra where the rule is about
//! bins, seeded noise where it is about statistics.

use gyroemu_spectrum::{find_tones, scale_exponent, tone_near, welch, Psd, SpectrumError};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

/// A spectrum with the given per-bin powers (L = 2 (bins - 1), fs = 1000 Hz).
fn psd_of(power: Vec<f64>) -> Psd {
    let segment_len = 2 * (power.len() - 1);
    let spread = vec![f64::NAN; power.len()];
    Psd {
        fs_hz: 1000.0,
        segment_len,
        segments: 1,
        power,
        enbw_hz: 1.5 * 1000.0 / segment_len as f64,
        spread,
    }
}

#[test]
fn a_peak_on_the_nyquist_bin_is_read_as_it_is() {
    let mut p = vec![1e-6; 129];
    p[128] = 4.0;
    let psd = psd_of(p);
    let tones = find_tones(&psd, 3, 20.0);
    assert_eq!(tones.len(), 1);
    let t = tones[0];
    assert_eq!((t.bin, t.freq_hz, t.mean_square), (128, 500.0, 4.0));
    // And from a search that reaches it.
    let t = tone_near(&psd, 497.0, 3).unwrap();
    assert_eq!((t.bin, t.mean_square), (128, 4.0));
}

#[test]
fn a_search_outside_the_spectrum_finds_nothing_even_when_its_window_overlaps_it() {
    let mut p = vec![1e-6; 129];
    p[127] = 4.0;
    let psd = psd_of(p);
    // Bins are 1000/256 Hz apart: 129 bins end at 500 Hz, bin 129 would be at 503.9 Hz.
    let bin = psd.bin_hz();
    for f in [129.0 * bin, 131.0 * bin, 1e4] {
        assert!(tone_near(&psd, f, 5).is_none(), "{f} Hz");
    }
    assert!(tone_near(&psd, -2.0 * bin, 5).is_none());
}

#[test]
fn a_search_sees_the_bins_at_both_ends_of_its_window() {
    for (peak, centre, bins) in [
        (40usize, 37usize, 3usize),
        (40, 43, 3),
        (40, 39, 1),
        (40, 41, 1),
    ] {
        let mut p = vec![1e-6; 129];
        p[peak] = 4.0;
        let psd = psd_of(p);
        let t = tone_near(&psd, centre as f64 * psd.bin_hz(), bins).unwrap();
        assert_eq!(t.bin, peak, "peak {peak}, centre {centre}, {bins} bins");
    }
}

#[test]
fn a_flat_topped_peak_is_one_tone() {
    // Two equal bins (a tone half-way between them reads so): one peak, not two.
    let mut p = vec![1e-6; 129];
    p[60] = 2.0;
    p[61] = 2.0;
    let tones = find_tones(&psd_of(p), 5, 20.0);
    assert_eq!(tones.len(), 1, "{tones:?}");
    // Half-way: the Hann response there is 1/2 of the peak's amplitude on either side.
    assert!(
        (tones[0].freq_hz - 60.5 * 1000.0 / 256.0).abs() < 1e-9,
        "{tones:?}"
    );
}

#[test]
fn bin_frequencies_are_k_fs_over_l() {
    let psd = psd_of(vec![0.0; 65]);
    let f = psd.freqs_hz();
    assert_eq!(f.len(), 65);
    for (k, &v) in f.iter().enumerate() {
        assert_eq!(v, k as f64 * 1000.0 / 128.0);
        assert_eq!(psd.freq_hz(k), v);
    }
    assert_eq!(f[64], 500.0);
}

#[test]
fn median_density_of_white_noise_sits_just_below_two_sigma_squared_over_fs() {
    // One-sided density of white noise of variance s^2 is 2 s^2 / fs; averaged over many
    // segments each bin's estimate is nearly Gaussian, so the median lies within a few per
    // cent below that.
    let (fs, sigma) = (2000.0, 0.3);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let x: Vec<f64> = (0..1 << 18)
        .map(|_| {
            let u1: f64 = 1.0 - rng.random::<f64>();
            let u2: f64 = rng.random::<f64>();
            sigma * (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
        })
        .collect();
    let psd = welch(&x, fs, Some(512)).unwrap();
    let want = 2.0 * sigma * sigma / fs;
    let got = psd.median_density();
    assert!(got < want && got > 0.95 * want, "{got} against {want}");
    // The density itself is power over the window's noise bandwidth.
    let d = psd.density();
    assert!((d[100] - psd.power[100] / psd.enbw_hz).abs() <= 1e-15 * d[100]);
}

#[test]
fn four_samples_are_the_shortest_record() {
    assert!(welch(&[1.0, -2.0, 0.5, 3.0], 100.0, None).is_ok());
    assert!(matches!(
        welch(&[1.0, -2.0, 0.5], 100.0, None),
        Err(SpectrumError::TooShort { got: 3, min: 4 })
    ));
}

#[test]
fn samples_are_scaled_only_outside_2_to_the_plus_minus_300() {
    for peak in [1e-90, 0.5, 10.0, 3e5, 1e90, 0.0, f64::INFINITY, f64::NAN] {
        assert_eq!(scale_exponent(peak), 0, "{peak}");
    }
    // Beyond, about log2(peak), within +-1000.
    assert_eq!(scale_exponent(2f64.powi(400)), 400);
    assert_eq!(scale_exponent(3.0 * 2f64.powi(-400)), -399);
    assert_eq!(scale_exponent(f64::MAX), 1000);
    assert_eq!(scale_exponent(5e-324), -1000);
}

/// Welch of `a cos(2 pi f t + 0.3) + c` at 1024 Hz over 4096 samples (256-sample segments, 4 Hz
/// bins).
fn tone_psd(a: f64, f: f64, c: f64) -> Psd {
    let x: Vec<f64> = (0..4096)
        .map(|n| a * (2.0 * PI * f * n as f64 / 1024.0 + 0.3).cos() + c)
        .collect();
    welch(&x, 1024.0, Some(256)).unwrap()
}

/// Within three bins of DC a tone shares its bins with its mirror image (-f), within three of
/// fs/2 with fs - f: neither its level nor its frequency is read there (a tone 0.4 bin from DC
/// read as a DC level 1.1 dB low, one 0.4 bin below fs/2 1.3 dB and 0.4 bin off). A constant,
/// whose bin 1 holds exactly the Hann window's leakage, is a DC level read exactly; a tone
/// three bins up or more is read to 0.02 dB.
#[test]
fn tones_against_their_mirror_images_are_said_unresolved() {
    use gyroemu_spectrum::unresolved;
    let strongest = |p: &Psd| find_tones(p, 1, 20.0)[0];
    for f in [1.6, 4.0, 8.0, 510.4, 506.0, 502.5] {
        let p = tone_psd(1.0, f, 0.0);
        let t = strongest(&p);
        let why = unresolved(&p, &t).unwrap_or_else(|| panic!("{f} Hz read as {t:?}"));
        let edge = if f < 256.0 { "of DC" } else { "of fs/2" };
        assert!(
            why.contains(edge) && why.contains("4 Hz bins"),
            "{f} Hz: {why}"
        );
    }
    for (a, f, c, ms) in [
        (0.0, 0.0, 0.7, 0.49),
        (1.0, 100.3, 0.0, 0.5),
        (1.0, 12.0, 0.0, 0.5),
        (1.0, 10.5, 0.0, 0.5),
        (1.0, 500.0, 0.0, 0.5),
    ] {
        let p = tone_psd(a, f, c);
        let t = strongest(&p);
        assert_eq!(unresolved(&p, &t), None, "{f} Hz: {t:?}");
        let db = 10.0 * (t.mean_square / ms).log10();
        assert!(db.abs() < 0.02, "{f} Hz: {db} dB off");
    }
}
