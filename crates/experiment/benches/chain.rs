//! divan benchmarks of the board (`cargo bench -p gyroemu-experiment`): the whole fused chain
//! in the lanes this CPU runs it in (eight operating points per group in f64x8 lanes with
//! AVX-512, else four in f64x4; `gyroemu_board::max_lanes_for`) on one lane group and on one
//! group per core, noiseless and with every noise source, DAC and ADC on; and the rate-table
//! chain with one table shared by the group's lanes against a table per lane (the bandwidth
//! sweep's loop, `RATE_TABLE_LANES`, which `gyroemu bench` does not time). Throughput is reported in
//! point-samples (one input sample of one operating point). `gyroemu bench` prints the same
//! chain figure and each stage alone.

use divan::counter::ItemsCount;
use divan::{black_box, Bencher};
use gyroemu_board::{max_lanes_for, GroupBoard, Point, RunOptions};
use gyroemu_config::presets::preset;
use gyroemu_config::Config;
use gyroemu_lpf::Window;

/// Input samples per lane group per iteration (2^22: 41 943 decimated blocks; shorter runs
/// let the thread pool's start-up show in the per-core figure).
const N_IN: u64 = 1 << 22;

fn main() {
    divan::main();
}

fn rotating(noise: bool) -> Config {
    let c = preset("m2tfg-rotating").expect("embedded preset");
    if noise {
        gyroemu_experiment::bench::with_noise(&c)
    } else {
        c
    }
}

/// The table frequencies of a group with a table per lane, Hz: the bandwidth sweep's eight
/// lowest (`gyroemu_analysis::bandwidth::BANDWIDTH_FREQS_HZ`, written out: this crate is
/// below that one).
const LANE_TABLES_HZ: [f64; 8] = [0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5];

/// Runs `groups` lane groups of N_IN samples each of the rotating chain, one per rayon worker.
fn run_groups(b: Bencher, noise: bool, groups: usize) {
    run_groups_of(b, &rotating(noise), groups, false);
}

/// Runs `groups` lane groups of `cfg`'s chain, N_IN samples each, one per rayon worker; with
/// `table_per_lane` (a rate-table `cfg`) each lane on its own table ([`LANE_TABLES_HZ`]).
fn run_groups_of(b: Bencher, cfg: &Config, groups: usize, table_per_lane: bool) {
    let lanes = max_lanes_for(&cfg.board_params());
    let listed = &cfg.experiment.rates_dps;
    let rates: Vec<f64> = (0..lanes)
        .map(|i| listed[i % listed.len()].to_radians())
        .collect();
    let streams: Vec<u64> = (0..lanes as u64).collect();
    let m = cfg.decimation() as u64;
    let n_out = N_IN / m;
    let point = |r: f64| Point {
        rate_rad_s: r,
        window: Window::Boxcar {
            n: n_out / 2,
            frac: 0.0,
        },
    };
    let points: Vec<Point> = rates.iter().map(|&r| point(r)).collect();
    let n_settle = n_out - n_out / 2 - 1;
    b.counter(ItemsCount::new(n_out * m * (lanes * groups) as u64))
        .with_inputs(|| {
            (0..groups)
                .map(|_| {
                    let p = cfg.board_params();
                    let board = if table_per_lane {
                        let tables = &LANE_TABLES_HZ[..lanes];
                        GroupBoard::with_table_hz(&p, &rates, tables, &streams)
                    } else {
                        GroupBoard::with_width(lanes, &p, &rates, &streams)
                    }
                    .expect("valid preset");
                    // The loop this bench is named for.
                    assert_eq!(board.table_per_lane(), table_per_lane);
                    board
                })
                .collect::<Vec<_>>()
        })
        .bench_local_values(|boards| {
            use rayon::prelude::*;
            boards.into_par_iter().for_each(|mut board| {
                black_box(
                    board
                        .run(n_settle, &points, RunOptions::default(), &|_| {})
                        .ok(),
                );
            });
        });
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn chain_1_group(b: Bencher) {
    run_groups(b, false, 1);
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn chain_group_per_core(b: Bencher) {
    run_groups(b, false, rayon::current_num_threads());
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn chain_with_noise_dac_adc_1_group(b: Bencher) {
    run_groups(b, true, 1);
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn rate_table_shared_1_group(b: Bencher) {
    let cfg = preset("m2tfg-ratetable").expect("embedded preset");
    run_groups_of(b, &cfg, 1, false);
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn rate_table_per_lane_1_group(b: Bencher) {
    let cfg = preset("m2tfg-ratetable").expect("embedded preset");
    run_groups_of(b, &cfg, 1, true);
}
