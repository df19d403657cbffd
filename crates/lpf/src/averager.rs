//! The board's final average: weighted means of several channels over long windows, one window
//! per lane, with compensated sums (THEORY section 7: 5e8 samples keep f64 accuracy).

use crate::{KahanSum, STAGE};
use gyroemu_core::detmath::sin_cos_turns;
use gyroemu_core::{Complex64, ParamError, ParamResult, Sample};

/// Most lanes an [`Averager`] serves (the widest sample type).
pub const MAX_LANES: usize = 8;

/// The weights of one lane's averaging window over samples `j = 0, 1, ...`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Window {
    /// Weight 1 on samples `0 .. n` and `frac` (in [0, 1)) on sample `n`: a window of exactly
    /// `n + frac` samples, the fractional end of a whole number of half periods (a boxcar over
    /// whole periods is exact; a non-whole number leaks about 1/(2 Omega T)).
    Boxcar {
        /// Whole samples of weight 1.
        n: u64,
        /// Weight of sample `n`.
        frac: f64,
    },
    /// Hann weights `sin^2(pi (j + 1/2) / n)` on samples `0 .. n`: sidelobes fall as 1/m^3, so
    /// a non-whole number of periods leaks little.
    Hann {
        /// Samples in the window.
        n: u64,
    },
}

impl Window {
    /// Weight of sample `j` (0 outside the window).
    #[inline]
    pub fn weight(&self, j: u64) -> f64 {
        match *self {
            Window::Boxcar { n, .. } | Window::Hann { n } if j > n => 0.0,
            Window::Hann { n } if j == n => 0.0,
            Window::Hann { n } => {
                let (s, _) = sin_cos_turns(0.5 * (j as f64 + 0.5) / n as f64);
                s * s
            }
            Window::Boxcar { n, frac } if j == n => frac,
            Window::Boxcar { .. } => 1.0,
        }
    }

    /// Samples after which every weight is zero: `n + 1` (the fractional sample of a boxcar,
    /// or the zero end of a Hann window, is pushed too).
    pub fn samples(&self) -> u64 {
        match *self {
            // Saturating: a config's window is sized before validation bounds it.
            Window::Boxcar { n, .. } | Window::Hann { n } => n.saturating_add(1),
        }
    }

    /// The averaged span in samples (`n + frac` for a boxcar, `n` for Hann).
    pub fn span(&self) -> f64 {
        match *self {
            Window::Boxcar { n, frac } => n as f64 + frac,
            Window::Hann { n } => n as f64,
        }
    }

    /// The window's normalised response to a tone of `cycles` cycles per sample,
    /// `sum_j w_j e^{-j 2 pi cycles j} / sum_j w_j`, in closed form (geometric sums, so a
    /// window of 1e9 samples costs the same as one of ten): what the average keeps of a
    /// component that is not at DC.
    pub fn response(&self, cycles: f64) -> Complex64 {
        match *self {
            Window::Boxcar { n, frac } => {
                let (s, c) = sin_cos_turns((cycles * n as f64).rem_euclid(1.0));
                (geometric(cycles, n) + Complex64::new(c, -s) * frac) / (n as f64 + frac)
            }
            Window::Hann { n } => {
                // sin^2(pi (j + 1/2)/n) = 1/2 - (e^{i 2 pi (j + 1/2)/n} + conj) / 4.
                let step = 1.0 / n as f64;
                let (s, c) = sin_cos_turns(0.5 * step);
                let half = Complex64::new(c, s);
                let sum = 0.5 * geometric(cycles, n)
                    - 0.25
                        * (half * geometric(cycles - step, n)
                            + half.conj() * geometric(cycles + step, n));
                let weights: f64 = if n == 1 { 1.0 } else { 0.5 * n as f64 };
                sum / weights
            }
        }
    }

    /// Refuses a window no averager takes (a boxcar's `frac` outside [0, 1), a Hann window of
    /// no samples), naming the rule.
    pub fn check(&self) -> ParamResult<()> {
        match *self {
            Window::Boxcar { frac, .. } if !(0.0..1.0).contains(&frac) => Err(ParamError::new(
                STAGE,
                "window.frac",
                frac,
                "must be in [0, 1)",
            )),
            Window::Hann { n: 0 } => Err(ParamError::new(STAGE, "window.n", 0, "must be >= 1")),
            _ => Ok(()),
        }
    }
}

