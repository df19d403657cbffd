//! One second-order section `(b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2)`.

use gyroemu_core::{Complex64, Sample};

/// Coefficients of one section in f64 (`a0 = 1`); a first-order section has `b2 = a2 = 0`.
///
/// For the response each polynomial `p0 + p1 z^-1 + p2 z^-2` is also kept as
/// `P(1) + (p1 + 2 p2) u + p2 u^2` with `u = z^-1 - 1`: near DC, where the poles of a
/// narrow low-pass sit next to `z = 1`, this form has no cancellation, so the response and
/// the group delay keep full relative precision.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Coefs {
    pub b0: f64,
    pub b1: f64,
    pub b2: f64,
    pub a1: f64,
    pub a2: f64,
    b_sum: f64,
    b_slope: f64,
    a_sum: f64,
    a_slope: f64,
}

impl Coefs {
    /// A direct-form section `(b0, b1, b2) / (1, a1, a2)`.
    pub fn biquad(b0: f64, b1: f64, b2: f64, a1: f64, a2: f64) -> Self {
        Self {
            b0,
            b1,
            b2,
            a1,
            a2,
            b_sum: b0 + b1 + b2,
            b_slope: b1 + 2.0 * b2,
            // For poles near z = 1 these sums are exact (Sterbenz: a1 ~ -2, a2 ~ 1).
            a_sum: 1.0 + a1 + a2,
            a_slope: a1 + 2.0 * a2,
        }
    }

    /// The one-pole `y += k (x - y)`, i.e. `k / (1 - (1 - k) z^-1)`, with `A(1) = k` exactly.
    pub fn one_pole(k: f64) -> Self {
        Self {
            b0: k,
            b1: 0.0,
            b2: 0.0,
            a1: -(1.0 - k),
            a2: 0.0,
            b_sum: k,
            b_slope: 0.0,
            a_sum: k,
            a_slope: -(1.0 - k),
        }
    }

    /// `A(1) = 1 + a1 + a2` (exact near DC, see [`Coefs::biquad`]).
    pub fn a_sum(&self) -> f64 {
        self.a_sum
    }

    /// DC gain `B(1) / A(1)`.
    pub fn dc_gain(&self) -> f64 {
        self.b_sum / self.a_sum
    }

    /// Complex gain at `z^-1 = 1 + u`.
    pub fn response(&self, u: Complex64) -> Complex64 {
        let num = u * (u * self.b2 + self.b_slope) + self.b_sum;
        let den = u * (u * self.a2 + self.a_slope) + self.a_sum;
        num / den
    }

    /// DC group delay in samples: near DC `u = -j w`, so each polynomial's phase is
    /// `-w slope / sum`, and the section's delay is numerator's minus denominator's.
    pub fn dc_group_delay(&self) -> f64 {
        self.b_slope / self.b_sum - self.a_slope / self.a_sum
    }
}

/// A section's recursion coefficients as samples; the state lives with the caller (one set
/// per channel, see [`crate::cascade::Cascade`]), so every channel runs the very same
/// arithmetic.
///
/// Butterworth sections are run without their numerator gain: biquad designs them as
/// `g (1 + z^-1)^2 / A(z)` (first order: `g (1 + z^-1) / A(z)`), exactly (its `b1` is `2 b0`
/// and `b2` is `b0` bit for bit), so a section needs two multiply-adds and three adds instead
/// of five multiplies, and the cascade applies the product of the gains once (see
/// [`crate::LowPass`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SectionCoefs<S> {
    /// Lock-in one-pole: its `k`.
    k: S,
    /// -a1 and -a2, stored negated so the recursion is pure multiply-adds.
    neg_a1: S,
    neg_a2: S,
}

impl<S: Sample> SectionCoefs<S> {
    pub fn new(c: &Coefs) -> Self {
        Self {
            k: S::splat(c.b0),
            neg_a1: S::splat(-c.a1),
            neg_a2: S::splat(-c.a2),
        }
    }

    /// `(1 + z^-1)^2 / (1 + a1 z^-1 + a2 z^-2)` in transposed direct form II (fewest states).
    #[inline(always)]
    pub fn unit2(&self, s1: &mut S, s2: &mut S, x: S) -> S {
        // The recursion through y is one add and one multiply-add long; `2x + s2` waits on
        // nothing of this sample. It is one multiply-add: 2x is exact, so it rounds once, as
        // `(x + x) + s2` does (the same bits below overflow), with no temporary for 2x (four
        // lanes hold a held bank's states in their 16 registers measurably better).
        let y = x + *s1;
        *s1 = self.neg_a1.mul_add(y, S::splat(2.0).mul_add(x, *s2));
        *s2 = self.neg_a2.mul_add(y, x);
        y
    }

    /// `(1 + z^-1) / (1 + a1 z^-1)` in transposed direct form II.
    #[inline(always)]
    pub fn unit1(&self, s1: &mut S, x: S) -> S {
        let y = x + *s1;
        *s1 = self.neg_a1.mul_add(y, x);
        y
    }

    /// Lock-in RC one-pole `y += k (x - y)` (state `s1`): a held input is reached exactly,
    /// whatever the rounding of `k`.
    #[inline(always)]
    pub fn one_pole(&self, s1: &mut S, x: S) -> S {
        let y = *s1 + self.k * (x - *s1);
        *s1 = y;
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_one_pole_is_the_biquad_it_describes() {
        // k / (1 - (1 - k) z^-1): the direct-form fields (read by the stability rules and
        // the pole check) describe the same filter as the sums the response uses.
        for k in [1e-9, 0.01, 0.5, 0.999] {
            let c = Coefs::one_pole(k);
            let d = Coefs::biquad(k, 0.0, 0.0, -(1.0 - k), 0.0);
            assert_eq!(
                (c.b0, c.b1, c.b2, c.a1, c.a2),
                (d.b0, d.b1, d.b2, d.a1, d.a2)
            );
            // Its pole is at z = 1 - k.
            assert_eq!(-c.a1, 1.0 - k);
            for u in [0.0, 0.3, -1.7] {
                let u = Complex64::new(u, 0.2);
                let (a, b) = (c.response(u), d.response(u));
                assert!((a - b).norm() <= 1e-12 * b.norm(), "k {k}, u {u}");
            }
            assert_eq!(c.dc_gain(), 1.0);
        }
    }
}
