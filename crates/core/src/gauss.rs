//! Exact standard normals in the lanes: the ziggurat of Marsaglia and Tsang (2000), with 2048
//! layers, and the layer, the sign and the uniform taken from separate bits of one 64-bit draw
//! (Doornik 2005), on each lane's own xoshiro256++ streams (`noise`).
//!
//! The density's 2048 pieces of equal area (`gauss_tables`, computed at 80 digits by
//! `scripts/gauss_tables.py`) are the base (the rectangle under f(r) plus the tail beyond r)
//! and 2047 rectangles stacked on it. A draw picks a piece and a uniform point across it; in
//! 99.77 % of draws the point lies in the piece's core, under the curve by construction, and
//! is returned: that path runs four lanes at once (eight with AVX-512, `gauss_avx512`) with
//! no branch per lane. The rest (a point in a wedge between a rectangle's core and the curve,
//! or in the base beyond r) goes lane by lane through the exact test, drawing further values
//! from that lane's stream only. So each stream's sequence is the scalar ziggurat on it,
//! whatever the neighbouring lanes do: a point's noise is the same in every lane, group,
//! shard and thread count, and in a scalar run.
//!
//! Pure IEEE arithmetic with one rounding per operation throughout (the rare wedge `exp` and
//! tail `ln` are `wide`'s polynomials), so the same bits on every run.

use crate::gauss_scalar::{lane_normal, ONE_BITS, SIGN_BIT, SIGN_SHIFT};
use crate::gauss_tables::{FAST, N};
use crate::noise::{step, NoiseRng};
use wide::bytemuck::cast;
use wide::{f64x4, u64x4};

/// The fast path of four draws: each lane's candidate normal, and the bit mask of the lanes
/// whose point lay in its piece's core (those candidates are final).
#[inline(always)]
fn candidates(w: u64x4) -> (f64x4, u32) {
    let piece = w.to_array().map(|w| &FAST.0[w as usize & (N - 1)]);
    let width = f64x4::new(piece.map(|p| p[0]));
    let bound = f64x4::new(piece.map(|p| p[1]));
    let b: f64x4 = cast((w >> 12u32) | u64x4::splat(ONE_BITS));
    let sign: f64x4 = cast((w & u64x4::splat(SIGN_BIT)) << SIGN_SHIFT);
    // (b - 1) is exact; x >= 0, so or-ing the sign bit in negates it.
    let x = ((b - f64x4::ONE) * width) | sign;
    (x, b.simd_lt(bound).to_bitmask())
}

/// The next normal of every lane from the four lanes' stream states `s`.
#[inline(always)]
fn next_normal(s: &mut [u64x4; 4]) -> f64x4 {
    let w = step(s);
    let (x, core) = candidates(w);
    if core == 0xF {
        x
    } else {
        let (st, x) = rare(*s, w, x, core);
        *s = st;
        x
    }
}

/// The lanes whose draw `w` missed its piece's core (bit `l` of `core` clear) finish one by
/// one, each on its own stream (so their order does not matter). The state goes in and out
/// by value: the caller's copy stays in registers on the common path.
#[cold]
#[inline(never)]
fn rare(mut st: [u64x4; 4], w: u64x4, x: f64x4, core: u32) -> ([u64x4; 4], f64x4) {
    let w = w.to_array();
    let mut out = x.to_array();
    let mut pending = !core & 0xF;
    while pending != 0 {
        let l = pending.trailing_zeros() as usize;
        pending &= pending - 1;
        out[l] = lane_normal(&mut || lane_draw(&mut st, l), w[l]);
    }
    (st, f64x4::new(out))
}

/// The next draw of lane `lane` alone: all four lanes step, only that lane keeps its step.
#[inline(always)]
fn lane_draw(s: &mut [u64x4; 4], lane: usize) -> u64 {
    let mut t = *s;
    let w = step(&mut t);
    let keep = u64x4::new(core::array::from_fn(
        |l| if l == lane { u64::MAX } else { 0 },
    ));
    for (si, ti) in s.iter_mut().zip(t) {
        *si = keep.select(ti, *si);
    }
    w.as_array()[lane]
}

/// How the AVX-512F fast path fetches its eight table entries: the same entries, so the same
/// bits, either way; a speed choice ([`Lookup::this_cpu`]). Without AVX-512F it is ignored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lookup {
    /// Eight 128-bit loads, assembled by shuffles.
    Loads,
    /// Two 512-bit gathers (widths, then bounds).
    Gather,
}

