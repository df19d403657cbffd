//! Eight f64 lanes in one AVX-512 register, for CPUs that have it (chosen at run time: the
//! build targets x86-64-v3, which has no AVX-512). Every operation is the IEEE operation of
//! `f64` and `f64x4` lane by lane (the same rounding, `mul_add` fused alike, the same
//! min/max and NaN rules as `wide`'s f64x4), so a point gets the same bits in every lane type.
//!
//! A value exists only inside a board built after checking the CPU ([`available`]): an
//! eight-lane board of [`crate::GroupBoard`], or the joined TIA flicker sources of a four-lane
//! board, made only when [`crate::max_lanes`] is 8. That is what makes the intrinsics below
//! sound; the type is private to
//! this crate so nothing else can make one. The sample loop enters through
//! [`Sample::with_target_features`], which compiles it, with every operation inlined, for
//! AVX-512.

use core::arch::x86_64::*;
use core::fmt;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};
use gyroemu_core::Sample;

/// This CPU runs AVX-512 F, VL, DQ and BW (the answer is cached by `std`): the features the
/// eight-lane loop is compiled for (the 512-bit operations need F; VL, DQ and BW let the
/// compiler use 32 registers and masks in the rest of the loop).
pub(crate) fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && std::arch::is_x86_feature_detected!("avx512bw")
}

/// Eight f64 lanes.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct F64x8(__m512d);

// The operations run intrinsics of AVX-512F. SAFETY (every `unsafe` block below): an F64x8
// exists only on a CPU with AVX-512 (module doc).

impl F64x8 {
    #[inline(always)]
    fn to_array(self) -> [f64; 8] {
        // SAFETY: __m512d is eight f64, any bits valid.
        unsafe { core::mem::transmute::<__m512d, [f64; 8]>(self.0) }
    }

    /// The lanes in memory, read without an AVX-512 instruction (so code compiled without
    /// it, such as a four-lane loop, may read an eight-lane buffer).
    #[inline(always)]
    pub(crate) fn as_array(&self) -> &[f64; 8] {
        // SAFETY: __m512d is eight f64, and [f64; 8] needs less alignment.
        unsafe { &*(self as *const Self).cast::<[f64; 8]>() }
    }

    #[inline(always)]
    fn from_array(a: [f64; 8]) -> Self {
        // SAFETY: as above.
        Self(unsafe { core::mem::transmute::<[f64; 8], __m512d>(a) })
    }

    #[inline(always)]
    fn bits_and(self, rhs: Self) -> Self {
        unsafe {
            Self(_mm512_castsi512_pd(_mm512_and_si512(
                _mm512_castpd_si512(self.0),
                _mm512_castpd_si512(rhs.0),
            )))
        }
    }

    #[inline(always)]
    fn bits_or(self, rhs: Self) -> Self {
        unsafe {
            Self(_mm512_castsi512_pd(_mm512_or_si512(
                _mm512_castpd_si512(self.0),
                _mm512_castpd_si512(rhs.0),
            )))
        }
    }
}

/// Runs `f` compiled for AVX-512, everything it calls inline inlined with it.
///
/// # Safety
/// The CPU must have the features of [`available`].
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw")]
#[inline(never)]
unsafe fn with_avx512<R>(f: impl FnOnce() -> R) -> R {
    f()
}

impl Default for F64x8 {
    #[inline(always)]
    fn default() -> Self {
        Self::from_array([0.0; 8])
    }
}

impl fmt::Debug for F64x8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "F64x8({:?})", self.to_array())
    }
}

macro_rules! binary {
    ($tr:ident, $m:ident, $tra:ident, $ma:ident, $op:ident) => {
        impl $tr for F64x8 {
            type Output = Self;
            #[inline(always)]
            fn $m(self, rhs: Self) -> Self {
                Self(unsafe { $op(self.0, rhs.0) })
            }
        }
        impl $tra for F64x8 {
            #[inline(always)]
            fn $ma(&mut self, rhs: Self) {
                *self = $tr::$m(*self, rhs);
            }
        }
    };
}
binary!(Add, add, AddAssign, add_assign, _mm512_add_pd);
binary!(Sub, sub, SubAssign, sub_assign, _mm512_sub_pd);
binary!(Mul, mul, MulAssign, mul_assign, _mm512_mul_pd);

impl Div for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: Self) -> Self {
        Self(unsafe { _mm512_div_pd(self.0, rhs.0) })
    }
}

