//! LowPass invariants: block processing equals ticking, reset reproduces, lanes equal scalar,
//! a bank of channels equals one filter per channel.

mod common;

use gyroemu_core::Response;
use gyroemu_core::{f64x4, Sample, Stage};
use gyroemu_lpf::{LowPass, LowPassBank, LowPassDesign};

fn designs() -> Vec<LowPassDesign> {
    let mut d: Vec<LowPassDesign> = (1..=8)
        .map(|order| LowPassDesign::Butterworth {
            order,
            cutoff_hz: 1.7e3,
        })
        .collect();
    d.extend((1..=8).map(|order| LowPassDesign::LockIn { order, tau_s: 3e-4 }));
    d
}

#[test]
fn process_on_random_chunkings_equals_tick_and_reset_reproduces() {
    let x = common::noise(8000, 2.0, 1);
    for (i, design) in designs().into_iter().enumerate() {
        let mut lp = LowPass::<f64>::new(design, 1e5).unwrap();
        let reference: Vec<f64> = x.iter().map(|&v| lp.tick(v)).collect();
        lp.reset();
        let mut out = vec![0.0; x.len()];
        let mut at = 0;
        for len in common::chunks(x.len(), 300, i as u64) {
            lp.process(&x[at..at + len], &mut out[at..at + len]);
            at += len;
        }
        assert!(
            out.iter()
                .zip(&reference)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{design:?}"
        );
    }
}

#[test]
fn f64x4_lanes_equal_scalar_bit_for_bit() {
    let xs: Vec<Vec<f64>> = (0..4)
        .map(|l| common::noise(4000, 1.0 + l as f64, 10 + l as u64))
        .collect();
    for design in designs() {
        let mut v = LowPass::<f64x4>::new(design, 1e5).unwrap();
        let out: Vec<f64x4> = (0..4000)
            .map(|i| v.tick(f64x4::from_fn(|l| xs[l][i])))
            .collect();
        for (l, x) in xs.iter().enumerate() {
            let mut s = LowPass::<f64>::new(design, 1e5).unwrap();
            for (i, &xi) in x.iter().enumerate() {
                assert_eq!(
                    s.tick(xi).to_bits(),
                    out[i].lane(l).to_bits(),
                    "{design:?} lane {l} at {i}"
                );
            }
        }
    }
}

#[test]
fn bank_channels_equal_one_filter_each_bit_for_bit_and_reset_reproduces() {
    let xs: Vec<Vec<f64>> = (0..3)
        .map(|c| common::noise(3000, 1.0 + c as f64, 40 + c as u64))
        .collect();
    for design in designs() {
        let proto = LowPass::<f64x4>::new(design, 1e5).unwrap();
        let mut bank = LowPassBank::<f64x4, 3>::new(&proto);
        let input = |i: usize| -> [f64x4; 3] {
            core::array::from_fn(|c| f64x4::from_fn(|l| xs[c][i] * (l + 1) as f64))
        };
        let out: Vec<[f64x4; 3]> = (0..3000).map(|i| bank.tick(input(i))).collect();
        for c in 0..3 {
            let mut one = proto.clone();
            for (i, o) in out.iter().enumerate() {
                let want = one.tick(input(i)[c]).to_array().map(f64::to_bits);
                assert_eq!(
                    o[c].to_array().map(f64::to_bits),
                    want,
                    "{design:?} ch {c} at {i}"
                );
            }
        }
        bank.reset();
        assert_eq!(bank.tick(input(0))[2].to_array(), out[0][2].to_array());
        assert_eq!(bank.response(900.0), proto.response(900.0));
        assert_eq!(bank.latency_samples(), proto.latency_samples());
    }
}

proptest::proptest! {
    /// Linearity by an exact power of two holds bit for bit in any cascade of linear sections.
    #[test]
    fn homogeneous_by_powers_of_two(order in 1usize..=8, fc in 1.0f64..4.9e4, lockin in proptest::bool::ANY) {
        let design = if lockin {
            LowPassDesign::LockIn { order, tau_s: 1.0 / fc }
        } else {
            LowPassDesign::Butterworth { order, cutoff_hz: fc }
        };
        let mut a = LowPass::<f64>::new(design, 1e5).unwrap();
        let mut b = LowPass::<f64>::new(design, 1e5).unwrap();
        for v in common::noise(300, 2.0, 5) {
            proptest::prop_assert_eq!((a.tick(v) * 8.0).to_bits(), b.tick(v * 8.0).to_bits());
        }
    }
}
