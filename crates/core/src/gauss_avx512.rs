//! The fast path of `gauss` with AVX-512F, chosen at run time (the build targets x86-64-v3):
//! one 512-bit register holds two sets of four streams (stream a and stream b of four lanes,
//! or stream a of eight lanes), so each step, table look-up and test serves eight normals.
//! The operations are the portable path's (integer steps, the same table entries, one exact
//! subtraction and one rounded product per normal, exact comparisons), and draws that miss
//! their piece's core finish in the portable code's scalar ziggurat, each lane's further
//! draws stepped in the register, so the bits are the same on either path (tested).
//!
//! The eight pieces' table entries come in one of two ways (`gauss::Lookup`; `gather` here),
//! the same entries either way: eight 128-bit loads assembled by shuffles, or two 512-bit
//! gathers where the CPU runs gathers fast.

use crate::gauss_scalar::{lane_normal, ONE_BITS, SIGN_BIT, SIGN_SHIFT};
use crate::gauss_tables::{FAST, N};
use core::arch::x86_64::*;
use wide::{f64x4, u64x4};

/// The CPU runs AVX-512F (the answer is cached by `std`).
#[inline]
pub(crate) fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
}

/// Gathers are the faster look-up on this CPU: an Intel core with AVX512-FP16 (Sapphire
/// Rapids and later). Measured on a Sapphire Rapids-class Xeon, eight-lane blocks: 1.85
/// against 1.57 G normals/s (docs/performance.md, thirty-second session); on an Emerald
/// Rapids-class one, 1.34 against 1.21 (forty-third). Elsewhere the loads:
/// on AMD Zen 4 and Zen 5 a 512-bit gather measured 1.65 to 2.2 times slower, and Intel's
/// earlier AVX-512 cores (Skylake-SP to Ice Lake) run gathers under the microcode mitigation
/// of Gather Data Sampling, which slows them severalfold; FP16 arrived after them.
pub(crate) fn gathers_fast() -> bool {
    static FAST: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *FAST.get_or_init(|| {
        // Leaf 0 exists on every x86-64 CPU: "GenuineIntel" in EBX, EDX, ECX.
        let v = core::arch::x86_64::__cpuid(0);
        let intel = (v.ebx, v.edx, v.ecx) == (0x756e_6547, 0x4965_6e69, 0x6c65_746e);
        available() && intel && std::arch::is_x86_feature_detected!("avx512fp16")
    })
}

/// Stream a of the four lanes in the low half, stream b in the high half.
#[inline]
#[target_feature(enable = "avx512f")]
fn join(a: u64x4, b: u64x4) -> __m512i {
    let a: __m256i = wide::bytemuck::cast(a);
    let b: __m256i = wide::bytemuck::cast(b);
    _mm512_inserti64x4::<1>(_mm512_castsi256_si512(a), b)
}

/// The two halves of [`join`].
#[inline]
#[target_feature(enable = "avx512f")]
fn halves(v: __m512i) -> [u64x4; 2] {
    [
        wide::bytemuck::cast(_mm512_castsi512_si256(v)),
        wide::bytemuck::cast(_mm512_extracti64x4_epi64::<1>(v)),
    ]
}

// A piece's byte offset in the table fits the 16-bit words [`draw`] moves it in.
const _: () = assert!(16 * N <= 1 << 16);

/// [`FAST`] as two tables, widths and bounds, for the gathers (a gather's scale is at most
/// 8 bytes, so the index is the piece itself). Built from `FAST` at compile time: the same
/// entries.
#[repr(C, align(64))]
struct Split([f64; N], [f64; N]);

static SPLIT: Split = {
    let (mut width, mut bound) = ([0.0; N], [0.0; N]);
    let mut i = 0;
    while i < N {
        [width[i], bound[i]] = FAST.0[i];
        i += 1;
    }
    Split(width, bound)
};

/// The constants of [`draw`].
#[derive(Clone, Copy)]
struct Consts {
    index: __m512i,
    one: __m512i,
    sign_bit: __m512i,
}

impl Consts {
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn new() -> Self {
        Self {
            index: _mm512_set1_epi64(N as i64 - 1),
            one: _mm512_set1_epi64(ONE_BITS as i64),
            sign_bit: _mm512_set1_epi64(SIGN_BIT as i64),
        }
    }
}