/// `sum_{j < n} e^{-i 2 pi t j}` = e^{-i pi t (n - 1)} sin(pi n t) / sin(pi t), with t taken
/// to the nearest whole turn first (so whole turns give exactly n).
fn geometric(turns: f64, n: u64) -> Complex64 {
    let t = turns - turns.round();
    if t == 0.0 {
        return Complex64::new(n as f64, 0.0);
    }
    let (num, _) = sin_cos_turns((0.5 * t * n as f64).rem_euclid(1.0));
    let (den, _) = sin_cos_turns(0.5 * t);
    let (s, c) = sin_cos_turns((0.5 * t * (n as f64 - 1.0)).rem_euclid(1.0));
    Complex64::new(c, -s) * (num / den)
}

/// Weighted means `sum(w x) / sum(w)` of up to `C` channels, each lane with its own
/// [`Window`] (the board averages four or eight operating points at once, each over its own
/// number of modulation periods). The weighted values are summed with [`KahanSum`]; the
/// weights with a plain sum (whole ones for a boxcar, so exact; a Hann weight sum only scales
/// every channel of a lane alike). Every lane of `f64x4` gives the bits of an `f64` averager
/// fed that lane alone.
#[derive(Clone, Debug)]
pub struct Averager<S, const C: usize> {
    windows: [Window; MAX_LANES],
    lanes: usize,
    channels: usize,
    j: u64,
    /// Each lane's first sample: its window's sample 0 is pushed sample `from[i]` (0 but in a
    /// lane restarted by [`Averager::restart_lane`]).
    from: [u64; MAX_LANES],
    acc: [KahanSum<S>; C],
    wsum: [f64; MAX_LANES],
}

impl<S: Sample, const C: usize> Averager<S, C> {
    /// An averager of the first `channels` (at most `C`) channels, lane `i` weighted by
    /// `windows[i]` (lanes beyond `windows.len()` repeat its last window). Needs 1 to
    /// `S::LANES` windows, each valid.
    pub fn new(windows: &[Window], channels: usize) -> ParamResult<Self> {
        if windows.is_empty() || windows.len() > S::LANES.min(MAX_LANES) {
            return Err(ParamError::new(
                STAGE,
                "windows",
                windows.len(),
                format!("must list 1 to {} lane windows", S::LANES.min(MAX_LANES)),
            ));
        }
        if channels > C {
            return Err(ParamError::new(
                STAGE,
                "channels",
                channels,
                format!("must be at most {C}"),
            ));
        }
        windows.iter().try_for_each(Window::check)?;
        let last = windows[windows.len() - 1];
        Ok(Self {
            windows: core::array::from_fn(|i| windows.get(i).copied().unwrap_or(last)),
            lanes: windows.len(),
            channels,
            j: 0,
            from: [0; MAX_LANES],
            acc: core::array::from_fn(|_| KahanSum::default()),
            wsum: [0.0; MAX_LANES],
        })
    }

    /// Lane `lane` starts over with `window`, its sample 0 the sample pushed at index
    /// `from` (at or after the next one, [`Averager::count`]): its sums go back to zero, and
    /// until `from` it weighs every sample 0. Adding a zero leaves a compensated sum's value
    /// as it is, so the lane then holds the bits of a fresh averager fed from `from` on (a
    /// lane of the board refilled with another operating point). The other lanes keep their
    /// bits. Refused (changing nothing) for a lane past the averager's, an invalid window or a
    /// `from` already pushed.
    pub fn restart_lane(&mut self, lane: usize, window: Window, from: u64) -> ParamResult<()> {
        if lane >= self.lanes {
            return Err(ParamError::new(
                STAGE,
                "lane",
                lane,
                format!("must be below the averager's lanes ({})", self.lanes),
            ));
        }
        if from < self.j {
            return Err(ParamError::new(
                STAGE,
                "from",
                from,
                format!("must not precede the next sample ({})", self.j),
            ));
        }
        window.check()?;
        self.windows[lane] = window;
        self.from[lane] = from;
        for acc in &mut self.acc {
            acc.reset_lane(lane);
        }
        self.wsum[lane] = 0.0;
        Ok(())
    }

