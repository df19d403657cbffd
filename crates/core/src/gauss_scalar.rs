//! The scalar ziggurat of `gauss` on one lane's stream: how a 64-bit draw splits into piece,
//! sign and uniform, and the exact test of a point that missed its piece's core (a wedge, or
//! the base beyond r). The four-lane path (`gauss`) and its AVX-512F twin (`gauss_avx512`)
//! both finish their rare lanes here, so each stream's sequence is this ziggurat's.

use crate::gauss_tables::{F, FAST, N, R, WEDGE};
use wide::f64x4;

/// The exponent bits of 1.0: `ONE_BITS | m` for a 52-bit `m` is `1 + m / 2^52`, in [1, 2).
pub(crate) const ONE_BITS: u64 = 0x3FF0_0000_0000_0000;
/// The bit of a draw that gives the sign (the bits below it pick the piece).
pub(crate) const SIGN_BIT: u64 = N as u64;
/// How far the sign bit moves to become an f64's sign.
pub(crate) const SIGN_SHIFT: u32 = 63 - N.trailing_zeros();
const _: () = assert!(
    N.is_power_of_two() && N <= 1 << 11,
    "piece and sign fit below bit 12"
);

/// The piece (bits 0-10), the sign (bit 11, moved to bit 63) and the uniform
/// `b = 1 + m / 2^52` in [1, 2) (bits 12-63) of a draw.
#[inline(always)]
fn split(w: u64) -> (usize, u64, f64) {
    (
        w as usize & (N - 1),
        (w & SIGN_BIT) << SIGN_SHIFT,
        f64::from_bits((w >> 12) | ONE_BITS),
    )
}

/// `e^x`, the same bits on every run (`wide`'s polynomial).
#[inline]
fn exp(x: f64) -> f64 {
    f64x4::splat(x).exp().to_array()[0]
}

/// `ln x`, the same bits on every run (`wide`'s polynomial).
#[inline]
pub(crate) fn ln(x: f64) -> f64 {
    f64x4::splat(x).ln().to_array()[0]
}

/// Uniform in (0, 1] from a draw's top 53 bits (so `ln` never sees 0).
#[inline]
pub(crate) fn open0(w: u64) -> f64 {
    ((w >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Uniform in [0, 1) from a draw's top 53 bits.
#[inline]
pub(crate) fn closed0(w: u64) -> f64 {
    (w >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The scalar ziggurat on one lane, starting from draw `w` (already taken from that lane's
/// stream); `draw` gives the same stream's further draws.
#[inline(always)]
pub(crate) fn lane_normal(draw: &mut impl FnMut() -> u64, mut w: u64) -> f64 {
    loop {
        let (i, sign, b) = split(w);
        let [width, bound] = FAST.0[i];
        let x = (b - 1.0) * width;
        let x = if b < bound {
            Some(x)
        } else if i == 0 {
            Some(tail(draw))
        } else {
            // A uniform height across layer i's wedge, from f(X[i]) at its right edge up to
            // f(X[i+1]); the point is kept where it lies under the curve. The chord between
            // the wedge's corners, with the tabled bounds on f minus it, decides all but a
            // thin band around the curve without exp.
            let y = F[i] + closed0(draw()) * (F[i + 1] - F[i]);
            let [slope, lo, hi] = WEDGE[i];
            let c = F[i] + (width - x) * slope;
            let under = if y < c + lo {
                true
            } else if y >= c + hi {
                false
            } else {
                y < exp(-0.5 * x * x)
            };
            under.then_some(x)
        };
        if let Some(x) = x {
            return f64::from_bits(x.to_bits() | sign);
        }
        w = draw();
    }
}

/// A normal conditioned on x > r (Marsaglia 1964): x = r + a with a exponential of rate r,
/// kept with probability exp(-a^2 / 2).
#[inline(never)]
fn tail(draw: &mut impl FnMut() -> u64) -> f64 {
    loop {
        let a = -ln(open0(draw())) / R;
        let c = -ln(open0(draw()));
        if c + c > a * a {
            return R + a;
        }
    }
}