/// xoshiro256++ of all eight streams (`crate::noise::step`): their draws and new state.
#[inline]
#[target_feature(enable = "avx512f")]
fn step(st: [__m512i; 4]) -> (__m512i, [__m512i; 4]) {
    let [mut s0, mut s1, mut s2, mut s3] = st;
    let w = _mm512_add_epi64(_mm512_rol_epi64::<23>(_mm512_add_epi64(s0, s3)), s0);
    let t = _mm512_slli_epi64::<17>(s1);
    s2 = _mm512_xor_si512(s2, s0);
    s3 = _mm512_xor_si512(s3, s1);
    s1 = _mm512_xor_si512(s1, s2);
    s0 = _mm512_xor_si512(s0, s3);
    s2 = _mm512_xor_si512(s2, t);
    s3 = _mm512_rol_epi64::<45>(s3);
    (w, [s0, s1, s2, s3])
}

/// The eight pieces' widths and bounds of draws `w` by loads: each entry's 16 bytes, then
/// shuffles into two registers.
#[inline]
#[target_feature(enable = "avx512f")]
fn pieces(w: __m512i, k: Consts) -> (__m512d, __m512d) {
    // Each stream's piece: the byte offset of its [width, bound] pair, as eight 16-bit words
    // in one register, then in two general registers. A store and eight reloads instead
    // (the look-ups then wait on store-to-load forwarding) gave 7 % fewer normals per second.
    let off = _mm512_cvtepi64_epi16(_mm512_slli_epi64::<4>(_mm512_and_si512(w, k.index)));
    let words = [
        _mm_cvtsi128_si64(off) as u64,
        _mm_extract_epi64::<1>(off) as u64,
    ];
    let base = FAST.0.as_ptr() as *const u8;
    let at = |k: usize| ((words[k / 4] >> (16 * (k % 4))) & 0xFFFF) as usize;
    // SAFETY: every offset is 16 times an index below N (the mask, then the shift; it fits
    // the 16-bit word, asserted above), so each 16-byte read lies inside the table.
    let p = |k: usize| unsafe { _mm_loadu_pd(base.add(at(k)).cast()) };
    let lo = |k: usize, j: usize| _mm256_insertf128_pd::<1>(_mm256_castpd128_pd256(p(k)), p(j));
    // Pieces of streams 0, 2, 4, 6 and of 1, 3, 5, 7, then width and bound of all eight.
    let even = _mm512_insertf64x4::<1>(_mm512_castpd256_pd512(lo(0, 2)), lo(4, 6));
    let odd = _mm512_insertf64x4::<1>(_mm512_castpd256_pd512(lo(1, 3)), lo(5, 7));
    let width = _mm512_unpacklo_pd(even, odd);
    let bound = _mm512_unpackhi_pd(even, odd);
    (width, bound)
}

/// The next normal of the eight streams in `st` (two sets of four joined) into `pair` (two
/// f64x4: the low set's lanes, then the high set's), the pieces looked up by gathers if
/// `GATHER`, else by loads; returns the streams' new state. By value in and out, so the
/// caller's state stays in registers.
#[inline]
#[target_feature(enable = "avx512f")]
fn draw<const GATHER: bool>(st: [__m512i; 4], pair: &mut [f64x4], k: Consts) -> [__m512i; 4] {
    // Taken apart and rebuilt below: with the array passed on whole, LLVM kept the state in
    // memory on the common path (a fifth slower).
    let (w, [s0, s1, s2, s3]) = step(st);
    let (width, bound) = if GATHER {
        let piece = _mm512_and_si512(w, k.index);
        // SAFETY: every index is below N (the mask), inside both tables.
        unsafe {
            (
                _mm512_i64gather_pd::<8>(piece, SPLIT.0.as_ptr().cast()),
                _mm512_i64gather_pd::<8>(piece, SPLIT.1.as_ptr().cast()),
            )
        }
    } else {
        pieces(w, k)
    };
    let b = _mm512_castsi512_pd(_mm512_or_si512(_mm512_srli_epi64::<12>(w), k.one));
    let sign = _mm512_sll_epi64(
        _mm512_and_si512(w, k.sign_bit),
        _mm_cvtsi32_si128(SIGN_SHIFT as i32),
    );
    // b * width - width with one rounding is (b - 1) * width rounded (b - 1 is exact): the
    // portable path's bits in one instruction.
    let x = _mm512_fmsub_pd(b, width, width);
    let x = _mm512_castsi512_pd(_mm512_or_si512(_mm512_castpd_si512(x), sign));
    let core = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(b, bound);
    let (st, x) = if core != 0xFF {
        finish([s0, s1, s2, s3], w, x, core as u32)
    } else {
        ([s0, s1, s2, s3], x)
    };
    assert!(pair.len() == 2);
    // SAFETY: `pair` is two adjacent f64x4, 64 bytes.
    unsafe { _mm512_storeu_pd(pair.as_mut_ptr().cast(), x) };
    st
}