impl Lookup {
    /// The faster on this CPU: gathers on an Intel core with AVX512-FP16 (Sapphire Rapids and
    /// later), else loads (`gauss_avx512::gathers_fast` gives the measurements).
    pub fn this_cpu() -> Self {
        #[cfg(target_arch = "x86_64")]
        if crate::gauss_avx512::gathers_fast() {
            return Self::Gather;
        }
        Self::Loads
    }
}

/// The generator's fast path on this CPU, as [`fill_one`] and [`fill_two`] choose it, for a
/// benchmark's header: AVX-512F with its table look-up ([`Lookup::this_cpu`]), or without.
pub fn fast_path() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    if crate::gauss_avx512::available() {
        return match Lookup::this_cpu() {
            Lookup::Gather => "AVX-512F, its table look-up by two 512-bit gathers",
            Lookup::Loads => "AVX-512F, its table look-up by 128-bit loads",
        };
    }
    "no AVX-512F, four lanes at a time"
}

/// Fills `out` (of even length) with the next normals of stream a and stream b of four
/// lanes in turn, with AVX-512F when the CPU has it (the same bits).
#[inline]
pub(crate) fn fill_one(s: &mut [[u64x4; 4]; 2], out: &mut [f64x4], lookup: Lookup) {
    assert!(out.len().is_multiple_of(2), "normals come in pairs");
    #[cfg(target_arch = "x86_64")]
    if crate::gauss_avx512::available() {
        // SAFETY: the CPU has AVX-512F (checked just above).
        unsafe { crate::gauss_avx512::fill_one(s, out, lookup == Lookup::Gather) };
        return;
    }
    fill_one_portable(s, out);
}

/// [`fill_one`] without AVX-512: stream a, then stream b, four lanes at a time.
pub(crate) fn fill_one_portable(s: &mut [[u64x4; 4]; 2], out: &mut [f64x4]) {
    let [mut a, mut b] = *s;
    for pair in out.chunks_exact_mut(2) {
        pair[0] = next_normal(&mut a);
        pair[1] = next_normal(&mut b);
    }
    *s = [a, b];
}

/// Fills `out` (a multiple of four long) with the next normals of the four-lane stream sets
/// `s[0][0], s[0][1], s[1][0], s[1][1]` in turn (stream a of lanes 0-3 and 4-7, then stream
/// b of lanes 0-3 and 4-7: rows of eight lanes), with AVX-512F when the CPU has it.
#[inline]
pub(crate) fn fill_two(s: &mut [[[u64x4; 4]; 2]; 2], out: &mut [f64x4], lookup: Lookup) {
    assert!(out.len().is_multiple_of(4), "whole rows of eight lanes");
    #[cfg(target_arch = "x86_64")]
    if crate::gauss_avx512::available() {
        // SAFETY: the CPU has AVX-512F (checked just above).
        unsafe { crate::gauss_avx512::fill_two(s, out, lookup == Lookup::Gather) };
        return;
    }
    fill_two_portable(s, out);
}

/// [`fill_two`] without AVX-512.
pub(crate) fn fill_two_portable(s: &mut [[[u64x4; 4]; 2]; 2], out: &mut [f64x4]) {
    let [[mut a0, mut a1], [mut b0, mut b1]] = *s;
    for round in out.chunks_exact_mut(4) {
        round[0] = next_normal(&mut a0);
        round[1] = next_normal(&mut a1);
        round[2] = next_normal(&mut b0);
        round[3] = next_normal(&mut b1);
    }
    *s = [[a0, a1], [b0, b1]];
}

impl NoiseRng {
    /// The next standard normal of each lane's stream a and of its stream b.
    #[inline]
    pub fn normal_pair(&mut self) -> (f64x4, f64x4) {
        let mut out = [f64x4::ZERO; 2];
        self.fill_pairs(&mut out);
        (out[0], out[1])
    }

    /// Fills `out` (of even length) with the next pairs: `out[2k]` and `out[2k + 1]` are what
    /// the k-th call of [`NoiseRng::normal_pair`] gives (the same bits).
    pub fn fill_pairs(&mut self, out: &mut [f64x4]) {
        fill_one(&mut self.s, out, Lookup::this_cpu());
    }
}

