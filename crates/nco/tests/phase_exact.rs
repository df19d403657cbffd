//! No phase drift: after 5e8 steps the phase equals the exact rational value, and jump(N)
//! equals N ticks bit for bit.

use gyroemu_core::Stage;
use gyroemu_nco::Nco;
use std::f64::consts::TAU;

const FS_HZ: u128 = 1_000_000;
/// f = P / 2^30 Hz = 10 000.123 463 5.. Hz, exactly representable in f64 (P < 2^53).
const P: u128 = 10_000 * (1 << 30) + 132_567_891;

fn f_hz() -> f64 {
    P as f64 / (1u64 << 30) as f64
}

/// `f * n / fs mod 1` in exact integer arithmetic, as turns.
fn exact_turns(n: u128) -> f64 {
    let den = FS_HZ << 30;
    ((P * n) % den) as f64 / den as f64
}

fn circ_dist_rad(a_rad: f64, b_rad: f64) -> f64 {
    let d = (a_rad - b_rad).rem_euclid(TAU);
    d.min(TAU - d)
}

#[test]
fn jump_5e8_matches_exact_rational_phase() {
    assert_eq!(P as f64 as u128, P);
    let n: u64 = 500_000_000;
    let mut nco = Nco::new(f_hz(), FS_HZ as f64, 0.0).unwrap();
    nco.jump(n);
    let want = exact_turns(n as u128) * TAU;
    let err = circ_dist_rad(nco.phase_rad(), want);
    println!("phase error after 5e8 steps (jump): {err:.3e} rad");
    assert!(err < 1e-9, "phase error {err} rad");
}

#[test]
fn ticks_equal_jump_bit_for_bit() {
    // 5e8 ticks take ~1 s in release; debug builds use fewer.
    let n: u64 = if cfg!(debug_assertions) {
        5_000_000
    } else {
        500_000_000
    };
    let mut a = Nco::new(f_hz(), FS_HZ as f64, 1.234).unwrap();
    let mut b = a.clone();
    let t0 = std::time::Instant::now();
    let mut acc = 0.0;
    for _ in 0..n {
        acc += a.tick(()).re;
    }
    println!(
        "{n} ticks in {:.2} s (checksum {acc:.6})",
        t0.elapsed().as_secs_f64()
    );
    b.jump(n);
    assert_eq!(a.phase_word(), b.phase_word());
    let start = Nco::new(f_hz(), FS_HZ as f64, 1.234).unwrap();
    let want = 1.234 + exact_turns(n as u128) * TAU;
    assert!(circ_dist_rad(a.phase_rad(), want) < 1e-9);
    assert_eq!(
        a.phase_word(),
        start
            .phase_word()
            .wrapping_add(start.step_word().wrapping_mul(n))
    );
}

#[test]
fn realised_frequency_is_within_quantum() {
    for &(f, fs) in &[
        (f_hz(), 1e6),
        (-3_333.333_333, 48_000.0),
        (0.0, 1.0),
        (0.1, 1.0),
    ] {
        let nco = Nco::new(f, fs, 0.0).unwrap();
        let quantum = fs / 2f64.powi(64);
        assert!(
            (nco.f_hz() - f).abs() <= quantum + f.abs() * 2.3e-16,
            "{f} {fs}"
        );
        assert_eq!(nco.fs_hz(), fs);
    }
}