    /// Samples pushed so far (the index `j` of the next one).
    pub fn count(&self) -> u64 {
        self.j
    }

    /// Adds the next sample of every channel with each lane's weight.
    #[inline(always)]
    pub fn push(&mut self, x: &[S; C]) {
        let (j, w, from) = (self.j, &self.windows, &self.from);
        let weight = S::from_fn(|i| match j.checked_sub(from[i]) {
            Some(local) => w[i].weight(local),
            None => 0.0,
        });
        for i in 0..self.lanes {
            self.wsum[i] += weight.lane(i);
        }
        for (acc, &x) in self.acc.iter_mut().zip(x).take(self.channels) {
            acc.add(weight * x);
        }
        self.j += 1;
    }

    /// The weighted mean of every channel of `lane` so far (NaN before any weight).
    pub fn mean(&self, lane: usize) -> [f64; C] {
        core::array::from_fn(|c| self.acc[c].value().lane(lane) / self.wsum[lane])
    }

    /// The boxcar mean of `lane` as if its window had been `n` whole samples and `frac` of
    /// the next, where `n` is [`Averager::count`] (the samples pushed) and `x` the next
    /// sample: the same average over a shorter time, read on the way to the full window (the
    /// averaging-time analysis). Meaningful for boxcar lanes only.
    pub fn mean_if_ended(&self, lane: usize, frac: f64, x: &[S; C]) -> [f64; C] {
        let n = self.j as f64;
        core::array::from_fn(|c| {
            (self.acc[c].value().lane(lane) + frac * x[c].lane(lane)) / (n + frac)
        })
    }

    /// Forgets every sample (the windows stay; every lane starts at sample 0 again).
    pub fn reset(&mut self) {
        self.j = 0;
        self.from = [0; MAX_LANES];
        self.acc = core::array::from_fn(|_| KahanSum::default());
        self.wsum = [0.0; MAX_LANES];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_windows_are_refused_with_the_rule() {
        let e = Averager::<f64, 2>::new(&[Window::Hann { n: 0 }], 2).unwrap_err();
        assert_eq!((e.stage, e.param), ("lpf", "window.n"));
        let e = Averager::<f64, 2>::new(&[Window::Boxcar { n: 3, frac: 1.0 }], 2).unwrap_err();
        assert_eq!(e.param, "window.frac");
        assert!(Averager::<f64, 2>::new(&[], 2).is_err());
        let two = [Window::Hann { n: 4 }; 2];
        assert!(
            Averager::<f64, 2>::new(&two, 2).is_err(),
            "f64 has one lane"
        );
        assert!(Averager::<f64, 2>::new(&two[..1], 3).is_err());
    }

    #[test]
    fn samples_is_one_past_the_window_and_saturates_at_the_top() {
        assert_eq!(Window::Boxcar { n: 7, frac: 0.5 }.samples(), 8);
        assert_eq!(Window::Hann { n: 7 }.samples(), 8);
        // A config's window is sized (as `f64 as u64`, saturating) before validation bounds
        // it; wrapping to 0 there would make a huge run look empty.
        assert_eq!(
            Window::Boxcar {
                n: u64::MAX,
                frac: 0.0
            }
            .samples(),
            u64::MAX
        );
        assert_eq!(Window::Hann { n: u64::MAX }.samples(), u64::MAX);
    }

    #[test]
    fn single_sample_windows() {
        let mut a = Averager::<f64, 1>::new(&[Window::Boxcar { n: 1, frac: 0.0 }], 1).unwrap();
        assert!(a.mean(0)[0].is_nan());
        a.push(&[3.0]);
        a.push(&[5.0]); // weight frac = 0
        assert_eq!(a.mean(0), [3.0]);
        assert_eq!(a.count(), 2);
    }
}
