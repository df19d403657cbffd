//! The bank's two biquads held out of it ([`BiquadPair`]): offered for exactly the designs of
//! two unit-numerator biquads, and bit for bit the bank's outputs and states however a run
//! is cut into held stretches and bank ticks.

use gyroemu_core::check::Gen;
use gyroemu_core::{f64x4, Sample, Stage};
use gyroemu_lpf::{LowPass, LowPassBank, LowPassDesign};

fn bank<S: Sample>(d: LowPassDesign, fs: f64) -> LowPassBank<S, 4> {
    LowPassBank::new(&LowPass::new(d, fs).unwrap())
}

#[test]
fn a_pair_is_offered_for_two_biquads_only() {
    for order in 1..=8 {
        let bw = LowPassDesign::Butterworth {
            order,
            cutoff_hz: 1e3,
        };
        // Butterworth: order / 2 biquads, plus a first-order section when odd.
        let want = order == 4;
        assert_eq!(bank::<f64>(bw, 1e5).hold_pair().is_some(), want, "{bw:?}");
        let lock_in = LowPassDesign::LockIn { order, tau_s: 1e-3 };
        assert!(
            bank::<f64>(lock_in, 1e5).hold_pair().is_none(),
            "{lock_in:?}"
        );
    }
}

/// Runs `n` samples through a bank ticked throughout and through a copy whose run is cut,
/// at random, into stretches held as a pair (released after each) and stretches of plain
/// bank ticks; every output and the final states must agree bit for bit.
fn held_runs_match<S: Sample>(d: LowPassDesign, fs: f64, seed: u64) {
    let mut g = Gen::new(seed);
    let mut plain = bank::<S>(d, fs);
    let mut cut = plain.clone();
    let bits = |y: [S; 4]| -> Vec<u64> {
        y.iter()
            .flat_map(|v| (0..S::LANES).map(|l| v.lane(l).to_bits()))
            .collect()
    };
    let mut n = 0;
    while n < 20_000 {
        let len = 1 + (g.u64() % 300) as usize;
        let held = !g.u64().is_multiple_of(3);
        let mut pair = if held { cut.hold_pair() } else { None };
        assert_eq!(pair.is_some(), held, "{d:?}");
        for _ in 0..len {
            let x: [S; 4] = core::array::from_fn(|_| g.sample(-1.0, 1.0));
            let want = plain.tick(x);
            let got = match &mut pair {
                Some(p) => p.tick(x),
                None => cut.tick(x),
            };
            assert_eq!(bits(got), bits(want), "{d:?} sample {n}");
            n += 1;
        }
        if let Some(p) = &pair {
            cut.release_pair(p);
        }
    }
    // The states agree too: an impulse rings out alike.
    let mut imp = [S::splat(1.0); 4];
    for k in 0..500 {
        assert_eq!(bits(cut.tick(imp)), bits(plain.tick(imp)), "{d:?} ring {k}");
        imp = [S::splat(0.0); 4];
    }
}

#[test]
fn held_stretches_are_the_banks_ticks_bit_for_bit() {
    for (k, (fc, fs)) in [(200.0, 240e3), (2e3, 48e6), (1e3, 1e5), (3e4, 1e5)]
        .into_iter()
        .enumerate()
    {
        let d = LowPassDesign::Butterworth {
            order: 4,
            cutoff_hz: fc,
        };
        held_runs_match::<f64>(d, fs, 11 + k as u64);
        held_runs_match::<f64x4>(d, fs, 23 + k as u64);
    }
}
