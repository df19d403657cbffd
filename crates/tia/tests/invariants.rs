//! Structural invariants of the TIA: sign inversion, rails, homogeneity (block processing,
//! reset and lanes are checked by the shared harness in tests/contract.rs).

use gyroemu_core::Stage;
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
