//! `e^{j 2 pi word / 2^64}` from a static table and a short Taylor series, IEEE arithmetic only.

use crate::dd::{self, Dd};
use gyroemu_core::Sample;
use num_complex::Complex64;
use std::sync::OnceLock;

/// log2 of the number of table entries (512 entries of 32 bytes, 16 KiB: stays in L1).
pub const TABLE_BITS: u32 = 9;
const TABLE_LEN: usize = 1 << TABLE_BITS;
const SHIFT: u32 = 64 - TABLE_BITS;
/// Half a table cell in phase-word units: rounds the index to the nearest entry so the
/// residual is centred, |r| <= pi / 512.
const HALF_CELL: u64 = 1 << (SHIFT - 1);
/// Radians per phase-word unit (exact power-of-two scaling of the f64 TAU).
const RAD_PER_WORD: f64 = core::f64::consts::TAU / 18_446_744_073_709_551_616.0;

/// One table entry: `e^{j 2 pi k / 512}` as `(cos, sin)` rounded to f64 plus the rounding
/// remainders, so the phasor is exact to ~1e-32 before the final rounding.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub(crate) struct Entry {
    c: f64,
    s: f64,
    c_lo: f64,
    s_lo: f64,
}

/// The table of unit phasors `e^{j 2 pi k / 512}`.
pub(crate) type Table = [Entry; TABLE_LEN];

fn build() -> Box<Table> {
    // First octant by a double-double Taylor series; the rest by exact swaps and sign changes,
    // so the table is exactly symmetric.
    let eighth = TABLE_LEN / 8;
    let octant: Vec<(Dd, Dd)> = (0..=eighth)
        .map(|k| dd::cos_sin(dd::PI.scale(k as f64 / (TABLE_LEN / 2) as f64)))
        .collect();
    let quarter = TABLE_LEN / 4;
    let mut t = Box::new([Entry::default(); TABLE_LEN]);
    for (k, slot) in t.iter_mut().enumerate() {
        let m = k % quarter;
        let (c, s) = if m <= eighth {
            octant[m]
        } else {
            let (c, s) = octant[quarter - m];
            (s, c)
        };
        // Multiply by j^q.
        let (c, s) = match k / quarter {
            0 => (c, s),
            1 => (s.neg(), c),
            2 => (c.neg(), s.neg()),
            _ => (s, c.neg()),
        };
        *slot = Entry {
            c: c.hi,
            s: s.hi,
            c_lo: c.lo,
            s_lo: s.lo,
        };
    }
    t
}

/// The shared table, built once on first use.
pub(crate) fn table() -> &'static Table {
    static TABLE: OnceLock<Box<Table>> = OnceLock::new();
    TABLE.get_or_init(build)
}

/// `e^{j 2 pi word / 2^64}` using the given table (the NCO keeps the reference to skip the
/// `OnceLock` check per sample). Error about half an ulp per component.
#[inline(always)]
pub(crate) fn phasor_with(t: &Table, word: u64) -> Complex64 {
    let idx = (word.wrapping_add(HALF_CELL) >> SHIFT) as usize;
    // |residual| <= 2^54 (its f64 rounding is below 4e-19 rad).
    let residual = word.wrapping_sub((idx as u64) << SHIFT) as i64;
    let r = residual as f64 * RAD_PER_WORD;
    let z = r * r;
    // e^{jr} = (1 + cm1) + j sn for |r| <= 6.2e-3; the omitted terms are below 1e-19.
    let sn = r + r * z * (-1.0 / 6.0 + z * (1.0 / 120.0));
    let cm1 = z * (-0.5 + z * (1.0 / 24.0 + z * (-1.0 / 720.0)));
    let e = t[idx & (TABLE_LEN - 1)];
    Complex64::new(
        e.c + (e.c_lo + (e.c * cm1 - e.s * sn)),
        e.s + (e.s_lo + (e.s * cm1 + e.c * sn)),
    )
}

/// [`phasor_with`] of `words[i]` in each lane `i` of `S`, as `(re, im)`: the index, the
/// residual and the table's words lane by lane, then the series and the sum in the lanes,
/// each lane by the same IEEE operations in the same order, so the same bits as the scalar
/// phasor (tested). A rotating NCO's exact re-set of eight lanes was scalar code, about 35
/// instructions a lane, once per 64 samples: 2 % of a `reproduce`.
#[inline(always)]
pub(crate) fn phasors_in_lanes<S: Sample>(t: &Table, words: &[u64]) -> (S, S) {
    let lane = |i: usize| {
        let idx = (words[i].wrapping_add(HALF_CELL) >> SHIFT) as usize;
        let residual = words[i].wrapping_sub((idx as u64) << SHIFT) as i64;
        (residual as f64, t[idx & (TABLE_LEN - 1)])
    };
    let parts: [(f64, Entry); 8] = core::array::from_fn(|i| {
        if i < S::LANES {
            lane(i)
        } else {
            (0.0, Entry::default())
        }
    });
    let r = S::from_fn(|i| parts[i].0) * S::splat(RAD_PER_WORD);
    let z = r * r;
    let sn = r + r * z * (S::splat(-1.0 / 6.0) + z * S::splat(1.0 / 120.0));
    let cm1 = z * (S::splat(-0.5) + z * (S::splat(1.0 / 24.0) + z * S::splat(-1.0 / 720.0)));
    let c = S::from_fn(|i| parts[i].1.c);
    let s = S::from_fn(|i| parts[i].1.s);
    let c_lo = S::from_fn(|i| parts[i].1.c_lo);
    let s_lo = S::from_fn(|i| parts[i].1.s_lo);
    (
        c + (c_lo + (c * cm1 - s * sn)),
        s + (s_lo + (s * cm1 + c * sn)),
    )
}

