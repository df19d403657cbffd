//! Frequency control (what a PLL steers): `set_frequency_hz` keeps the phase continuous,
//! lands on the exact word of the new frequency, refuses a bad frequency without a trace, and
//! `reset` restores the built frequency. The expected words come from integer arithmetic on
//! exactly representable frequencies; the expected phasors from libm.

use gyroemu_core::{f64x4, Complex64, Sample, Stage};
use gyroemu_nco::{Nco, RotatingNco, RESYNC};
use std::f64::consts::TAU;

const FS_HZ: f64 = 1e6;

/// `f = p / 2^30` Hz, exact in f64 for `p < 2^53`.
fn f_of(p: u64) -> f64 {
    p as f64 / (1u64 << 30) as f64
}

/// The exact step word of `p / 2^30` Hz at 1 MHz: `p 2^34 / 1e6`, rounded to nearest
/// (ties do not occur for the `p` used here), by integer arithmetic.
fn word_of(p: u64) -> u64 {
    let num = (p as u128) << 34;
    let (q, r) = (num / 1_000_000, num % 1_000_000);
    (q + u128::from(2 * r > 1_000_000)) as u64
}

/// `e^{j 2 pi w / 2^64}` from libm (quadrant exact from the top two bits).
fn libm_phasor(w: u64) -> Complex64 {
    let a = (w & ((1u64 << 62) - 1)) as f64 * (TAU / 2f64.powi(64));
    let rot = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][(w >> 62) as usize];
    Complex64::new(a.cos(), a.sin()) * Complex64::new(rot.0, rot.1)
}

const P_OLD: u64 = 12_345 * (1 << 30) + 987_654_321;
const P_NEW: u64 = 12_351 * (1 << 30) + 123_456_789;

#[test]
fn nco_change_is_phase_continuous_and_lands_on_the_exact_word() {
    let mut nco = Nco::new(f_of(P_OLD), FS_HZ, 0.7).unwrap();
    let start = nco.phase_word();
    assert_eq!(nco.step_word(), word_of(P_OLD));
    let (n1, n2) = (1_234u64, 500_000u64);
    for _ in 0..n1 {
        nco.tick(());
    }
    nco.set_frequency_hz(f_of(P_NEW)).unwrap();
    // Only the step changed: the accumulator is where n1 old steps put it.
    let at_change = start.wrapping_add(word_of(P_OLD).wrapping_mul(n1));
    assert_eq!(nco.phase_word(), at_change);
    assert_eq!(nco.step_word(), word_of(P_NEW));
    // The realised frequency is within half a word of the request.
    let word_hz = FS_HZ / 2f64.powi(64);
    assert!((nco.f_hz() - f_of(P_NEW)).abs() <= 0.5 * word_hz);
    let mut worst = 0.0f64;
    for k in 0..n2 {
        let want = at_change.wrapping_add(word_of(P_NEW).wrapping_mul(k));
        assert_eq!(nco.phase_word(), want, "sample {k} after the change");
        worst = worst.max((nco.tick(()) - libm_phasor(want)).norm());
    }
    println!("worst |phasor - libm| after the change: {worst:.2e}");
    assert!(worst < 1e-15, "{worst}");
}

#[test]
fn the_sample_after_the_change_continues_the_old_phase() {
    // The rotation between the last output before the change and the first after it is the
    // old step; from then on it is the new one: no phase jump.
    let (f_old, f_new) = (f_of(P_OLD), f_of(P_NEW));
    let mut nco = Nco::new(f_old, FS_HZ, 2.0).unwrap();
    let rot = |f: f64| Complex64::from_polar(1.0, TAU * f / FS_HZ);
    let mut prev = nco.tick(());
    for _ in 0..99 {
        prev = nco.tick(());
    }
    nco.set_frequency_hz(f_new).unwrap();
    let first = nco.tick(());
    assert!((first - prev * rot(f_old)).norm() < 1e-14);
    let second = nco.tick(());
    assert!((second - first * rot(f_new)).norm() < 1e-14);
    assert!(
        (second - first * rot(f_old)).norm() > 1e-5,
        "the step did not change"
    );
}

