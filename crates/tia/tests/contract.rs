//! The stage contract (gyroemu_core::check) for the TIA: block processing, reset and lanes
//! bit for bit (rails on, inputs that clip), and, without rails (where it is linear), its
//! response against the DFT of its impulse response and its latency against the DC group
//! delay of that impulse response and the phase slope of the response.

use gyroemu_core::check::{self, Gen};
use gyroemu_core::{f64x4, Sample, Stage};
use gyroemu_tia::{Tia, TiaParams};

const FS_HZ: f64 = 1e6;

fn params(pole_hz: Option<f64>, inverting: bool, rail_v: Option<f64>) -> TiaParams {
    TiaParams {
        gain_ohm: 2.2e5,
        pole_hz,
        inverting,
        rail_v,
        fs_hz: FS_HZ,
    }
}

/// Currents up to 2e-5 A: with 2.2e5 ohm and 2 V rails the output clips now and then.
fn current(g: &mut Gen) -> f64 {
    g.uniform(-2e-5, 2e-5)
}

#[test]
fn blocks_reset_and_lanes_are_bit_exact() {
    for p in [
        params(Some(3.3e4), true, Some(2.0)),
        params(Some(3.3e4), false, None),
        params(None, true, Some(2.0)),
    ] {
        let t = Tia::<f64>::new(&p).unwrap();
        check::tick_vs_process("tia", &t, current, check::same);
        check::reset_restores("tia", &t, current, check::same);
        let v = Tia::<f64x4>::new(&p).unwrap();
        check::lanes_match(
            "tia",
            &v,
            &[t.clone(), t.clone(), t.clone(), t],
            |g| g.sample(-2e-5, 2e-5),
            |x, l| x.lane(l),
            |y, l| y.lane(l),
            check::same,
        );
        // A lane reset mid-run (refilled with another point) starts as a fresh TIA.
        check::lane_replaced_matches(
            "tia",
            &v,
            (2, 4, 1234),
            Tia::reset_lane,
            &Tia::<f64>::new(&p).unwrap(),
            |g| g.sample(-2e-5, 2e-5),
            |x, l| x.lane(l),
            |y, l| y.lane(l),
            check::same,
        );
    }
}

#[test]
fn response_and_latency_match_the_impulse_response() {
    // a^1024 < 1e-50 for these poles; the harness checks the decay.
    for (pole, inverting) in [(Some(2e4), true), (Some(1.5e5), false), (None, true)] {
        let t = Tia::<f64>::new(&params(pole, inverting, None)).unwrap();
        let mut s = t.clone();
        let worst = check::response_matches_impulse("tia", FS_HZ, &t, |x| s.tick(x), 1024, 1e-12);
        eprintln!("tia pole {pole:?}: worst |DFT - H| / peak = {worst:e}");
        let mut s = t.clone();
        check::latency_matches("tia", t.latency_samples(), |x| s.tick(x), 1024, 1e-9);
        check::latency_matches_response("tia", t.latency_samples(), FS_HZ, &t, 1e-9);
    }
}
