//! The stage contract (gyroemu_core::check) for the oscillators and the phase shifter: block
//! processing and reset bit for bit (blocks that straddle the rotating NCO's re-sets), the
//! f64x4 rotating NCO lane by lane against one scalar rotating NCO per lane, and the shifter's
//! zero latency. The NCOs are sources (no input), so they have no impulse response.

use gyroemu_core::check::{self, Gen};
use gyroemu_core::{f64x4, Complex64, Sample, Stage};
use gyroemu_nco::{Nco, PhaseShifter, RotatingNco};

const FS_HZ: f64 = 1e6;

/// Signed frequencies from near DC to near Nyquist, each with its own start phase.
fn ncos() -> Vec<Nco> {
    [
        (15_000.0, 0.0),
        (-31_415.926_535, 2.5),
        (0.060_7, 6.2),
        (499_999.9, 1.0),
    ]
    .iter()
    .map(|&(f, p)| Nco::new(f, FS_HZ, p).unwrap())
    .collect()
}

fn none(_: &mut Gen) {}

#[test]
fn nco_blocks_and_reset_are_bit_exact() {
    for nco in ncos() {
        check::tick_vs_process("nco", &nco, none, check::same);
        check::reset_restores("nco", &nco, none, check::same);
    }
}

#[test]
fn rotating_nco_blocks_reset_and_lanes_are_bit_exact() {
    let ncos = ncos();
    let v = RotatingNco::<f64x4>::new(&ncos);
    check::tick_vs_process("rotating_nco<f64x4>", &v, none, check::same);
    check::reset_restores("rotating_nco<f64x4>", &v, none, check::same);
    let scalars: Vec<RotatingNco<f64>> = ncos
        .iter()
        .map(|n| RotatingNco::new(std::slice::from_ref(n)))
        .collect();
    for s in &scalars {
        check::tick_vs_process("rotating_nco<f64>", s, none, check::same);
        check::reset_restores("rotating_nco<f64>", s, none, check::same);
    }
    check::lanes_match(
        "rotating_nco",
        &v,
        &scalars,
        none,
        |_, _| (),
        |&(c, s), l| (c.lane(l), s.lane(l)),
        check::same,
    );
}

#[test]
fn a_lane_replaced_at_a_re_set_runs_as_a_fresh_oscillator() {
    // Another frequency from another phase (a board's lane refilled with another point,
    // started some samples into its own time axis): from the re-set on, the lane gives the
    // bits of an oscillator built from that NCO alone, whose re-sets fall on the same ticks.
    let mut next = Nco::new(-0.731, FS_HZ, 0.0).unwrap();
    next.jump(123_456);
    for at in [64, 64 * 17] {
        check::lane_replaced_matches(
            "rotating_nco",
            &RotatingNco::<f64x4>::new(&ncos()),
            (1, 4, at),
            |v: &mut RotatingNco<f64x4>, l| v.set_lane_at_resync(l, &next).unwrap(),
            &RotatingNco::<f64>::new(&[next.clone()]),
            none,
            |_, _| (),
            |&(c, s), l| (c.lane(l), s.lane(l)),
            check::same,
        );
    }
}

#[test]
fn a_lane_is_replaced_only_at_a_re_set() {
    let mut v = RotatingNco::<f64x4>::new(&ncos());
    let other = Nco::new(100.0, FS_HZ, 0.0).unwrap();
    // Built: the re-set of sample 0 is done, the next is 64 ticks away.
    for ticks in [0, 1, 63] {
        let mut w = v.clone();
        for _ in 0..ticks {
            w.tick(());
        }
        let before = w.clone();
        let e = w.set_lane_at_resync(0, &other).unwrap_err();
        assert_eq!(e.param, "count", "{e}");
        // Refused: nothing changed (the next ticks are the untouched copy's).
        let mut b = before;
        for _ in 0..200 {
            assert_eq!(w.tick(()), b.tick(()));
        }
    }
    for _ in 0..64 {
        v.tick(());
    }
    assert!(v.at_resync());
    assert_eq!(v.set_lane_at_resync(4, &other).unwrap_err().param, "lane");
    let slow = Nco::new(100.0, 48_000.0, 0.0).unwrap();
    assert_eq!(v.set_lane_at_resync(0, &slow).unwrap_err().param, "fs_hz");
    assert!(v.set_lane_at_resync(0, &other).is_ok());
}

#[test]
fn phase_shifter_is_memoryless_and_bit_exact() {
    for shifter in [
        PhaseShifter::quadrature(),
        PhaseShifter::new(0.3).unwrap(),
        PhaseShifter::new(-2.0).unwrap(),
    ] {
        check::tick_vs_process("phase_shifter", &shifter, |g| g.phasor(), check::same);
        check::reset_restores("phase_shifter", &shifter, |g| g.phasor(), check::same);
    }
    // The real part of a real input rotated by 0.3 rad: h = [cos 0.3], no delay.
    let mut s = PhaseShifter::new(0.3).unwrap();
    let lat = s.latency_samples();
    check::latency_matches(
        "phase_shifter",
        lat,
        |x| s.tick(Complex64::new(x, 0.0)).re,
        8,
        0.0,
    );
}
