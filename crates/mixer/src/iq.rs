//! An I/Q pair of lane samples: the complex stage-1 output `z = I + jQ` per lane
//! (`num_complex::Complex<f64x4>` would need num traits that `f64x4` lacks).

use core::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};
use gyroemu_core::{Complex64, Sample};

/// A complex sample `i + j q`, each part a (possibly lane-parallel) real sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Iq<S> {
    /// In-phase (real) part.
    pub i: S,
    /// Quadrature (imaginary) part.
    pub q: S,
}

impl<S: Sample> Iq<S> {
    /// Builds `i + j q`.
    #[inline]
    pub fn new(i: S, q: S) -> Self {
        Self { i, q }
    }

    /// The same complex value in every lane.
    #[inline]
    pub fn splat(z: Complex64) -> Self {
        Self {
            i: S::splat(z.re),
            q: S::splat(z.im),
        }
    }

    /// Lane `k` as a complex number.
    #[inline]
    pub fn lane(&self, k: usize) -> Complex64 {
        Complex64::new(self.i.lane(k), self.q.lane(k))
    }
}

impl<S: Sample> Add for Iq<S> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::new(self.i + o.i, self.q + o.q)
    }
}

impl<S: Sample> Sub for Iq<S> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::new(self.i - o.i, self.q - o.q)
    }
}

impl<S: Sample> Neg for Iq<S> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self::new(-self.i, -self.q)
    }
}

impl<S: Sample> AddAssign for Iq<S> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        self.i += o.i;
        self.q += o.q;
    }
}

impl<S: Sample> SubAssign for Iq<S> {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        self.i -= o.i;
        self.q -= o.q;
    }
}

/// Scaling by a real sample (lane-wise).
impl<S: Sample> Mul<S> for Iq<S> {
    type Output = Self;
    #[inline]
    fn mul(self, k: S) -> Self {
        Self::new(self.i * k, self.q * k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_core::f64x4;

    #[test]
    fn arithmetic_matches_complex() {
        let a = Iq::<f64>::new(1.5, -2.0);
        let b = Iq::<f64>::new(-0.25, 4.0);
        let (ca, cb) = (a.lane(0), b.lane(0));
        assert_eq!((a + b).lane(0), ca + cb);
        assert_eq!((a - b).lane(0), ca - cb);
        assert_eq!((-a).lane(0), -ca);
        assert_eq!((a * 3.0).lane(0), ca * 3.0);
        let mut c = a;
        c += b;
        c -= a;
        assert_eq!(c, b);
        let v = Iq::<f64x4>::splat(Complex64::new(0.5, -1.0));
        assert_eq!(v.lane(3), Complex64::new(0.5, -1.0));
    }
}
