//! The numeric type that flows through the chain: `f64`, or `f64x4` to run four operating
//! points in SIMD lanes through the very same stage code.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};
use wide::f64x4;

/// A real sample, scalar or lane-parallel. All arithmetic is plain IEEE `+ - * /`, fused
/// only where [`Sample::mul_add`] is written, so that every lane of a lane-parallel type gives
/// the bits the scalar `f64` path gives.
pub trait Sample:
    Copy
    + Default
    + Debug
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// Number of independent lanes (1 for `f64`).
    const LANES: usize;
    /// The same value in every lane.
    fn splat(v: f64) -> Self;
    /// Lane `i` set to `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> f64) -> Self;
    /// The value of lane `i` (`i < LANES`).
    fn lane(self, i: usize) -> f64;
    /// Lane-wise clamp into `[lo, hi]`.
    fn clamp_to(self, lo: Self, hi: Self) -> Self;
    /// Lane-wise round half away from zero.
    fn round_away(self) -> Self;
    /// Lane-wise round to nearest, ties to even: one instruction in the x86-64-v3 build
    /// (SSE4.1 and AVX), for a caller that has kept every lane off a tie (where it equals
    /// [`Sample::round_away`]).
    fn round_even(self) -> Self;
    /// True when every lane is finite.
    fn all_finite(self) -> bool;
    /// Lane-wise `|x|` (the sign bit cleared; a NaN stays a NaN).
    fn abs(self) -> Self;
    /// True when every lane is `<= hi` (a NaN lane is not): a whole-group test that keeps a
    /// rare case out of the per-sample path with one comparison and one branch.
    fn all_le(self, hi: Self) -> bool;
    /// 1.0 in the lanes where `self == other`, 0.0 elsewhere: a count a lane-parallel loop
    /// can add up without a branch (how often a converter clips, or outputs exact zeros).
    fn flag_eq(self, other: Self) -> Self;
    /// 1.0 in the lanes where `self != other` (a NaN counts as different), 0.0 elsewhere.
    fn flag_ne(self, other: Self) -> Self;
    /// `self * a + b`: fused (one rounding) when the build targets FMA (x86-64-v3, see
    /// `.cargo/config.toml`), two roundings otherwise. The choice is the same for every lane
    /// type, so f64x4 lanes keep the bits of the scalar path in either build.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// Lanes `0 .. LANES` from `v[0 .. LANES]` (`v` at least that long): how lane-parallel
    /// helpers such as the noise generator hand their lanes to any sample type.
    fn load(v: &[f64]) -> Self;
    /// Runs `f` compiled for the instructions this sample type's operations need: the sample
    /// loop enters through it, so a lane type the build does not target (eight lanes on a
    /// CPU with AVX-512, chosen at run time) gets its whole loop compiled for it, every
    /// operation inlined. Only what is inlined into `f` is compiled so, which is why the stage
    /// methods the per-sample loop calls are `#[inline(always)]`. `f64` and `f64x4` run `f`
    /// as it is.
    #[inline(always)]
    fn with_target_features<R>(f: impl FnOnce() -> R) -> R {
        f()
    }
    /// `self` with lane `i` replaced by `v` (the others keep their bits): a lane refilled
    /// with another operating point between blocks, never in a per-sample path.
    fn with_lane(self, i: usize, v: f64) -> Self {
        Self::from_fn(|l| if l == i { v } else { self.lane(l) })
    }
}