/// `e^{j 2 pi word / 2^64}`: the unit phasor of a 64-bit phase word, platform-deterministic.
#[inline]
pub fn phasor_of_word(word: u64) -> Complex64 {
    phasor_with(table(), word)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_matches_libm_and_is_unit() {
        let t = table();
        let mut worst: f64 = 0.0;
        for (k, p) in t.iter().enumerate() {
            // libm on the angle within its quadrant (small, so accurately represented),
            // then the quadrant by multiplying with j^q.
            let q = k / (TABLE_LEN / 4);
            let a = core::f64::consts::TAU * (k % (TABLE_LEN / 4)) as f64 / TABLE_LEN as f64;
            let rot = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][q];
            let want = Complex64::new(a.cos(), a.sin()) * Complex64::new(rot.0, rot.1);
            worst = worst.max((p.c - want.re).abs()).max((p.s - want.im).abs());
            assert!(p.c_lo.abs() <= 0.5 * p.c.abs() * f64::EPSILON);
            assert!(p.s_lo.abs() <= 0.5 * p.s.abs() * f64::EPSILON);
        }
        assert!(worst < 2.3e-16, "worst table error {worst}");
        assert_eq!((t[0].c, t[0].s, t[0].c_lo, t[0].s_lo), (1.0, 0.0, 0.0, 0.0));
    }

    /// The lane-wise re-set gives each lane the scalar phasor's bits: words over the whole
    /// circle, at the table's cell edges and half-cells, and the lanes in every position.
    #[test]
    fn phasors_in_lanes_are_the_scalar_phasors_bits() {
        let t = table();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut words: Vec<u64> = (0..40_000)
            .map(|_| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                seed
            })
            .collect();
        for k in 0..TABLE_LEN as u64 {
            let edge = k << SHIFT;
            words.extend([
                edge,
                edge.wrapping_add(HALF_CELL),
                edge.wrapping_add(HALF_CELL - 1),
            ]);
            words.extend([edge.wrapping_sub(1), edge.wrapping_add(HALF_CELL + 1)]);
        }
        words.extend([0, 1, u64::MAX, 1 << 63, (1 << 63) - 1]);
        let bits = |c: Complex64| (c.re.to_bits(), c.im.to_bits());
        for chunk in words.chunks_exact(4) {
            let (re, im) = phasors_in_lanes::<gyroemu_core::f64x4>(t, chunk);
            for (i, &w) in chunk.iter().enumerate() {
                let want = bits(phasor_with(t, w));
                assert_eq!(
                    (re.lane(i).to_bits(), im.lane(i).to_bits()),
                    want,
                    "word {w:#x} in lane {i}"
                );
            }
        }
        for &w in &words {
            let (re, im) = phasors_in_lanes::<f64>(t, &[w]);
            assert_eq!((re.to_bits(), im.to_bits()), bits(phasor_with(t, w)));
        }
    }

    #[test]
    fn table_is_exactly_symmetric_about_the_octant() {
        // Built from one octant by swaps and sign changes: cos of k cells is sin of
        // (quarter - k) cells, remainders included, bit for bit.
        let t = table();
        let quarter = TABLE_LEN / 4;
        for k in 1..quarter {
            let (a, b) = (t[k], t[quarter - k]);
            assert_eq!(a.c.to_bits(), b.s.to_bits(), "cell {k}");
            assert_eq!(a.c_lo.to_bits(), b.s_lo.to_bits(), "cell {k}");
        }
    }

    #[test]
    fn phasors_are_within_a_hair_of_half_an_ulp_of_one() {
        // Against the double-double series (about 1e-32) on words of the first octant that
        // are exact in f64; errors in units of 2^-53, half an ulp of the components near 1
        // (measured: 0.512). The residual is centred (|r| <= pi/512), so the series' omitted
        // terms are below 1e-19; a residual of a whole cell would add about 0.08.
        let mut seed = 0x0123_4567_89ab_cdefu64;
        let mut worst: f64 = 0.0;
        for _ in 0..200_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let word = (seed >> 3) & !((1 << 11) - 1); // < 2^61: below pi/4, 53 bits
            let (c, s) = dd::cos_sin(dd::PI.scale(word as f64 * 2f64.powi(-63)));
            let p = phasor_of_word(word);
            for (got, want) in [(p.re, c), (p.im, s)] {
                if want.hi == 0.0 {
                    continue;
                }
                worst = worst.max(((got - want.hi) - want.lo).abs() / 2f64.powi(-53));
            }
        }
        assert!(worst <= 0.52, "worst error {worst} x 2^-53");
    }

    #[test]
    fn quadrant_words_are_exact() {
        assert_eq!(phasor_of_word(0), Complex64::new(1.0, 0.0));
        assert_eq!(phasor_of_word(1 << 62), Complex64::new(0.0, 1.0));
        assert_eq!(phasor_of_word(1 << 63), Complex64::new(-1.0, 0.0));
        assert_eq!(phasor_of_word(3 << 62), Complex64::new(0.0, -1.0));
    }
}
