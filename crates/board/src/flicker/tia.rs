//! The TIA's two flicker sources, drawn and run a chunk at a time.

#[cfg(target_arch = "x86_64")]
use crate::f64x8::F64x8;
use gyroemu_core::flicker::Flicker;
use gyroemu_core::{f64x4, Sample, Stage};

use super::lane_rng::LaneRng;

/// The TIA sources drawn and run ahead, up to [`TIA_CHUNK`] samples at a time and never past
/// the decimation block (the slow sources draw from the same streams at each block's start):
/// their Gaussians in one fill and the filters over the chunk ([`Flicker`]'s `process`, the
/// bits of a tick per sample), instead of a generator call and a chain of dependent
/// multiply-adds per sample.
#[derive(Clone, Debug)]
pub(super) struct TiaBlock<S> {
    /// Each four-lane stream set's next pairs (a, b): one per sample.
    pairs: [Vec<f64x4>; 2],
    /// Each source's Gaussians: source 0 takes the pair's first, source 1 its second.
    w: [Vec<S>; 2],
    /// Each source's output.
    y: [Vec<S>; 2],
    /// The two sources as one of eight lanes, on a board of four where the CPU has AVX-512.
    #[cfg(target_arch = "x86_64")]
    joined: Option<Joined>,
    /// The longest chunk: the buffers' length (the unjoined ones are empty when joined).
    cap: usize,
    /// The next sample's index in the chunk, and the chunk's length.
    pub(super) pos: usize,
    pub(super) len: usize,
    /// The decimation block's length, and how many of its samples are not yet drawn.
    pub(super) block: usize,
    pub(super) left: usize,
}

/// Both TIA sources of a four-lane board in one eight-lane source (they share their design):
/// half the multiply-adds of two four-lane ones, the same bits lane by lane
/// ([`Flicker::from_parts`]). Source 0 in lanes 0-3, source 1 in lanes 4-7.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Debug)]
struct Joined {
    f: Flicker<F64x8>,
    /// Sample k's Gaussians: the k-th pair (a, b) of the four lanes' stream set, whose a
    /// source 0 takes and b source 1, so the pair's eight values in order are the input.
    w: Vec<F64x8>,
    y: Vec<F64x8>,
}

/// Samples of TIA flicker drawn at a time: the buffers stay a few tens of kB whatever the
/// decimation (a chunk as long as a block of 10^6 samples would take hundreds of MB).
const TIA_CHUNK: usize = 256;

impl<S: Sample> TiaBlock<S> {
    /// `f`: the two sources, joined in eight lanes when the board has four and the process
    /// runs eight ([`crate::max_lanes`]; `--lanes 4` keeps four-lane code throughout).
    pub(super) fn new(block: usize, f: [&Flicker<S>; 2]) -> Self {
        let cap = block.min(TIA_CHUNK);
        #[cfg(target_arch = "x86_64")]
        let joined = (S::LANES == 4 && crate::max_lanes() == 8).then(|| Joined {
            f: Flicker::from_parts(&f),
            w: vec![F64x8::default(); cap],
            y: vec![F64x8::default(); cap],
        });
        #[cfg(target_arch = "x86_64")]
        let is_joined = joined.is_some();
        #[cfg(not(target_arch = "x86_64"))]
        let is_joined = {
            let _ = f;
            false
        };
        let own = if is_joined { 0 } else { cap };
        Self {
            pairs: [vec![f64x4::ZERO; 2 * own], vec![f64x4::ZERO; 2 * own]],
            w: [vec![S::splat(0.0); own], vec![S::splat(0.0); own]],
            y: [vec![S::splat(0.0); own], vec![S::splat(0.0); own]],
            #[cfg(target_arch = "x86_64")]
            joined,
            cap,
            pos: 0,
            len: 0,
            block,
            left: 0,
        }
    }

    /// Draws and runs the next chunk of the block (at most what is left of it).
    #[inline(never)]
    pub(super) fn refill(&mut self, rng: &mut LaneRng, f: [&mut Flicker<S>; 2]) {
        let n = self.left.min(self.cap);
        assert!(
            n > 0,
            "the kernel takes one decimation block per next_block"
        );
        self.pos = 0;
        self.len = n;
        self.left -= n;
        #[cfg(target_arch = "x86_64")]
        if let Some(j) = &mut self.joined {
            let Joined { f, w, y } = j;
            F64x8::with_target_features(
                #[inline(always)]
                || {
                    // SAFETY: an F64x8 is eight f64 (any bits valid), 64-byte aligned, so
                    // its slice is twice as many f64x4 (32-byte aligned) in the same memory.
                    let pairs: &mut [f64x4] =
                        unsafe { core::slice::from_raw_parts_mut(w.as_mut_ptr().cast(), 2 * n) };
                    rng.0[0].fill_pairs(pairs);
                    f.process(&w[..n], &mut y[..n]);
                },
            );
            return;
        }
        let [f0, f1] = f;
        let (pairs, w, y) = (&mut self.pairs, &mut self.w, &mut self.y);
        // Compiled for the lane type's instructions (eight lanes: AVX-512), as the sample
        // loop is.
        S::with_target_features(
            #[inline(always)]
            || {
                rng.pairs_into(n, pairs, w);
                f0.process(&w[0][..n], &mut y[0][..n]);
                f1.process(&w[1][..n], &mut y[1][..n]);
            },
        );
    }

    /// The sources run joined in eight lanes (see [`Joined`]).
    pub(super) fn joined(&self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            self.joined.is_some()
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            false
        }
    }

    /// The two sources' values at chunk index `i`.
    #[inline(always)]
    pub(super) fn at(&self, i: usize) -> [S; 2] {
        #[cfg(target_arch = "x86_64")]
        if let Some(j) = &self.joined {
            let v = j.y[i].as_array();
            return [S::load(&v[..4]), S::load(&v[4..])];
        }
        [self.y[0][i], self.y[1][i]]
    }
}
