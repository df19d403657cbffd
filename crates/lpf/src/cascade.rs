//! The cascade's shape and coefficients, run on any number of channels.

use crate::design::MAX_ORDER;
use crate::section::{Coefs, SectionCoefs};
use gyroemu_core::Sample;

/// The state of `C` channels of a cascade: `s1`, `s2` of every section, per channel.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CascadeState<S, const C: usize> {
    pub s1: [[S; C]; MAX_ORDER],
    pub s2: [[S; C]; MAX_ORDER],
}

impl<S: Sample, const C: usize> Default for CascadeState<S, C> {
    fn default() -> Self {
        Self {
            s1: [[S::default(); C]; MAX_ORDER],
            s2: [[S::default(); C]; MAX_ORDER],
        }
    }
}

/// Up to 8 sections with fixed capacity (no allocation): Butterworth sections with unit
/// numerators and one input gain (see [`crate::LowPass`]), or lock-in RC one-poles. One
/// `tick` serves a single filter (`C = 1`) and a bank of channels alike.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cascade<S> {
    one_pole: bool,
    /// Section 0 is the first-order section of an odd Butterworth order.
    first_order: bool,
    n: usize,
    /// Product of the Butterworth sections' numerator gains (1 for a lock-in filter).
    gain: S,
    sec: [SectionCoefs<S>; MAX_ORDER],
}

impl<S: Sample> Cascade<S> {
    /// The cascade of `n` sections `coefs` (lock-in one-poles if `one_pole`).
    pub fn new(one_pole: bool, n: usize, coefs: &[Coefs; MAX_ORDER]) -> Self {
        let gain = if one_pole {
            1.0
        } else {
            coefs[..n].iter().map(|c| c.b0).product()
        };
        Self {
            one_pole,
            first_order: !one_pole && coefs[0].a2 == 0.0 && coefs[0].b2 == 0.0,
            n,
            gain: S::splat(gain),
            sec: core::array::from_fn(|k| SectionCoefs::new(&coefs[k])),
        }
    }

    /// Number of sections in use.
    pub fn sections(&self) -> usize {
        self.n
    }

    /// Exactly `n` unit-numerator biquads (no one-pole, no first-order section).
    pub fn is_biquads(&self, n: usize) -> bool {
        !self.one_pole && !self.first_order && self.n == n
    }

    /// The product of the sections' numerator gains, applied at the input.
    pub fn gain(&self) -> S {
        self.gain
    }

    /// Section `k`'s recursion coefficients.
    pub fn section(&self, k: usize) -> SectionCoefs<S> {
        self.sec[k]
    }

    /// One input sample of each of `C` channels through the cascade.
    #[inline(always)]
    pub fn tick<const C: usize>(&self, st: &mut CascadeState<S, C>, x: [S; C]) -> [S; C] {
        let n = self.n;
        let (sec, s1, s2) = (&self.sec[..n], &mut st.s1[..n], &mut st.s2[..n]);
        if self.one_pole {
            let mut y = x;
            for (c, s) in sec.iter().zip(s1) {
                for ch in 0..C {
                    y[ch] = c.one_pole(&mut s[ch], y[ch]);
                }
            }
            return y;
        }
        let g = self.gain;
        let mut y = x.map(|v| g * v);
        let first = usize::from(self.first_order);
        if first == 1 {
            for ch in 0..C {
                y[ch] = sec[0].unit1(&mut s1[0][ch], y[ch]);
            }
        }
        for ((c, a), b) in sec[first..]
            .iter()
            .zip(&mut s1[first..])
            .zip(&mut s2[first..])
        {
            for ch in 0..C {
                y[ch] = c.unit2(&mut a[ch], &mut b[ch], y[ch]);
            }
        }
        y
    }
}
