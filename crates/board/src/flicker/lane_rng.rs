//! The flicker sources' Gaussian streams.

use crate::seeding::lane_set_rng;
use gyroemu_core::noise::NoiseRng;
use gyroemu_core::{f64x4, Sample};

use super::SLOW;

/// The flicker streams of up to eight lanes, in four-lane sets as the white noise's
/// ([`lane_set_rng`]), so a point draws the same normals in a group of four or of eight.
#[derive(Clone, Debug)]
pub(super) struct LaneRng(pub(super) [NoiseRng; 2]);

impl LaneRng {
    /// Lane `i` on stream `streams[i]` (lanes past the end repeat the last).
    pub(super) fn new(seed: u64, streams: &[u64]) -> Self {
        Self([
            lane_set_rng(seed, streams, 0),
            lane_set_rng(seed, streams, 1),
        ])
    }

    /// The next pair of standard normals in every lane of `S` (the second generator only
    /// draws for lane types wider than four).
    #[inline(always)]
    pub(super) fn pair<S: Sample>(&mut self) -> (S, S) {
        let (a0, b0) = self.0[0].normal_pair();
        if S::LANES <= 4 {
            return (lanes(a0, a0), lanes(b0, b0));
        }
        let (a1, b1) = self.0[1].normal_pair();
        (lanes(a0, a1), lanes(b0, b1))
    }

    /// `w[k]` = the first of the k-th call of [`LaneRng::pair`] for every k (the same bits:
    /// each stream set's pairs in one fill, their second normals left unused as `pair`'s
    /// callers leave them).
    #[inline(always)]
    pub(super) fn firsts_into<S: Sample>(&mut self, w: &mut [S]) {
        let mut pairs = [[f64x4::ZERO; 2 * SLOW]; 2];
        let n = w.len();
        assert!(n <= SLOW, "at most {SLOW} slow sources");
        if n == 0 {
            return;
        }
        let sets = if S::LANES <= 4 { 1 } else { 2 };
        for (rng, p) in self.0.iter_mut().zip(pairs.iter_mut()).take(sets) {
            rng.fill_pairs(&mut p[..2 * n]);
        }
        let [lo, hi] = &pairs;
        for (k, wk) in w.iter_mut().enumerate() {
            *wk = lanes(lo[2 * k], hi[2 * k]);
        }
    }

    /// `w[0][k], w[1][k]` = the k-th call of [`LaneRng::pair`] for every k < `n` (the same
    /// bits), drawn through `pairs` (each stream set's pairs) in one fill per set.
    #[inline(always)]
    pub(super) fn pairs_into<S: Sample>(
        &mut self,
        n: usize,
        pairs: &mut [Vec<f64x4>; 2],
        w: &mut [Vec<S>; 2],
    ) {
        let sets = if S::LANES <= 4 { 1 } else { 2 };
        for (rng, p) in self.0.iter_mut().zip(pairs.iter_mut()).take(sets) {
            rng.fill_pairs(&mut p[..2 * n]);
        }
        let [lo, hi] = pairs;
        for k in 0..n {
            for (c, wc) in w.iter_mut().enumerate() {
                wc[k] = lanes(lo[2 * k + c], hi[2 * k + c]);
            }
        }
    }
}

/// The lanes of `S` from the four-lane sets `lo` (lanes 0-3) and `hi` (lanes 4-7, read only
/// by lane types wider than four).
#[inline(always)]
fn lanes<S: Sample>(lo: f64x4, hi: f64x4) -> S {
    let mut v = [0.0; 8];
    v[..4].copy_from_slice(&lo.to_array());
    v[4..].copy_from_slice(&hi.to_array());
    S::load(&v[..S::LANES])
}
