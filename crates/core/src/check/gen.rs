//! Seeded inputs for the checks.

use crate::detmath::sin_cos_turns;
use crate::noise::splitmix64;
use crate::Sample;
use num_complex::Complex64;

/// A seeded pseudo-random source (SplitMix64) that a check hands to the caller's input
/// closure: the same inputs on every run and platform, so a failure reproduces.
#[derive(Clone, Debug)]
pub struct Gen {
    state: u64,
}

impl Gen {
    /// A generator from `seed`.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// The next 64 random bits.
    pub fn u64(&mut self) -> u64 {
        splitmix64(&mut self.state)
    }

    /// Uniform in `[0, 1)`, on the grid of 2^-53.
    pub fn unit(&mut self) -> f64 {
        (self.u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in `[lo, hi)`, independently in every lane of `S`.
    pub fn sample<S: Sample>(&mut self, lo: f64, hi: f64) -> S {
        S::from_fn(|_| self.uniform(lo, hi))
    }

    /// A unit phasor `e^{j phi}` with `phi` uniform over the circle.
    pub fn phasor(&mut self) -> Complex64 {
        let (s, c) = sin_cos_turns(self.unit());
        Complex64::new(c, s)
    }
}
