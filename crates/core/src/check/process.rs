//! `process` on blocks against `tick` per sample.

use super::{Bits, Gen, SEED};
use crate::Stage;
use core::fmt::Debug;

/// The block sizes [`tick_vs_process`] feeds, in order: empty, single, odd, prime and large
/// blocks (4093 and 8191 are prime; 64 is a power of two, as internal chunkings tend to be).
pub const BLOCK_SIZES: [usize; 18] = [
    0, 1, 1, 2, 3, 0, 5, 7, 13, 1, 31, 64, 127, 0, 257, 1021, 4093, 8191,
];

/// Checks that [`Stage::process`] on the blocks of [`BLOCK_SIZES`] gives, sample for sample,
/// the bits [`Stage::tick`] gives on the same inputs, and processes exactly the common prefix
/// of its input and output: every third block gets two more inputs than outputs (the extra
/// inputs must not be consumed) and every third two more output slots than inputs (the extra
/// slots must stay untouched).
///
/// `stage` is cloned, never advanced; `input` draws one input sample from the seeded [`Gen`];
/// `view` maps an output to what is compared ([`super::same`] when the output is [`Bits`]).
/// The process run is repeated with two different fillers in the output buffer, so a slot that
/// `process` skips cannot match by chance. Panics on the first difference, naming the sample,
/// its block and both values.
pub fn tick_vs_process<T, V>(
    name: &str,
    stage: &T,
    mut input: impl FnMut(&mut Gen) -> T::Input,
    view: impl Fn(&T::Output) -> V,
) where
    T: Stage + Clone,
    V: Bits + Debug,
{
    let total: usize = BLOCK_SIZES.iter().sum();
    let mut gen = Gen::new(SEED);
    let xs: Vec<T::Input> = (0..total).map(|_| input(&mut gen)).collect();
    let mut ticked = stage.clone();
    let want: Vec<T::Output> = xs.iter().map(|&x| ticked.tick(x)).collect();
    for filler in [want[0], want[1]] {
        let mut b = stage.clone();
        let mut got = vec![filler; total];
        let mut at = 0;
        for (j, &len) in BLOCK_SIZES.iter().enumerate() {
            let (end_in, end_out) = match j % 3 {
                1 => ((at + len + 2).min(total), at + len),
                2 => (at + len, (at + len + 2).min(total)),
                _ => (at + len, at + len),
            };
            b.process(&xs[at..end_in], &mut got[at..end_out]);
            for (i, y) in got.iter().enumerate().take(end_out).skip(at + len) {
                if view(y).words() != view(&filler).words() {
                    panic!(
                        "{name}: tick_vs_process: process on a block of {len} inputs at sample \
                         {at} with {} output slots wrote slot {i} past the inputs: {:?}",
                        end_out - at,
                        view(y)
                    );
                }
            }
            at += len;
        }
        for (i, (w, g)) in want.iter().zip(&got).enumerate() {
            let (w, g) = (view(w), view(g));
            if w.words() != g.words() {
                let (j, start, len) = block_of(i);
                panic!(
                    "{name}: tick_vs_process: sample {i} (block {j}: {len} samples from {start}): \
                     tick gave {w:?}, process gave {g:?}"
                );
            }
        }
    }
}

/// `(block index, first sample, length)` of the block of [`BLOCK_SIZES`] holding sample `i`.
fn block_of(i: usize) -> (usize, usize, usize) {
    let mut start = 0;
    for (j, &len) in BLOCK_SIZES.iter().enumerate() {
        if i < start + len {
            return (j, start, len);
        }
        start += len;
    }
    (BLOCK_SIZES.len(), start, 0)
}