impl Sample for f64 {
    const LANES: usize = 1;
    #[inline(always)]
    fn splat(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
        f(0)
    }
    #[inline(always)]
    fn lane(self, _i: usize) -> f64 {
        self
    }
    #[inline(always)]
    fn load(v: &[f64]) -> Self {
        v[0]
    }
    #[inline(always)]
    fn clamp_to(self, lo: Self, hi: Self) -> Self {
        // max/min rather than f64::clamp: no panic path, NaN propagates as a NaN.
        if self < lo {
            lo
        } else if self > hi {
            hi
        } else {
            self
        }
    }
    #[inline(always)]
    fn round_away(self) -> Self {
        self.round()
    }
    #[inline(always)]
    fn round_even(self) -> Self {
        self.round_ties_even()
    }
    #[inline(always)]
    fn all_finite(self) -> bool {
        self.is_finite()
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn all_le(self, hi: Self) -> bool {
        self <= hi
    }
    #[inline(always)]
    fn flag_eq(self, other: Self) -> Self {
        if self == other {
            1.0
        } else {
            0.0
        }
    }
    #[inline(always)]
    fn flag_ne(self, other: Self) -> Self {
        1.0 - self.flag_eq(other)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        #[cfg(target_feature = "fma")]
        {
            f64::mul_add(self, a, b)
        }
        #[cfg(not(target_feature = "fma"))]
        {
            self * a + b
        }
    }
}

impl Sample for f64x4 {
    const LANES: usize = 4;
    #[inline(always)]
    fn splat(v: f64) -> Self {
        f64x4::splat(v)
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
        f64x4::new([f(0), f(1), f(2), f(3)])
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn load(v: &[f64]) -> Self {
        let a: [f64; 4] = v[..4].try_into().expect("four lanes");
        f64x4::new(a)
    }
    #[inline(always)]
    fn clamp_to(self, lo: Self, hi: Self) -> Self {
        // f64's rule in two instructions: `vmaxpd a, b` returns `a` only where a > b, else `b`
        // (also where either is a NaN), so `max(lo, x)` keeps x unless x < lo and
        // `min(hi, .)` keeps that unless it is > hi: a NaN passes through and a tie keeps x
        // (its sign of zero), as in f64. `wide`'s NaN-aware max and min cost a compare and a
        // blend each and turned a NaN input into `lo`.
        hi.fast_min(lo.fast_max(self))
    }
    #[inline(always)]
    fn round_away(self) -> Self {
        // f64::round (half away from zero) in four vector operations, without a libm call
        // per lane: trunc(x + copysign(1/2 - 2^-54, x)). The addend just below 1/2
        // makes the sum reach the next integer exactly when |x| has a fraction of 1/2 or more
        // (a sum that lands within half an ulp of it rounds there), never below (so
        // 0.49999999999999994 stays 0). From 2^52 up every f64 is an integer and the addend is
        // below half an ulp, so those pass through, as do inf and NaN; the sign survives (-0.3
        // gives -0.0 as f64::round does). LLVM lowers f64::round itself this way.
        let half = f64x4::splat(0.499_999_999_999_999_94) | (self & f64x4::splat(-0.0));
        (self + half).trunc()
    }
    #[inline(always)]
    fn round_even(self) -> Self {
        f64x4::round_ties_even(self)
    }
    #[inline(always)]
    fn all_finite(self) -> bool {
        self.is_finite().all()
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64x4::abs(self)
    }
    #[inline(always)]
    fn all_le(self, hi: Self) -> bool {
        // Ordered: false in a NaN lane.
        self.simd_le(hi).all()
    }
    #[inline(always)]
    fn flag_eq(self, other: Self) -> Self {
        // The comparison's lane masks are all ones or all zeros: and-ed with 1.0's bits.
        self.simd_eq(other) & f64x4::splat(1.0)
    }
    #[inline(always)]
    fn flag_ne(self, other: Self) -> Self {
        f64x4::splat(1.0) - self.flag_eq(other)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        #[cfg(target_feature = "fma")]
        {
            f64x4::mul_add(self, a, b)
        }
        #[cfg(not(target_feature = "fma"))]
        {
            self * a + b
        }
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    #[test]
    fn lanes_match_scalar_arithmetic() {
        let a = [1.25, -3.5, 1e-300, 7.0e12];
        let b = [0.1, 2.0 / 3.0, -4.0, 1.0 / 7.0];
        let va = f64x4::from_fn(|i| a[i]);
        let vb = f64x4::from_fn(|i| b[i]);
        let r = (va * vb + va - vb) / vb;
        for i in 0..4 {
            let s = (a[i] * b[i] + a[i] - b[i]) / b[i];
            assert_eq!(r.lane(i).to_bits(), s.to_bits());
        }
    }

    #[test]
    fn round_and_clamp_match_scalar() {
        let xs = [2.5, -2.5, 0.49999999999999994, -7.3];
        let v = f64x4::from_fn(|i| xs[i]);
        let r = v.round_away();
        let c = v.clamp_to(f64x4::splat(-1.0), f64x4::splat(1.0));
        for i in 0..4 {
            assert_eq!(r.lane(i), xs[i].round());
            assert_eq!(c.lane(i), xs[i].clamp_to(-1.0, 1.0));
        }
        // Clamping by the scalar rule bit for bit: a NaN passes, a tie keeps the input's
        // sign of zero, infinities clip, the bounds themselves stay.
        let specials = [
            f64::NAN,
            -0.0,
            0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -1.0,
            1.0,
            5e-324,
        ];
        for (lo, hi) in [
            (-1.0, 1.0),
            (0.0, 0.0),
            (-0.0, 0.0),
            (0.0, 2.0),
            (-3.0, -0.0),
        ] {
            for q in specials.chunks(4) {
                let c = f64x4::load(q).clamp_to(f64x4::splat(lo), f64x4::splat(hi));
                for (i, &x) in q.iter().enumerate() {
                    let want = x.clamp_to(lo, hi);
                    assert_eq!(c.lane(i).to_bits(), want.to_bits(), "{x} in [{lo}, {hi}]");
                }
            }
        }
        assert!(!f64x4::from_fn(|i| if i == 2 { f64::NAN } else { 0.0 }).all_finite());
    }

    #[test]
    fn flags_are_one_where_the_comparison_holds_in_each_lane() {
        let a = [0.0, -0.0, f64::NAN, 2.5];
        let b = [0.0, 0.0, f64::NAN, 2.0];
        let (va, vb) = (f64x4::from_fn(|i| a[i]), f64x4::from_fn(|i| b[i]));
        let (eq, ne) = (va.flag_eq(vb), va.flag_ne(vb));
        // -0 == +0 in IEEE; NaN equals nothing.
        let want_eq = [1.0, 1.0, 0.0, 0.0];
        for i in 0..4 {
            assert_eq!(eq.lane(i), want_eq[i], "lane {i}");
            assert_eq!(ne.lane(i), 1.0 - want_eq[i], "lane {i}");
            assert_eq!(a[i].flag_eq(b[i]), want_eq[i], "scalar {i}");
            assert_eq!(a[i].flag_ne(b[i]), 1.0 - want_eq[i], "scalar {i}");
        }
    }

    #[test]
    fn abs_and_all_le_match_scalar_lane_by_lane() {
        let xs = [
            0.0,
            -0.0,
            1.5,
            -2.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.5,
        ];
        for rot in 0..8 {
            let a: [f64; 4] = core::array::from_fn(|i| xs[(i + rot) % 8]);
            let va = f64x4::from_fn(|i| a[i]);
            for i in 0..4 {
                assert_eq!(Sample::abs(va).lane(i).to_bits(), a[i].abs().to_bits());
            }
            for hi in [1.5, 0.0, -0.0, -2.0, f64::INFINITY, f64::NEG_INFINITY] {
                let scalar = a.iter().all(|&x| x.all_le(hi));
                assert_eq!(scalar, a.iter().all(|&x| x <= hi));
                assert_eq!(va.all_le(f64x4::splat(hi)), scalar, "{a:?} <= {hi}");
            }
        }
        // A NaN is below nothing, not even infinity; -0 <= +0.
        assert!(!f64::NAN.all_le(f64::INFINITY));
        assert!(!f64x4::from_fn(|i| if i == 3 { f64::NAN } else { 0.0 }).all_le(f64x4::splat(1.0)));
        assert!((0.0f64).all_le(-0.0));
    }

    #[test]
    fn vector_roundings_are_f64_round_and_round_ties_even_on_ties_edges_and_a_seeded_sweep() {
        let mut xs = vec![
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -0.0,
            0.0,
            -0.3,
            4503599627370495.5,
            -4503599627370495.5,
            4503599627370496.0,
            9.0e18,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            1e-310,
        ];
        // Splitmix-style generator: halves, near-halves and wide magnitudes.
        let mut s = 0x1234_5678_9abc_def0u64;
        for _ in 0..100_000 {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let z = (s ^ (s >> 31)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            let scale = 2f64.powi((z % 60) as i32 - 5);
            let u = (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            xs.push(u * scale);
            xs.push((u * scale).trunc() + 0.5 * u.signum());
        }
        for c in xs.chunks(4) {
            let v = f64x4::from_fn(|i| c[i % c.len()]);
            let (r, e) = (v.round_away(), v.round_even());
            for i in 0..4 {
                let x = c[i % c.len()];
                assert_eq!(r.lane(i).to_bits(), x.round().to_bits(), "x = {x:e}");
                let even = x.round_ties_even();
                assert_eq!(e.lane(i).to_bits(), even.to_bits(), "x = {x:e}");
                assert_eq!(Sample::round_even(x).to_bits(), even.to_bits(), "x = {x:e}");
            }
        }
        // The two rules part only at a tie: 2.5 goes to 2 by one, to 3 by the other.
        assert_eq!(f64x4::splat(2.5).round_even().lane(0), 2.0);
        assert_eq!(
            f64x4::splat(-0.5).round_even().lane(0).to_bits(),
            (-0.0f64).to_bits()
        );
        let n = f64x4::splat(f64::NAN).round_away();
        assert!(n.lane(0).is_nan());
        assert!(f64x4::splat(f64::NAN).round_even().lane(0).is_nan());
    }

    #[test]
    fn mul_add_lanes_match_scalar_and_fuse_when_the_build_has_fma() {
        let (a, b, c) = (0.1, 10.0, -1.0);
        let v = f64x4::splat(a).mul_add(f64x4::splat(b), f64x4::splat(c));
        let s = Sample::mul_add(a, b, c);
        assert_eq!(v.lane(3).to_bits(), s.to_bits());
        // 0.1 * 10 - 1 is 0 with two roundings and 2^-54 with one.
        let fused = cfg!(target_feature = "fma");
        assert_eq!(s == 0.0, !fused, "{s:e}");
    }
}
