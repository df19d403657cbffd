//! Throughput measurement of the emulated board: the whole chain in f64x4 lanes on one thread
//! and on all threads, and each stage alone. Used by `gyroemu bench` and the criterion-free
//! benchmark; timing lives here, never in tests.

use crate::board::{Board, Point};
use crate::config::Config;
use gyroemu_core::{f64x4, Sample, Stage};
use rayon::prelude::*;
use std::hint::black_box;
use std::time::Instant;

/// One measured figure.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Throughput {
    /// What was measured.
    pub name: String,
    /// Threads used.
    pub threads: usize,
    /// Operating-point samples per second.
    pub point_samples_per_s: f64,
}

/// Four operating points of `cfg` (its first rates, padded) for one lane group.
fn lane_rates(cfg: &Config) -> Vec<f64> {
    (0..4)
        .map(|i| cfg.experiment.rates_dps[i % cfg.experiment.rates_dps.len()].to_radians())
        .collect()
}

/// Runs `groups` lane groups of `n_in` input samples each, spread over the rayon pool;
/// returns point-samples per second.
pub fn chain(cfg: &Config, n_in: u64, groups: usize) -> f64 {
    let rates = lane_rates(cfg);
    let m = cfg.board.decimation as u64;
    let n_out = n_in / m;
    let points: Vec<Point> = rates
        .iter()
        .map(|&r| Point {
            rate_rad_s: r,
            n_avg: n_out / 2,
            window: crate::board::PointWindow::Boxcar { frac: 0.0 },
        })
        .collect();
    let n_settle = n_out - n_out / 2 - 1;
    let mut boards: Vec<Board<f64x4>> = (0..groups)
        .map(|_| Board::new(cfg, &rates).expect("bench config is valid"))
        .collect();
    let t = Instant::now();
    boards.par_iter_mut().for_each(|b| {
        black_box(b.run(n_settle, &points, None, &|_| {}).ok());
    });
    let s = t.elapsed().as_secs_f64();
    (n_out * m * 4 * groups as u64) as f64 / s
}

/// Times `n` ticks of a stage fed by `input(i)`; returns point-samples per second
/// (`lanes` operating points per tick).
fn stage<T: Stage>(mut st: T, n: u64, lanes: usize, input: impl Fn(u64) -> T::Input) -> f64 {
    let t = Instant::now();
    for i in 0..n {
        black_box(st.tick(black_box(input(i))));
    }
    (n as f64 * lanes as f64) / t.elapsed().as_secs_f64()
}

/// Every figure: the chain on 1 thread and on all threads, then each stage on 1 thread.
pub fn all(cfg: &Config, n_in: u64) -> Vec<Throughput> {
    use crate::board::{resonator_params, tia_params};
    use gyroemu_am::{AmInput, AmModulator, DrivePattern};
    use gyroemu_lpf::{LowPass, LowPassDesign};
    use gyroemu_mixer::{Iq, Stage1Mixer, Stage2Mixer};
    use gyroemu_nco::{Nco, PhaseShifter, RotatingNco};
    use gyroemu_resonator::Resonator;
    use gyroemu_tia::Tia;
    let threads = rayon::current_num_threads();
    let mut out = vec![Throughput {
        name: "whole chain".into(),
        threads: 1,
        point_samples_per_s: chain(cfg, n_in, 1),
    }];
    if threads > 1 {
        out.push(Throughput {
            name: "whole chain".into(),
            threads,
            point_samples_per_s: chain(cfg, n_in, threads),
        });
    }
    let x = |i: u64| f64x4::splat((i & 1023) as f64 * 1e-3);
    let fs = cfg.board.fs_hz;
    let mut push = |name: &str, v: f64| {
        out.push(Throughput {
            name: name.into(),
            threads: 1,
            point_samples_per_s: v,
        })
    };
    let nco = Nco::new(cfg.device.f0_hz, fs, 0.0).expect("valid");
    let carrier = RotatingNco::<f64>::new(std::slice::from_ref(&nco));
    push(
        "carrier RotatingNco (scalar, 4 lanes share it)",
        stage(carrier, n_in, 4, |_| ()),
    );
    let mods: Vec<Nco> = lane_rates(cfg)
        .iter()
        .map(|r| Nco::new(r / std::f64::consts::TAU, fs, 0.0).expect("valid"))
        .collect();
    push(
        "modulation RotatingNco (f64x4)",
        stage(RotatingNco::<f64x4>::new(&mods), n_in, 4, |_| ()),
    );
    push(
        "table Nco (exact re-sets only)",
        stage(nco, n_in, 4, |_| ()),
    );
    let c = |i: u64| gyroemu_core::Complex64::new(x(i).lane(0), 0.5);
    push(
        "phase shifter (scalar)",
        stage(PhaseShifter::quadrature(), n_in, 4, c),
    );
    let am = AmModulator::<f64x4>::new(DrivePattern::Rotating, 1.0, 1.0).expect("valid");
    push(
        "am modulator",
        stage(am, n_in, 4, |i| AmInput {
            carrier_i: x(i),
            carrier_q: x(i + 1),
            mod_cos: x(i + 2),
            mod_sin: x(i + 3),
        }),
    );
    let scalar: Vec<Resonator<f64>> = lane_rates(cfg)
        .iter()
        .map(|&r| Resonator::new(&resonator_params(cfg), r).expect("valid"))
        .collect();
    let plant = Resonator::<f64x4>::from_lanes(&scalar);
    push("resonator", stage(plant, n_in, 4, |i| [x(i), x(i + 7)]));
    let tia = Tia::<f64x4>::new(&tia_params(cfg)).expect("valid");
    push("tia", stage(tia, n_in, 4, x));
    let mix = Stage1Mixer::<f64x4>::new(0.0).expect("valid");
    let c = gyroemu_core::Complex64::new(0.6, 0.8);
    push("stage-1 mixer", stage(mix, n_in, 4, |i| (x(i), c)));
    let design = LowPassDesign::Butterworth {
        order: cfg.board.lpf_order,
        cutoff_hz: cfg.board.lpf_cutoff_hz,
    };
    let lp = LowPass::<f64x4>::new(design, fs).expect("valid");
    push("low-pass (one channel)", stage(lp, n_in, 4, x));
    let s2 = Stage2Mixer::<f64x4>::default();
    push(
        "stage-2 mixer (per decimated sample)",
        stage(s2, n_in, 4, |i| {
            (Iq::new(x(i), x(i + 1)), [x(i + 2), x(i + 3)])
        }),
    );
    out
}