/// [`crate::gauss::fill_one_portable`] with AVX-512F: stream a and stream b of the four lanes
/// in one register.
///
/// # Safety
/// The CPU must have AVX-512F.
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn fill_one(s: &mut [[u64x4; 4]; 2], out: &mut [f64x4], gather: bool) {
    if gather {
        fill_one_by::<true>(s, out)
    } else {
        fill_one_by::<false>(s, out)
    }
}

/// [`fill_one`] with the pieces looked up by gathers if `GATHER`.
#[target_feature(enable = "avx512f")]
fn fill_one_by<const GATHER: bool>(s: &mut [[u64x4; 4]; 2], out: &mut [f64x4]) {
    let mut st: [__m512i; 4] = core::array::from_fn(|w| join(s[0][w], s[1][w]));
    let k = Consts::new();
    for pair in out.chunks_exact_mut(2) {
        st = draw::<GATHER>(st, pair, k);
    }
    for (w, v) in st.iter().enumerate() {
        [s[0][w], s[1][w]] = halves(*v);
    }
}

/// [`crate::gauss::fill_two_portable`] with AVX-512F: stream a of the eight lanes in one
/// register, stream b in another.
///
/// # Safety
/// The CPU must have AVX-512F.
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn fill_two(s: &mut [[[u64x4; 4]; 2]; 2], out: &mut [f64x4], gather: bool) {
    if gather {
        fill_two_by::<true>(s, out)
    } else {
        fill_two_by::<false>(s, out)
    }
}

/// [`fill_two`] with the pieces looked up by gathers if `GATHER`.
#[target_feature(enable = "avx512f")]
fn fill_two_by<const GATHER: bool>(s: &mut [[[u64x4; 4]; 2]; 2], out: &mut [f64x4]) {
    let [mut sa, mut sb]: [[__m512i; 4]; 2] =
        core::array::from_fn(|j| core::array::from_fn(|w| join(s[j][0][w], s[j][1][w])));
    let k = Consts::new();
    for round in out.chunks_exact_mut(4) {
        let (a, b) = round.split_at_mut(2);
        sa = draw::<GATHER>(sa, a, k);
        sb = draw::<GATHER>(sb, b, k);
    }
    for (j, st) in [sa, sb].iter().enumerate() {
        for (w, v) in st.iter().enumerate() {
            [s[j][0][w], s[j][1][w]] = halves(*v);
        }
    }
}

/// The streams whose draw missed its piece's core (bit clear in `core`), finished one by
/// one by the portable code's scalar ziggurat (`gauss_scalar::lane_normal`), each drawing from its
/// own stream in the register: all eight step, only that one keeps its step. Returns the
/// state and `x` with those lanes replaced. Lanes move between the vector and general
/// registers by permutes: through memory (a 64-byte store read back 8 bytes at a time) this
/// path took 6.1 % of a noisy eight-lane run's profile, through registers 4.9 %.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx512f")]
fn finish(mut st: [__m512i; 4], w: __m512i, mut x: __m512d, core: u32) -> ([__m512i; 4], __m512d) {
    let mut pending = !core & 0xFF;
    while pending != 0 {
        let l = pending.trailing_zeros();
        pending &= pending - 1;
        let keep: __mmask8 = 1 << l;
        let at = _mm512_set1_epi64(l as i64);
        let lane = |v: __m512i| {
            _mm_cvtsi128_si64(_mm512_castsi512_si128(_mm512_permutexvar_epi64(at, v))) as u64
        };
        let mut next = || {
            let (drawn, t) = step(st);
            st = core::array::from_fn(|k| _mm512_mask_mov_epi64(st[k], keep, t[k]));
            lane(drawn)
        };
        let v = lane_normal(&mut next, lane(w));
        x = _mm512_mask_mov_pd(x, keep, _mm512_set1_pd(v));
    }
    (st, x)
}
