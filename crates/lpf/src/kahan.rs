//! Compensated (Kahan) summation, generic over the sample type.

use gyroemu_core::Sample;

/// A running sum with Kahan-style compensation: the error stays `O(eps)` relative to the sum
/// (plus `O(n^2 eps^2)` of the sum of magnitudes) instead of growing with the count, as
/// 5e8 samples at 1 MS/s over 500 s need.
///
/// Form: Knuth's branch-free TwoSum gives the exact rounding error of each addition, which is
/// accumulated apart (the Kahan-Babuska/Neumaier sum without its magnitude test; Ogita-Rump-
/// Oishi "Sum2"). Unlike classic Kahan it stays exact when a term exceeds the running sum,
/// and the loop-carried dependency is one addition (not four), so it pipelines better.
/// Branch-free, so it is generic over `S` and every lane of `f64x4` gives the scalar bits.
/// It relies on IEEE evaluation order: it must never be compiled with fast-math /
/// reassociation, which would simplify the error term to zero.
#[derive(Clone, Copy, Debug, Default)]
pub struct KahanSum<S> {
    sum: S,
    comp: S,
}

impl<S: Sample> KahanSum<S> {
    /// An empty sum (zero).
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `x`.
    #[inline(always)]
    pub fn add(&mut self, x: S) {
        let t = self.sum + x;
        // TwoSum: (sum + x) - t exactly, whatever the magnitudes.
        let z = t - self.sum;
        let err = (self.sum - (t - z)) + (x - z);
        self.comp += err;
        self.sum = t;
    }

    /// The compensated value of the sum.
    #[inline(always)]
    pub fn value(&self) -> S {
        self.sum + self.comp
    }

    /// Back to zero.
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Lane `lane` back to zero, the other lanes untouched.
    pub fn reset_lane(&mut self, lane: usize) {
        self.sum = self.sum.with_lane(lane, 0.0);
        self.comp = self.comp.with_lane(lane, 0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_when_a_term_exceeds_the_running_sum() {
        // classic Kahan loses the 1.0 here; the TwoSum form keeps it
        let mut k = KahanSum::<f64>::new();
        for x in [1.0, 1e100, 1.0, -1e100] {
            k.add(x);
        }
        assert_eq!(k.value(), 2.0);
    }

    #[test]
    fn recovers_what_a_naive_sum_drops() {
        // 1 + 1e-16 * 1e4: the naive sum drops every small term.
        let mut k = KahanSum::<f64>::new();
        let mut naive = 0.0;
        k.add(1.0);
        naive += 1.0;
        for _ in 0..10_000 {
            k.add(1e-16);
            naive += 1e-16;
        }
        assert_eq!(naive, 1.0);
        assert!((k.value() - (1.0 + 1e-12)).abs() < 1e-16);
        k.reset();
        assert_eq!(k.value(), 0.0);
    }
}
