//! A peak is read as one tone only when it looks like one: its neighbouring bins hold one
//! tone's Hann leakage (a second tone within two bins shares them), and its power stays put
//! across the Welch segments (noise's moves by about 100 %). Seeded noise and sums of exact
//! sinusoids, checked against their definitions.

use gyroemu_spectrum::{find_tones, unresolved, welch, Psd, SPREAD_MAX};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

const FS: f64 = 1024.0;
/// 4096 samples in 256-sample segments: 4 Hz bins, 31 segments.
const N: usize = 4096;
const L: usize = 256;

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
}

/// `sum a cos(2 pi f t + phase)` plus white noise of standard deviation `sigma`.
fn record(tones: &[(f64, f64, f64)], sigma: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..N)
        .map(|n| {
            let t = n as f64 / FS;
            let s: f64 = tones
                .iter()
                .map(|&(a, f, ph)| a * (2.0 * PI * f * t + ph).cos())
                .sum();
            s + sigma * gauss(&mut rng)
        })
        .collect()
}

fn psd(x: &[f64]) -> Psd {
    welch(x, FS, Some(L)).unwrap()
}

/// Every tone the finder reads (not said unresolved) is one of `truth` (frequency, mean
/// square) within 0.05 bin and 0.1 dB.
fn read_tones_are_true(p: &Psd, truth: &[(f64, f64)], what: &str) -> usize {
    let mut read = 0;
    for t in find_tones(p, 4, 20.0) {
        if unresolved(p, &t).is_some() {
            continue;
        }
        read += 1;
        let ok = truth.iter().any(|&(f, ms)| {
            (t.freq_hz - f).abs() < 0.05 * p.bin_hz()
                && (10.0 * (t.mean_square / ms).log10()).abs() < 0.1
        });
        assert!(ok, "{what}: read {t:?}, truth {truth:?}");
    }
    read
}

#[test]
fn two_tones_within_two_bins_are_said_unresolved_and_never_misread() {
    // Unit tones 1 to 2.4 bins apart, on and between bins, at several relative phases: before,
    // two bins apart read 1.6 to 2.6 dB low and a quarter bin off, closer ones as one tone.
    let bin = FS / L as f64;
    let mut said = 0;
    let mut cases = 0;
    for sep in [1.0, 1.5, 2.0, 2.4, 2.7, 3.0] {
        for start in [50.0, 50.25, 50.5] {
            for ph in [0.0, 0.9, 1.7, 2.6] {
                let (f1, f2) = (start * bin, (start + sep) * bin);
                let x = record(&[(1.0, f1, 0.0), (1.0, f2, ph)], 0.0, 0);
                let p = psd(&x);
                let what = format!("sep {sep} bins from bin {start}, phase {ph}");
                read_tones_are_true(&p, &[(f1, 0.5), (f2, 0.5)], &what);
                if sep <= 2.0 {
                    let strongest = find_tones(&p, 1, 20.0)[0];
                    cases += 1;
                    said += usize::from(unresolved(&p, &strongest).is_some());
                }
            }
        }
    }
    // Within two bins the strongest peak is a pair's sum in most cases (a tone on a bin with
    // its partner's leakage cancelled there is read exactly, and passes above).
    assert!(said * 2 >= cases, "{said} of {cases} said unresolved");
}

#[test]
fn tones_three_and_a_half_bins_apart_or_more_are_both_read() {
    // From 2.5 to 3 bins apart a pair is sometimes said unresolved (and never misread: the
    // test above); from 3.5 on both are read.
    let bin = FS / L as f64;
    for sep in [3.5, 5.0, 12.25] {
        for ph in [0.0, 1.3, 2.9] {
            let (f1, f2) = (50.3 * bin, (50.3 + sep) * bin);
            let x = record(&[(1.0, f1, 0.0), (0.5, f2, ph)], 0.0, 0);
            let p = psd(&x);
            let what = format!("sep {sep} bins, phase {ph}");
            let read = read_tones_are_true(&p, &[(f1, 0.5), (f2, 0.125)], &what);
            assert_eq!(read, 2, "{what}");
        }
    }
}