/// Normals drawn ahead in blocks, for a loop that takes four per sample, of four lanes (one
/// [`NoiseRng`]) or eight (two): row `k` holds every lane's `k`-th normal, which alternate
/// between the lane's stream a and stream b as [`NoiseRng::normal_pair`] gives them. A lane's
/// rows are the same in a block of four lanes and of eight.
#[derive(Clone, Debug)]
pub struct NormalBlock {
    /// The four-lane stream sets, paired as one AVX-512 register fills them (each pair one
    /// row of eight lanes, or two rows of four): one [`NoiseRng`]: its (a, b); two: (a of
    /// lanes 0-3, a of lanes 4-7), then (b of lanes 0-3, b of lanes 4-7).
    s: [[[u64x4; 4]; 2]; 2],
    /// Lanes per row: 4 or 8.
    width: usize,
    /// How the AVX-512F fill looks its table up.
    lookup: Lookup,
    buf: Box<Rows>,
    /// The next unread row (`LEN`: all read).
    pos: usize,
}

/// The rows of a [`NormalBlock`], `LEN` rows of up to eight lanes, as chunks of four lanes;
/// aligned so that a row of eight is one cache line.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
struct Rows([f64x4; 2 * NormalBlock::LEN]);

impl NormalBlock {
    /// Rows (normals per lane) drawn at a time: 64 samples of four (a power of two).
    pub const LEN: usize = 256;

    /// Four lanes' normals from `rng`'s streams, from their current state on.
    pub fn new(rng: NoiseRng) -> Self {
        Self::with_sets([rng.s, [[u64x4::ZERO; 4]; 2]], 4)
    }

    /// Eight lanes' normals: lanes 0-3 from `lo`'s streams, lanes 4-7 from `hi`'s.
    pub fn wide(lo: NoiseRng, hi: NoiseRng) -> Self {
        let [la, lb] = lo.s;
        let [ha, hb] = hi.s;
        Self::with_sets([[la, ha], [lb, hb]], 8)
    }

    fn with_sets(s: [[[u64x4; 4]; 2]; 2], width: usize) -> Self {
        Self {
            s,
            width,
            lookup: Lookup::this_cpu(),
            buf: Box::new(Rows([f64x4::ZERO; 2 * Self::LEN])),
            pos: Self::LEN,
        }
    }

    /// Lanes per row (4 or 8).
    pub fn width(&self) -> usize {
        self.width
    }

    /// The block with its further draws looked up by `lookup` in place of this CPU's choice
    /// ([`Lookup::this_cpu`]): the same normals, for benchmarks and tests.
    pub fn with_lookup(mut self, lookup: Lookup) -> Self {
        self.lookup = lookup;
        self
    }

    /// Makes the normals of up to `samples` samples (four rows each) ready, drawing more if
    /// none are left, and returns how many samples they cover (at least one): a loop can then
    /// read them with [`NormalBlock::row`] from [`NormalBlock::pos`] on, without a call per
    /// sample, and [`NormalBlock::advance`] past them.
    #[inline(always)]
    pub fn ready(&mut self, samples: u64) -> u64 {
        if self.pos == Self::LEN {
            self.refill();
        }
        samples.min(((Self::LEN - self.pos) / 4) as u64)
    }

    /// The index of the next unread row.
    #[inline(always)]
    pub fn pos(&self) -> usize {
        self.pos
    }

    /// Row `r` (below `LEN`) of a block of `width` lanes ([`NormalBlock::width`], passed by a
    /// caller that knows it at compile time): lane `l`'s normal at index `l`.
    #[inline(always)]
    pub fn row(&self, r: usize, width: usize) -> &[f64] {
        debug_assert_eq!(width, self.width);
        let flat: &[f64; 8 * Self::LEN] = wide::bytemuck::cast_ref(&self.buf.0);
        let i = (r & (Self::LEN - 1)) * width;
        &flat[i..i + width]
    }

    /// Marks `samples` samples' rows (four each) as read.
    #[inline(always)]
    pub fn advance(&mut self, samples: u64) {
        self.pos += 4 * samples as usize;
    }

    #[inline(never)]
    fn refill(&mut self) {
        let rows = &mut self.buf.0[..Self::LEN * self.width / 4];
        if self.width == 8 {
            fill_two(&mut self.s, rows, self.lookup);
        } else {
            fill_one(&mut self.s[0], rows, self.lookup);
        }
        self.pos = 0;
    }
}

#[cfg(test)]
#[path = "gauss_tests.rs"]
mod tests;
