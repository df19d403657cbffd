//! Long weighted averages with compensated summation, and whole-period lengths.

use crate::{KahanSum, STAGE};
use gyroemu_core::detmath::sin_cos_turns;
use gyroemu_core::{ParamError, ParamResult, Sample};

/// Averaging window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Window {
    /// Equal weights: exact over a whole number of periods, leaks ~1/(2 Omega T) otherwise.
    Boxcar,
    /// `w[n] = 0.5 - 0.5 cos(2 pi (n + 0.5)/n_total)`: sidelobes fall as 1/m^3, so a
    /// non-whole number of periods leaks little (THEORY section 7).
    Hann,
}

/// Weighted mean `sum(w x) / sum(w)` of a long stream, with Kahan-compensated sums so that
/// 5e8 samples keep f64 accuracy.
#[derive(Clone, Debug)]
pub struct Averager<S> {
    window: Window,
    n_total: u64,
    count: u64,
    sum: KahanSum<S>,
    wsum: KahanSum<f64>,
}

impl<S: Sample> Averager<S> {
    /// `n_total`: the number of samples that will be averaged (sets the Hann weights; pushes
    /// beyond it continue the weights periodically). Must be >= 1.
    pub fn new(window: Window, n_total: u64) -> ParamResult<Self> {
        if n_total == 0 {
            return Err(ParamError::new(STAGE, "n_total", n_total, "must be >= 1"));
        }
        Ok(Self {
            window,
            n_total,
            count: 0,
            sum: KahanSum::new(),
            wsum: KahanSum::new(),
        })
    }

    /// Adds the next sample with its window weight.
    #[inline]
    pub fn push(&mut self, x: S) {
        match self.window {
            Window::Boxcar => self.sum.add(x),
            Window::Hann => {
                let n = self.count % self.n_total;
                // (n + 0.5)/N is exact enough: n < 2^53; detmath gives the same bits anywhere.
                let (_, c) = sin_cos_turns((n as f64 + 0.5) / self.n_total as f64);
                let w = 0.5 - 0.5 * c;
                self.sum.add(x * S::splat(w));
                self.wsum.add(w);
            }
        }
        self.count += 1;
    }

    /// Number of samples pushed since `new`/`reset`.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The weighted mean so far (zero before the first push).
    pub fn mean(&self) -> S {
        if self.count == 0 {
            return S::default();
        }
        let wsum = match self.window {
            Window::Boxcar => self.count as f64,
            Window::Hann => self.wsum.value(),
        };
        self.sum.value() / S::splat(wsum)
    }

    /// Forgets every sample.
    pub fn reset(&mut self) {
        self.count = 0;
        self.sum.reset();
        self.wsum.reset();
    }
}

/// Number of samples in the largest whole number of half-periods of `f_hz` that fits in
/// `duration_s` at `fs_hz` (a half-period of the modulation is a whole period of the `2 f`
/// products stage 2 averages out). The count is `round(k fs/(2f))` with
/// `k = floor(floor(duration fs) 2f/fs)`; it is exactly whole only when `k fs/(2f)` is an
/// integer (choose `fs/(2f)` integer), otherwise within half a sample of it.
/// If not even one half-period fits, returns every sample of the duration
/// (`floor(duration fs)`, not leak-free); returns 0 for non-finite or non-positive inputs.
pub fn whole_half_periods(f_hz: f64, fs_hz: f64, duration_s: f64) -> u64 {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    if !(ok(f_hz) && ok(fs_hz) && ok(duration_s)) {
        return 0;
    }
    let n_dur = (duration_s * fs_hz).floor();
    let half = fs_hz / (2.0 * f_hz);
    let k = (n_dur / half).floor();
    if k < 1.0 {
        return n_dur as u64;
    }
    ((k * half).round()).min(n_dur) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_half_periods_counts() {
        // 125 Hz at 1 MS/s: half period 4000 samples; 0.1037 s = 103700 samples -> 25 halves.
        assert_eq!(whole_half_periods(125.0, 1e6, 0.1037), 100_000);
        assert_eq!(whole_half_periods(125.0, 1e6, 0.004), 4000);
        assert_eq!(whole_half_periods(125.0, 1e6, 0.0039), 3900);
        assert_eq!(whole_half_periods(0.1, 1e6, 500.0), 500_000_000);
        assert_eq!(whole_half_periods(f64::NAN, 1e6, 1.0), 0);
        assert_eq!(whole_half_periods(1.0, 0.0, 1.0), 0);
    }

    #[test]
    fn n_total_zero_is_an_error() {
        let e = Averager::<f64>::new(Window::Hann, 0).unwrap_err();
        assert_eq!((e.stage, e.param), ("lpf", "n_total"));
        let mut a = Averager::<f64>::new(Window::Hann, 1).unwrap();
        assert_eq!(a.mean(), 0.0);
        a.push(3.0);
        assert_eq!(a.mean(), 3.0); // single sample: weight 1
    }
}