#[test]
fn a_rotating_drive_shows_its_sidebands_or_says_they_are_unresolved() {
    // cos(Omega t) cos(w0 t): two sidebands of amplitude 1/2 (-9.03 dB) at fc +- Omega and
    // nothing at fc. Omega one bin (the default dump window's case) shares their bins; four
    // bins apart they are read.
    let bin = FS / L as f64;
    let fc = 60.0 * bin;
    for (om_bins, resolved) in [
        (0.75, false),
        (1.0, false),
        (2.0, true),
        (4.0, true),
        (6.5, true),
    ] {
        let om = om_bins * bin;
        let x: Vec<f64> = (0..N)
            .map(|n| {
                let t = n as f64 / FS;
                (2.0 * PI * om * t).cos() * (2.0 * PI * fc * t).cos()
            })
            .collect();
        let p = psd(&x);
        let read = read_tones_are_true(&p, &[(fc - om, 0.125), (fc + om, 0.125)], "drive");
        assert_eq!(read, if resolved { 2 } else { 0 }, "Omega {om_bins} bins");
    }
}

#[test]
fn a_tone_in_noise_is_read_whatever_its_offset() {
    // The shape test must not refuse a lone tone: 20 to 40 dB above the noise in its bins,
    // any offset between bins, many seeds.
    let bin = FS / L as f64;
    for seed in 0..20u64 {
        for (offset, snr_db) in [(0.0, 25.0), (0.25, 30.0), (0.5, 25.0), (0.8, 40.0)] {
            let f = (80.0 + offset) * bin;
            // Noise power per bin: sigma^2 enbw / fs ... the tone's mean square 0.5 over it.
            let per_bin = 0.5 / 10f64.powf(snr_db / 10.0);
            let sigma = (per_bin * FS / (2.0 * 1.5 * bin)).sqrt();
            let x = record(&[(1.0, f, 0.4)], sigma, seed);
            // 31 segments, and 7 (the fewest a default segment length gives).
            for x in [&x[..], &x[..1024]] {
                let p = psd(x);
                let t = find_tones(&p, 1, 20.0)[0];
                let why = unresolved(&p, &t);
                assert_eq!(
                    why, None,
                    "seed {seed}, offset {offset}, {} segments",
                    p.segments
                );
                assert!((t.freq_hz - f).abs() < 0.05 * bin, "{t:?}");
            }
        }
    }
}

#[test]
fn noise_in_a_narrow_pass_band_is_never_read_as_a_tone() {
    // White noise through four one-pole low-passes with their corner two bins up: its pass
    // band spans a few bins, the rest is stop band, so its bumps stood 20 dB above the local
    // median and were listed as tones (a low-passed node's dump of 480 samples read two).
    let bin = FS / L as f64;
    let a = (-2.0 * PI * 2.0 * bin / FS).exp();
    let mut listed = 0;
    for seed in 0..40u64 {
        let mut x = record(&[], 1.0, seed);
        for _ in 0..4 {
            let mut y = 0.0;
            for v in &mut x {
                y = a * y + (1.0 - a) * *v;
                *v = y;
            }
        }
        let p = psd(&x);
        for t in find_tones(&p, 4, 20.0) {
            listed += 1;
            assert!(
                unresolved(&p, &t).is_some(),
                "seed {seed}: noise read as {t:?} (spread {})",
                p.spread[t.bin]
            );
        }
    }
    // The case arises: the finder lists bumps, which are then said unresolved.
    assert!(listed > 0);
}

#[test]
fn the_spread_is_zero_for_a_steady_tone_and_near_one_for_noise() {
    let p = psd(&record(&[(1.0, 200.3, 0.2)], 0.0, 0));
    let k = find_tones(&p, 1, 20.0)[0].bin;
    assert!(p.spread[k] < 1e-6, "tone: {}", p.spread[k]);
    // White noise: a bin's power is exponential in each segment (mean = standard deviation),
    // so the spread over 31 half-overlapping segments averages a little below 1.
    let p = psd(&record(&[], 1.0, 3));
    let inner = &p.spread[5..p.spread.len() - 5];
    let mean = inner.iter().sum::<f64>() / inner.len() as f64;
    assert!((0.85..1.02).contains(&mean), "noise: mean spread {mean}");
    let steady = inner.iter().filter(|&&s| s <= SPREAD_MAX).count();
    assert!(
        steady * 100 < inner.len(),
        "{steady} of {} noise bins steady",
        inner.len()
    );
    // One segment has no spread.
    let p = welch(&record(&[], 1.0, 3)[..L], FS, Some(L)).unwrap();
    assert!(p.spread.iter().all(|s| s.is_nan()));
}
