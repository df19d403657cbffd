//! Structural invariants of the TIA: sign inversion, rails, block processing, reset, lanes.

use gyroemu_core::{f64x4, Sample, Stage};
use gyroemu_tia::{Tia, TiaParams};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn params(inverting: bool, rail_v: Option<f64>) -> TiaParams {
    TiaParams {
        gain_ohm: 2.2e5,
        pole_hz: Some(3.3e4),
        inverting,
        rail_v,
        fs_hz: 1e6,
    }
}

fn noise(n: usize, scale: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| scale * (rng.random::<f64>() - 0.5))
        .collect()
}

#[test]
fn inverting_flips_the_sign_exactly() {
    let x = noise(5000, 1e-5, 1);
    let mut p = Tia::<f64>::new(&params(false, Some(1.0))).unwrap();
    let mut n = Tia::<f64>::new(&params(true, Some(1.0))).unwrap();
    for &v in &x {
        assert_eq!(p.tick(v).to_bits(), (-n.tick(v)).to_bits());
    }
}

#[test]
fn rails_clip_and_recovery_follows_the_pole_without_windup() {
    let rail = 1.5;
    let mut t = Tia::<f64>::new(&params(false, Some(rail))).unwrap();
    let mut peak: f64 = 0.0;
    for &v in &noise(20_000, 1e-4, 2) {
        let y = t.tick(v);
        peak = peak.max(y.abs());
        assert!(y.abs() <= rail);
    }
    assert_eq!(peak, rail, "a 22 V swing must clip at the rail");
    // Overload hard for a long time, then release: the output decays as rail * a^n at once.
    for _ in 0..10_000 {
        assert_eq!(t.tick(1.0), rail);
    }
    let a = (-std::f64::consts::TAU * 3.3e4 / 1e6).exp();
    for n in 1..200 {
        let y = t.tick(0.0);
        assert!((y - rail * a.powi(n)).abs() <= 1e-13 * rail, "n = {n}: {y}");
    }
    let mut neg = Tia::<f64>::new(&params(true, Some(rail))).unwrap();
    for _ in 0..100 {
        neg.tick(1.0);
    }
    assert_eq!(neg.tick(1.0), -rail);
}

#[test]
fn process_on_random_chunkings_equals_tick_and_reset_reproduces() {
    let x = noise(10_000, 4e-5, 3);
    let mut t = Tia::<f64>::new(&params(true, Some(2.0))).unwrap();
    let reference: Vec<f64> = x.iter().map(|&v| t.tick(v)).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    for _ in 0..5 {
        t.reset();
        let mut out = vec![0.0; x.len()];
        let mut i = 0;
        while i < x.len() {
            let len = rng.random_range(0..300usize).min(x.len() - i);
            t.process(&x[i..i + len], &mut out[i..i + len]);
            i += len;
        }
        assert!(out
            .iter()
            .zip(&reference)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}

#[test]
fn f64x4_lanes_equal_scalar_bit_for_bit() {
    let xs: Vec<Vec<f64>> = (0..4)
        .map(|l| noise(5000, 3e-5 * (l + 1) as f64, 10 + l as u64))
        .collect();
    let mut v = Tia::<f64x4>::new(&params(true, Some(2.0))).unwrap();
    let out: Vec<f64x4> = (0..5000)
        .map(|i| v.tick(f64x4::from_fn(|l| xs[l][i])))
        .collect();
    for (l, x) in xs.iter().enumerate() {
        let mut s = Tia::<f64>::new(&params(true, Some(2.0))).unwrap();
        for (i, &xi) in x.iter().enumerate() {
            assert_eq!(
                s.tick(xi).to_bits(),
                out[i].lane(l).to_bits(),
                "lane {l} sample {i}"
            );
        }
    }
}

proptest::proptest! {
    #[test]
    fn linear_below_the_rails(g in 1.0f64..1e6, pole in 1.0f64..4.9e5, scale in -1e3f64..1e3) {
        // Homogeneity by an exact power of two holds bit for bit for a linear recurrence.
        let p = TiaParams { gain_ohm: g, pole_hz: Some(pole), inverting: true, rail_v: None, fs_hz: 1e6 };
        let mut a = Tia::<f64>::new(&p).unwrap();
        let mut b = Tia::<f64>::new(&p).unwrap();
        for v in noise(200, scale.abs() + 1e-9, 7) {
            proptest::prop_assert_eq!((a.tick(v) * 4.0).to_bits(), b.tick(v * 4.0).to_bits());
        }
    }
}
