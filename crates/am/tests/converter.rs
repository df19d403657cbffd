//! The quantiser and the DAC: noise power, symmetry, idempotence, clipping, the hold's
//! frequency response, parameter errors.

use gyroemu_am::{Dac, Quantizer};
use gyroemu_core::{f64x4, Sample, Stage};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// A busy signal: three incommensurate tones, peak below 0.95 of full scale.
fn busy(n: usize, full_scale: f64) -> impl Iterator<Item = f64> {
    (0..n).map(move |i| {
        let t = i as f64;
        full_scale
            * (0.45 * (TAU * 0.013_127_941_3 * t).sin()
                + 0.3 * (TAU * 0.171_428_571_9 * t + 1.0).sin()
                + 0.2 * (TAU * 0.031_622_776_6 * t + 2.0).cos())
    })
}

#[test]
fn noise_power_is_step_squared_over_twelve() {
    for bits in [8u32, 12, 16, 24] {
        let full_scale = 2.5;
        let mut q = Quantizer::<f64>::new(bits, full_scale).unwrap();
        assert_eq!(q.step(), 2.0 * full_scale / 2f64.powi(bits as i32));
        let n = 1 << 20;
        let mut sum = 0.0;
        let mut worst: f64 = 0.0;
        for x in busy(n, full_scale) {
            let e = q.tick(x) - x;
            worst = worst.max(e.abs());
            sum += e * e;
        }
        let ratio = sum / n as f64 / (q.step() * q.step() / 12.0);
        println!("{bits} bits: noise power / (step^2/12) = {ratio:.4}");
        assert!((ratio - 1.0).abs() < 0.03, "{bits} bits: {ratio}");
        assert!(worst <= 0.5 * q.step() * (1.0 + 1e-12));
    }
}

#[test]
fn odd_symmetric_idempotent_and_clipping() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for bits in [2u32, 5, 12, 32] {
        let fs = 1.7;
        let q = Quantizer::<f64>::new(bits, fs).unwrap();
        let step = q.step();
        let top = fs - step; // largest level
        for _ in 0..20_000 {
            let x: f64 = rng.random_range(-1.5 * fs..1.5 * fs);
            let y = q.quantize(x);
            assert_eq!(q.quantize(y), y, "idempotent");
            // On the level grid: y / step is an integer code (to rounding).
            let code = y / step;
            assert!((code - code.round()).abs() < 1e-6);
            assert!((-fs..=top).contains(&y));
            if x.abs() <= top {
                assert_eq!(q.quantize(-x), -y, "odd symmetry at {x}");
                assert!((y - x).abs() <= 0.5 * step * (1.0 + 1e-12));
            }
            if x >= top + 0.5 * step {
                assert_eq!(y, top);
            }
            if x <= -fs {
                assert_eq!(y, -fs);
            }
        }
        assert_eq!(q.quantize(0.0), 0.0); // mid-tread: zero is a level
        assert_eq!(q.quantize(0.49 * step), 0.0);
        assert_eq!(q.quantize(1e9), top);
        assert_eq!(q.quantize(-1e9), -fs);
    }
}

#[test]
fn dac_quantises_or_passes_through() {
    let mut ideal = Dac::<f64>::new(1e6, None).unwrap();
    let mut real = Dac::<f64>::new(1e6, Some((12, 1.0))).unwrap();
    let q = Quantizer::<f64>::new(12, 1.0).unwrap();
    assert!(ideal.quantizer().is_none());
    assert_eq!(real.quantizer().map(|q| q.bits()), Some(12));
    for x in busy(10_000, 1.0) {
        assert_eq!(ideal.tick(x), x);
        assert_eq!(real.tick(x), q.quantize(x));
    }
    assert_eq!(real.fs_hz(), 1e6);
}

#[test]
fn bad_parameters_are_refused() {
    for (bits, fs) in [
        (1, 1.0),
        (33, 1.0),
        (0, 1.0),
        (12, 0.0),
        (12, -1.0),
        (12, f64::NAN),
    ] {
        let e = Quantizer::<f64>::new(bits, fs).unwrap_err();
        assert_eq!(e.stage, "quantizer");
        let e2 = Dac::<f64>::new(1e6, Some((bits, fs))).unwrap_err();
        assert_eq!(e2, e);
    }
    assert_eq!(Quantizer::<f64>::new(1, 1.0).unwrap_err().param, "bits");
    assert_eq!(
        Quantizer::<f64>::new(8, 0.0).unwrap_err().param,
        "full_scale"
    );
    for fs in [0.0, -1.0, f64::INFINITY, f64::NAN] {
        let e = Dac::<f64>::new(fs, None).unwrap_err();
        assert_eq!((e.stage, e.param), ("dac", "fs_hz"));
    }
    assert!(Quantizer::<f64>::new(2, 1.0).is_ok() && Quantizer::<f64>::new(32, 1.0).is_ok());
}

#[test]
fn counting_quantizer_gives_the_same_bits_and_counts_clips_and_zeros() {
    // 4 bits over +-1: step 1/8, codes -8..=7, so inputs beyond 7.5 steps up or 8.5 steps down
    // clip, and inputs within half a step of 0 give an exact 0.
    let q = Quantizer::<f64>::new(4, 1.0).unwrap();
    let xs = [
        0.0, 0.06, -0.0624, 0.0626, 0.93, 0.94, -1.06, -1.07, 5.0, -5.0,
    ];
    let clips = [0, 0, 0, 0, 0, 1, 0, 1, 1, 1];
    let zeros = [1, 1, 1, 0, 0, 0, 0, 0, 0, 0];
    for (i, &x) in xs.iter().enumerate() {
        let (mut c, mut z) = (0.0, 0.0);
        let y = q.quantize_counting(x, &mut c, &mut z);
        assert_eq!(y.to_bits(), q.quantize(x).to_bits(), "x = {x}");
        assert_eq!((c, z), (clips[i] as f64, zeros[i] as f64), "x = {x}");
    }
    // Lanes count on their own.
    let v = Quantizer::<f64x4>::new(4, 1.0).unwrap();
    let (mut c, mut z) = (f64x4::splat(0.0), f64x4::splat(0.0));
    for chunk in xs.chunks(4).filter(|c| c.len() == 4) {
        v.quantize_counting(f64x4::from_fn(|i| chunk[i]), &mut c, &mut z);
    }
    let (want_c, want_z): (Vec<f64>, Vec<f64>) = (0..4)
        .map(|l| {
            let sel = |t: &[i32; 10]| {
                (0..8)
                    .filter(|k| k % 4 == l)
                    .map(|k| t[k] as f64)
                    .sum::<f64>()
            };
            (sel(&clips), sel(&zeros))
        })
        .unzip();
    for l in 0..4 {
        assert_eq!((c.lane(l), z.lane(l)), (want_c[l], want_z[l]), "lane {l}");
    }
}