#[test]
fn a_bad_frequency_is_refused_and_changes_nothing() {
    let mut nco = Nco::new(1_000.0, FS_HZ, 0.1).unwrap();
    for _ in 0..17 {
        nco.tick(());
    }
    let mut twin = nco.clone();
    for bad in [f64::NAN, f64::INFINITY, 0.5 * FS_HZ, -0.5 * FS_HZ, 7e5] {
        let e = nco.set_frequency_hz(bad).unwrap_err();
        assert_eq!((e.stage, e.param), ("nco", "f_hz"), "{e}");
    }
    for _ in 0..1000 {
        assert_eq!(nco.tick(()), twin.tick(()));
    }
    let mut rot = RotatingNco::<f64x4>::new(&[nco.clone()]);
    let mut rot_twin = rot.clone();
    assert_eq!(rot.set_frequency_hz(0, f64::NAN).unwrap_err().param, "f_hz");
    assert_eq!(rot.set_frequency_hz(4, 1.0).unwrap_err().param, "lane");
    let mut scalar = RotatingNco::<f64>::new(&[nco]);
    let e = scalar.set_frequency_hz(1, 1.0).unwrap_err();
    assert_eq!((e.stage, e.param), ("rotating_nco", "lane"), "{e}");
    for _ in 0..1000 {
        let (a, b) = (rot.tick(()), rot_twin.tick(()));
        assert_eq!(
            (a.0.to_array(), a.1.to_array()),
            (b.0.to_array(), b.1.to_array())
        );
    }
}

#[test]
fn reset_restores_the_built_frequency() {
    let fresh = Nco::new(f_of(P_OLD), FS_HZ, 1.3).unwrap();
    let mut nco = fresh.clone();
    let mut rot = RotatingNco::<f64>::new(std::slice::from_ref(&fresh));
    for _ in 0..100 {
        nco.tick(());
        rot.tick(());
    }
    nco.set_frequency_hz(f_of(P_NEW)).unwrap();
    rot.set_frequency_hz(0, f_of(P_NEW)).unwrap();
    for _ in 0..100 {
        nco.tick(());
        rot.tick(());
    }
    nco.reset();
    rot.reset();
    assert_eq!(nco.f_hz(), fresh.f_hz());
    assert_eq!(rot.f_hz(0), fresh.f_hz());
    let (mut a, mut b) = (fresh.clone(), RotatingNco::<f64>::new(&[fresh]));
    for _ in 0..1000 {
        assert_eq!(nco.tick(()), a.tick(()));
        assert_eq!(rot.tick(()), b.tick(()));
    }
}

/// Four lanes, each changed at its own samples (every position in the re-set cycle: at a
/// re-set, just after, mid-way, just before), against four exact NCOs changed alike: within
/// 1e-14 throughout, bit-identical to the exact phasor on the sample right after each change,
/// and each lane bit-identical to a scalar rotating NCO changed alike.
#[test]
fn rotating_nco_lanes_follow_exact_ncos_through_changes() {
    let r = u64::from(RESYNC);
    let starts = [
        (15_000.0, 0.0),
        (-31_415.926_535, 2.5),
        (0.060_7, 6.2),
        (4e5, 1.0),
    ];
    let ncos: Vec<Nco> = starts
        .iter()
        .map(|&(f, p)| Nco::new(f, FS_HZ, p).unwrap())
        .collect();
    // (sample index, lane, new frequency)
    let mut changes: Vec<(u64, usize, f64)> = vec![
        (0, 0, 15_001.5),
        (r, 1, -31_000.0),
        (r + 1, 2, 12.25),
        (3 * r - 1, 3, -4.9e5),
        (5 * r + 17, 0, 14_999.0),
        (5 * r + 17, 1, 1e-3),
        (9 * r + 33, 2, 0.0),
        (20 * r, 3, 4.99e5),
    ];
    changes.sort_by_key(|c| c.0);
    let mut exact = ncos.clone();
    let mut vec4 = RotatingNco::<f64x4>::new(&ncos);
    let mut scalars: Vec<RotatingNco<f64>> = ncos
        .iter()
        .map(|n| RotatingNco::new(std::slice::from_ref(n)))
        .collect();
    let mut worst = 0.0f64;
    for n in 0..100_000u64 {
        let mut changed = [false; 4];
        for &(at, lane, f) in changes.iter().filter(|c| c.0 == n) {
            exact[lane].set_frequency_hz(f).unwrap();
            vec4.set_frequency_hz(lane, f).unwrap();
            scalars[lane].set_frequency_hz(0, f).unwrap();
            assert_eq!(vec4.f_hz(lane), exact[lane].f_hz(), "sample {at}");
            assert_eq!(vec4.next_phase_word(lane), exact[lane].phase_word());
            changed[lane] = true;
        }
        let (c, s) = vec4.tick(());
        for lane in 0..4 {
            let p = exact[lane].tick(());
            let (sc, ss) = scalars[lane].tick(());
            assert_eq!(
                (c.lane(lane), s.lane(lane)),
                (sc, ss),
                "lane {lane} sample {n}"
            );
            if changed[lane] {
                assert_eq!((sc, ss), (p.re, p.im), "lane {lane} sample {n}");
            }
            worst = worst.max((sc - p.re).abs()).max((ss - p.im).abs());
        }
    }
    println!("worst deviation from the exact NCOs: {worst:.2e}");
    assert!(worst < 1e-14, "{worst}");
}