impl Neg for F64x8 {
    type Output = Self;
    /// The sign bit flipped, as `-x` of an f64 (NaNs included).
    #[inline(always)]
    fn neg(self) -> Self {
        unsafe {
            Self(_mm512_castsi512_pd(_mm512_xor_si512(
                _mm512_castpd_si512(self.0),
                _mm512_set1_epi64(i64::MIN),
            )))
        }
    }
}

impl Sample for F64x8 {
    const LANES: usize = 8;
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Self(unsafe { _mm512_set1_pd(v) })
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> f64) -> Self {
        Self::from_array(core::array::from_fn(f))
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn load(v: &[f64]) -> Self {
        let a: &[f64; 8] = v[..8].try_into().expect("eight lanes");
        Self(unsafe { _mm512_loadu_pd(a.as_ptr()) })
    }
    #[inline(always)]
    fn clamp_to(self, lo: Self, hi: Self) -> Self {
        // As f64x4's: `vmaxpd(lo, x)` then `vminpd(hi, .)`, the operand order f64's rule needs.
        unsafe { Self(_mm512_min_pd(hi.0, _mm512_max_pd(lo.0, self.0))) }
    }
    #[inline(always)]
    fn round_away(self) -> Self {
        // As f64x4's: trunc(x + copysign(1/2 - 2^-54, x)) is f64::round (see sample.rs).
        let half = Self::splat(0.499_999_999_999_999_94).bits_or(self.bits_and(Self::splat(-0.0)));
        let s = self + half;
        Self(unsafe { _mm512_roundscale_pd::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(s.0) })
    }
    #[inline(always)]
    fn round_even(self) -> Self {
        Self(unsafe {
            _mm512_roundscale_pd::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(self.0)
        })
    }
    #[inline(always)]
    fn all_finite(self) -> bool {
        // The lanes classed as a NaN (quiet 0x01, signalling 0x80) or an infinity (+ 0x08,
        // - 0x10).
        unsafe { _mm512_fpclass_pd_mask::<0x99>(self.0) == 0 }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Self(unsafe { _mm512_abs_pd(self.0) })
    }
    #[inline(always)]
    fn all_le(self, hi: Self) -> bool {
        // Ordered: false in a NaN lane.
        unsafe { _mm512_cmp_pd_mask::<_CMP_LE_OQ>(self.0, hi.0) == 0xFF }
    }
    #[inline(always)]
    fn flag_eq(self, other: Self) -> Self {
        unsafe {
            let eq = _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(self.0, other.0);
            Self(_mm512_maskz_mov_pd(eq, _mm512_set1_pd(1.0)))
        }
    }
    #[inline(always)]
    fn flag_ne(self, other: Self) -> Self {
        Self::splat(1.0) - self.flag_eq(other)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        #[cfg(target_feature = "fma")]
        {
            Self(unsafe { _mm512_fmadd_pd(self.0, a.0, b.0) })
        }
        #[cfg(not(target_feature = "fma"))]
        {
            self * a + b
        }
    }
    #[inline(always)]
    fn with_target_features<R>(f: impl FnOnce() -> R) -> R {
        // SAFETY: an F64x8 exists only on a CPU with these features (module doc).
        unsafe { with_avx512(f) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_core::f64x4;

    /// True (and says so) on a CPU without AVX-512, where the eight-lane type is not used.
    fn skip_without_avx512() -> bool {
        if available() {
            return false;
        }
        eprintln!("no AVX-512 on this CPU: the eight-lane type is not used here");
        true
    }

    /// Values that exercise every rule: ties, signed zeros, NaN, infinities, subnormals,
    /// huge and tiny magnitudes.
    const XS: [f64; 16] = [
        2.5,
        -2.5,
        0.499_999_999_999_999_94,
        -0.0,
        0.0,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1e-310,
        -7.3,
        4_503_599_627_370_495.5,
        1.0 / 3.0,
        -1e300,
        0.1,
        f64::MAX,
        -0.5,
    ];

    /// Each lane of every operation against f64x4's lane (itself tested against f64).
    #[test]
    fn every_operation_has_the_bits_of_f64x4_in_every_lane() {
        if skip_without_avx512() {
            return;
        }
        let bits = |v: f64| v.to_bits();
        for rot in 0..16 {
            let a: [f64; 8] = core::array::from_fn(|i| XS[(i + rot) % 16]);
            let b: [f64; 8] = core::array::from_fn(|i| XS[(3 * i + rot + 5) % 16]);
            let c: [f64; 8] = core::array::from_fn(|i| XS[(5 * i + 2 * rot + 1) % 16]);
            let (va, vb, vc) = (
                F64x8::from_array(a),
                F64x8::from_array(b),
                F64x8::from_array(c),
            );
            let four = |x: &[f64; 8], h: usize| f64x4::new(x[4 * h..4 * h + 4].try_into().unwrap());
            for h in 0..2 {
                let (fa, fb, fc) = (four(&a, h), four(&b, h), four(&c, h));
                let pairs: [(F64x8, f64x4); 14] = [
                    (va + vb, fa + fb),
                    (va - vb, fa - fb),
                    (va * vb, fa * fb),
                    (va / vb, fa / fb),
                    (-va, -fa),
                    (va.mul_add(vb, vc), fa.mul_add(fb, fc)),
                    (va.clamp_to(vb, vc), fa.clamp_to(fb, fc)),
                    (va.round_away(), fa.round_away()),
                    (va.round_even(), fa.round_even()),
                    (va.flag_eq(vb), fa.flag_eq(fb)),
                    (va.flag_ne(vb), fa.flag_ne(fb)),
                    (va.flag_eq(va), fa.flag_eq(fa)),
                    (F64x8::load(&a), f64x4::load(&a[4 * h..])),
                    (va.abs(), fa.abs()),
                ];
                for (k, (x8, x4)) in pairs.iter().enumerate() {
                    for l in 0..4 {
                        assert_eq!(
                            bits(x8.lane(4 * h + l)),
                            bits(x4.lane(l)),
                            "op {k}, lanes {a:?} {b:?} {c:?}, lane {}",
                            4 * h + l
                        );
                    }
                }
            }
            let finite = a.iter().all(|x| x.is_finite());
            assert_eq!(va.all_finite(), finite, "{a:?}");
            let below = (0..8).all(|i| a[i] <= c[i]);
            assert_eq!(va.all_le(vc), below, "{a:?} <= {c:?}");
            // At or below itself unless a lane is a NaN.
            let numbers = a.iter().all(|x| !x.is_nan());
            assert_eq!(va.all_le(va), numbers, "{a:?}");
        }
        assert!(F64x8::splat(1.5).all_finite());
        assert_eq!(F64x8::splat(-4.0).to_array(), [-4.0; 8]);
        assert_eq!(F64x8::default().to_array().map(bits), [0; 8]);
    }

    /// The round-half-away rule against `f64::round`, and round-to-even against
    /// `f64::round_ties_even`, on a seeded sweep of halves, near-halves and wide magnitudes
    /// (the edge cases are in the test above).
    #[test]
    fn roundings_are_f64_round_and_round_ties_even_on_a_seeded_sweep() {
        if skip_without_avx512() {
            return;
        }
        let mut s = 0x0123_4567_89ab_cdefu64;
        let mut xs = [0.0; 8];
        for k in 0..200_000 {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let z = (s ^ (s >> 31)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            let scale = 2f64.powi((z % 60) as i32 - 5);
            let u = (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            xs[k % 8] = if k % 2 == 0 {
                u * scale
            } else {
                (u * scale).trunc() + 0.5 * u.signum()
            };
            if k % 8 == 7 {
                let v = F64x8::from_array(xs);
                let (r, e) = (v.round_away(), v.round_even());
                for (l, x) in xs.iter().enumerate() {
                    assert_eq!(r.lane(l).to_bits(), x.round().to_bits(), "x = {x:e}");
                    let even = x.round_ties_even().to_bits();
                    assert_eq!(e.lane(l).to_bits(), even, "x = {x:e}");
                }
            }
        }
    }

    /// A flicker source in eight lanes (the joined TIA sources, and each TIA source of an
    /// eight-lane board) runs eight poles per pass, then the rest, up to seven, in one pass:
    /// `process` against `tick` on every block size of the stage contract, for 4 to 24 poles
    /// (every remainder modulo eight among them), and lane by lane against a scalar source.
    #[test]
    fn a_flicker_source_in_eight_lanes_is_its_ticks_for_every_pole_count() {
        use gyroemu_core::check::{self, Gen};
        use gyroemu_core::flicker::{Flicker, FlickerParams};
        use gyroemu_core::Stage;
        if skip_without_avx512() {
            return;
        }
        let mut g = Gen::new(0x0f11_c4e8);
        let mut counts = Vec::new();
        for tenth in (20..=120).step_by(5) {
            let p = FlickerParams {
                fs_hz: 1.0,
                psd_at_1hz: 0.7,
                f_lo_hz: 0.5 * 10f64.powf(-(tenth as f64) / 10.0),
                f_hi_hz: 0.5,
            };
            let wide = Flicker::<F64x8>::stationary(&p, || g.sample(-1.0, 1.0)).unwrap();
            counts.push(wide.design().poles());
            let input = |g: &mut Gen| g.sample::<F64x8>(-2.0, 2.0);
            check::tick_vs_process("flicker x8", &wide, input, |y| y.to_array());
            // Lane 5 from its own start, as a scalar source fed lane 5's inputs.
            let mut lane = Flicker::<f64>::at_rest(&p).unwrap();
            let mut eight = Flicker::<F64x8>::at_rest(&p).unwrap();
            let xs: Vec<F64x8> = (0..97).map(|_| input(&mut g)).collect();
            let mut ys = vec![F64x8::default(); xs.len()];
            eight.process(&xs, &mut ys);
            for (n, (x, y)) in xs.iter().zip(&ys).enumerate() {
                let want = lane.tick(x.lane(5));
                assert_eq!(y.lane(5).to_bits(), want.to_bits(), "sample {n}");
            }
        }
        for r in 0..8 {
            assert!(counts.iter().any(|&n| n % 8 == r && n > 8), "{counts:?}");
        }
    }

    /// The loop entry runs its closure compiled for AVX-512 and returns its value.
    #[test]
    fn the_loop_entry_runs_its_closure() {
        if skip_without_avx512() {
            return;
        }
        let v = F64x8::with_target_features(|| (F64x8::splat(3.0) * F64x8::splat(0.5)).lane(7));
        assert_eq!(v, 1.5);
    }

    /// The quantiser's product path in eight lanes against its division, lane by lane and
    /// count by count, on groups that mix clear lanes with zeros, near-ties, end codes and
    /// special values (the four-lane and scalar paths: `crates/am/tests/quantizer_fast.rs`).
    #[test]
    fn the_quantiser_fast_path_in_eight_lanes_is_the_division() {
        use gyroemu_am::Quantizer;
        if skip_without_avx512() {
            return;
        }
        let mut s = 0x5eed_0f8a_11e5_u64;
        let mut next = move || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let z = (s ^ (s >> 31)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z ^ (z >> 29)
        };
        for (bits, fs) in [(16, 1.5), (16, 0.05), (3, 1.0), (24, 3.3), (32, 1e-300)] {
            let q8 = Quantizer::<F64x8>::new(bits, fs).unwrap();
            let q1 = Quantizer::<f64>::new(bits, fs).unwrap();
            let (step, half) = (q1.step(), (1u64 << (bits - 1)) as f64);
            let edges = [0.0, -0.0, 0.5, -0.5, half - 0.5, half, -half, f64::NAN];
            let [mut c_fast, mut z_fast, mut c_div, mut z_div] = [F64x8::splat(0.0); 4];
            for _ in 0..20_000 {
                let x: [f64; 8] = core::array::from_fn(|_| {
                    let r = next();
                    let ulps = (r >> 60) as i64 - 8;
                    let code = match r % 8 {
                        // A clear lane, most of the time.
                        0..=4 => ((r >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * half,
                        5 => ((r >> 20) % 7) as f64 - 3.0 + 0.5,
                        _ => edges[((r >> 20) % 8) as usize],
                    };
                    let x = code * step;
                    let moved = f64::from_bits((x.to_bits() as i64).wrapping_add(ulps) as u64);
                    if x == 0.0 || !x.is_finite() {
                        x
                    } else {
                        moved
                    }
                });
                let v = F64x8::from_array(x);
                let fast = q8.quantize_counting_fast(v, &mut c_fast, &mut z_fast);
                let div = q8.quantize_counting(v, &mut c_div, &mut z_div);
                for l in 0..8 {
                    assert_eq!(fast.lane(l).to_bits(), div.lane(l).to_bits(), "{x:?}");
                    assert_eq!(div.lane(l).to_bits(), q1.quantize(x[l]).to_bits(), "{x:?}");
                }
            }
            assert_eq!(
                c_fast.to_array(),
                c_div.to_array(),
                "{bits} bits: clip counts"
            );
            assert_eq!(
                z_fast.to_array(),
                z_div.to_array(),
                "{bits} bits: zero counts"
            );
            assert!(
                z_div.to_array().iter().all(|&z| z > 100.0),
                "zeros are exercised"
            );
        }
    }
}
