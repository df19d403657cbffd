//! Decimation: output phase, response referred to the output instant, `process_block` (the
//! Stage contract, lanes included, is checked by the shared harness in tests/contract.rs).

mod common;

use gyroemu_core::{Complex64, Response, Stage};
use gyroemu_lpf::{DecimateMode, Decimator, LowPassDesign};
use std::f64::consts::TAU;

const FS: f64 = 1e5;

fn modes() -> [DecimateMode; 3] {
    let bw = LowPassDesign::Butterworth {
        order: 5,
        cutoff_hz: 2e3,
    };
    [
        DecimateMode::Filter(bw),
        DecimateMode::IntegrateDump,
        DecimateMode::FilterThenDump(bw),
    ]
}

#[test]
fn integrate_dump_output_k_is_the_mean_of_inputs_km_to_km_plus_m_minus_1() {
    for m in [1usize, 2, 5, 16] {
        let mut d = Decimator::<f64>::new(DecimateMode::IntegrateDump, m, FS).unwrap();
        assert_eq!(d.factor(), m);
        assert_eq!(d.fs_out_hz(), FS / m as f64);
        let mut k = 0;
        for n in 0..10 * m {
            // ramp: the block mean is kM + (M-1)/2 exactly (small integers and halves)
            match d.tick(n as f64) {
                None => assert_ne!(n % m, m - 1),
                Some(y) => {
                    assert_eq!(
                        n,
                        k * m + m - 1,
                        "output {k} must come on input {}",
                        k * m + m - 1
                    );
                    assert_eq!(y, (k * m) as f64 + 0.5 * (m - 1) as f64);
                    k += 1;
                }
            }
        }
        assert_eq!(k, 10);
        // latency (M-1)/2: the ramp output lags the output instant by exactly that
        assert_eq!(d.latency_samples(), 0.5 * (m - 1) as f64);
        // an impulse at input j lands in output floor(j/M) only
        for j in 0..3 * m {
            d.reset();
            let outs: Vec<f64> = (0..3 * m)
                .filter_map(|n| d.tick(if n == j { 1.0 } else { 0.0 }))
                .collect();
            for (k, y) in outs.iter().enumerate() {
                let want = if k == j / m { 1.0 / m as f64 } else { 0.0 };
                assert!((y - want).abs() < 1e-16, "M={m} j={j} k={k}");
            }
        }
    }
}

#[test]
fn filter_output_k_is_the_filter_output_at_input_km_plus_m_minus_1() {
    // One RC stage: impulse response (1-a) a^n (closed form), sampled at n = kM + M - 1 - j.
    let tau = 2e-4;
    let a = (-1.0 / (FS * tau)).exp();
    let design = LowPassDesign::LockIn {
        order: 1,
        tau_s: tau,
    };
    for m in [1usize, 3, 8] {
        for j in [0usize, 1, m.saturating_sub(1), m, 2 * m + 1] {
            let mut d = Decimator::<f64>::new(DecimateMode::Filter(design), m, FS).unwrap();
            let outs: Vec<f64> = (0..20 * m)
                .filter_map(|n| d.tick(if n == j { 1.0 } else { 0.0 }))
                .collect();
            assert_eq!(outs.len(), 20);
            for (k, y) in outs.iter().enumerate() {
                let n = k * m + m - 1;
                let want = if n >= j {
                    (1.0 - a) * a.powi((n - j) as i32)
                } else {
                    0.0
                };
                assert!((y - want).abs() < 1e-15, "M={m} j={j} k={k}: {y} vs {want}");
            }
        }
    }
}

#[test]
fn sinusoid_output_equals_response_referred_to_the_output_instant() {
    let m = 10;
    for mode in modes() {
        for f in [37.0, 480.0, 2.5e3, 9.1e3, 12.3e3] {
            let mut d = Decimator::<f64>::new(mode, m, FS).unwrap();
            let h = d.response(f);
            let mut worst: f64 = 0.0;
            // f and n are integers: (f n) mod fs is exact, so the phase carries no rounding
            let turns = |n: usize| (f * n as f64) % FS / FS;
            for n in 0..40_000usize {
                let x = gyroemu_core::detmath::sin_cos_turns(turns(n)).1;
                if let Some(y) = d.tick(x) {
                    if n > 20_000 {
                        let want = (h * Complex64::from_polar(1.0, TAU * turns(n))).re;
                        worst = worst.max((y - want).abs());
                    }
                }
            }
            eprintln!("decimator {mode:?} f={f}: worst |y - Re(H e^jwn)| = {worst:e}");
            assert!(worst < 1e-13, "{mode:?} f={f}: worst {worst:e}");
        }
    }
    // the dump's nulls: integrate-and-dump rejects k fs/M
    let d = Decimator::<f64>::new(DecimateMode::IntegrateDump, m, FS).unwrap();
    assert!(
        d.response(FS / m as f64).norm() < 1e-15 && d.response(3.0 * FS / m as f64).norm() < 1e-15
    );
    assert_eq!(d.response(0.0), Complex64::new(1.0, 0.0));
}

#[test]
fn process_block_on_random_chunkings_equals_tick_and_reset_reproduces() {
    let x = common::noise(20_000, 2.0, 21);
    for mode in modes() {
        for m in [1usize, 7, 64] {
            let mut d = Decimator::<f64>::new(mode, m, FS).unwrap();
            let reference: Vec<f64> = x.iter().filter_map(|&v| d.tick(v)).collect();
            assert_eq!(reference.len(), x.len() / m);
            for seed in 0..3 {
                d.reset();
                let mut out = vec![0.0; reference.len()];
                let (mut i, mut k) = (0, 0);
                for len in common::chunks(x.len(), 200, seed) {
                    assert_eq!(d.outputs_for(len), (i % m + len) / m);
                    k += d.process_block(&x[i..i + len], &mut out[k..]);
                    i += len;
                }
                assert_eq!(k, reference.len());
                assert!(
                    out.iter()
                        .zip(&reference)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "{mode:?} M={m}"
                );
            }
        }
    }
}

/// A generic caller's tick: the `Stage` trait's, not the inherent method.
fn stage_tick<T: Stage<Input = f64, Output = Option<f64>>>(s: &mut T, x: f64) -> Option<f64> {
    s.tick(x)
}

#[test]
fn the_stage_trait_ticks_as_the_decimator_does() {
    // Generic code (the contract harness, the board) reaches the decimator through `Stage`:
    // the same outputs at the same instants as the inherent `tick`, mean of M for the dump.
    for mode in modes() {
        for m in [1usize, 3, 8] {
            let mut direct = Decimator::<f64>::new(mode, m, FS).unwrap();
            let mut generic = direct.clone();
            let mut outputs = 0;
            for n in 0..400 {
                let x = (0.37 * n as f64).sin() + 0.25;
                let (a, b) = (direct.tick(x), stage_tick(&mut generic, x));
                assert_eq!(
                    a.map(f64::to_bits),
                    b.map(f64::to_bits),
                    "{mode:?} M {m} n {n}"
                );
                assert_eq!(b.is_some(), (n + 1) % m == 0, "{mode:?} M {m} n {n}");
                outputs += usize::from(b.is_some());
            }
            assert_eq!(outputs, 400 / m);
        }
    }
}
