//! divan benchmark of the exact normal generator (`cargo bench -p gyroemu-core`): blocks of
//! normals as the fused board reads them, four rows of four or eight lanes per input sample.
//! Throughput is in normals; at f GHz, cycles per normal are f / (normals per ns). The
//! eight-lane block takes the AVX-512 path where the CPU has it, with this CPU's table look-up
//! (`block_of_lanes`) or each look-up (`eight_lanes_by_lookup`; the same normals).

use divan::counter::ItemsCount;
use divan::Bencher;
use gyroemu_core::gauss::{Lookup, NormalBlock};
use gyroemu_core::noise::NoiseRng;

/// Input samples drawn per run (four normals per lane each).
const SAMPLES: u64 = 1 << 20;

fn main() {
    divan::main();
}

/// Draws every row of `SAMPLES` samples from `block` in the runs the board's loop takes, and
/// reads one value per run: what is timed is the generator, not the reads.
fn drain(block: &mut NormalBlock) -> f64 {
    let width = block.width();
    let mut left = SAMPLES;
    let mut acc = 0.0;
    while left > 0 {
        let run = block.ready(left);
        acc += block.row(block.pos(), width)[0];
        block.advance(run);
        left -= run;
    }
    acc
}

#[divan::bench(args = [4, 8])]
fn block_of_lanes(bencher: Bencher, lanes: usize) {
    let rng = |seed: u64| NoiseRng::new(core::array::from_fn(|l| seed + l as u64));
    let mut block = if lanes == 8 {
        NormalBlock::wide(rng(1), rng(5))
    } else {
        NormalBlock::new(rng(1))
    };
    bencher
        .counter(ItemsCount::new(SAMPLES * 4 * lanes as u64))
        .bench_local(|| drain(&mut block));
}

#[divan::bench(args = ["loads", "gather"])]
fn eight_lanes_by_lookup(bencher: Bencher, lookup: &str) {
    let rng = |seed: u64| NoiseRng::new(core::array::from_fn(|l| seed + l as u64));
    let lookup = if lookup == "gather" {
        Lookup::Gather
    } else {
        Lookup::Loads
    };
    let mut block = NormalBlock::wide(rng(1), rng(5)).with_lookup(lookup);
    bencher
        .counter(ItemsCount::new(SAMPLES * 4 * 8))
        .bench_local(|| drain(&mut block));
}
