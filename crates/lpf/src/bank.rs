//! Several channels through one low-pass design, sample by sample.

use crate::cascade::CascadeState;
use crate::lowpass::LowPass;
use crate::section::SectionCoefs;
use gyroemu_core::{Complex64, Response, Sample, Stage};

/// `C` channels through the same [`LowPass`] (the board's I and Q of both modes): each
/// channel's output equals a `LowPass` of its own bit for bit (the same cascade code runs
/// both), but the cascade's shape (section count, first-order section, filter kind) is read
/// once per sample for all channels and each coefficient is loaded once for all of them (the
/// loop control is paid once, not per channel; figures in docs/performance.md).
#[derive(Clone, Debug)]
pub struct LowPassBank<S, const C: usize> {
    proto: LowPass<S>,
    state: CascadeState<S, C>,
}

impl<S: Sample, const C: usize> LowPassBank<S, C> {
    /// `C` channels of `lp`'s design, each in `lp`'s state.
    pub fn new(lp: &LowPass<S>) -> Self {
        let one = &lp.state;
        let state = CascadeState {
            s1: one.s1.map(|[v]| [v; C]),
            s2: one.s2.map(|[v]| [v; C]),
        };
        let mut proto = lp.clone();
        proto.reset();
        Self { proto, state }
    }

    /// The design every channel runs (in its initial state).
    pub fn design(&self) -> &LowPass<S> {
        &self.proto
    }

    /// Lane `lane` of every channel back to rest, as [`Stage::reset`] leaves every lane; the
    /// other lanes keep their bits (a lane refilled with another operating point).
    pub fn reset_lane(&mut self, lane: usize) {
        for s in self.state.s1.iter_mut().chain(self.state.s2.iter_mut()) {
            for v in s.iter_mut() {
                *v = v.with_lane(lane, 0.0);
            }
        }
    }
}

impl<S: Sample, const C: usize> Stage for LowPassBank<S, C> {
    type Input = [S; C];
    type Output = [S; C];

    #[inline(always)]
    fn tick(&mut self, x: [S; C]) -> [S; C] {
        self.proto.cascade.tick(&mut self.state, x)
    }

    fn reset(&mut self) {
        self.state = CascadeState::default();
    }

    fn latency_samples(&self) -> f64 {
        self.proto.latency_samples()
    }
}

impl<S: Sample, const C: usize> Response for LowPassBank<S, C> {
    /// Every channel's response: the design's.
    fn response(&self, f_hz: f64) -> Complex64 {
        self.proto.response(f_hz)
    }
}

/// A [`LowPassBank`] of two biquads (a fourth-order Butterworth, every preset's stage-1
/// low-pass) taken out of the bank for a run of samples ([`LowPassBank::hold_pair`]): in a
/// local the compiler keeps its states in registers from sample to sample, where the bank's
/// states, indexed by a section count known only at run time, go through memory every
/// sample. The same arithmetic as the bank's [`Stage::tick`], bit for bit.
#[derive(Clone, Copy, Debug)]
pub struct BiquadPair<S, const C: usize> {
    gain: S,
    sec: [SectionCoefs<S>; 2],
    s1: [[S; C]; 2],
    s2: [[S; C]; 2],
}

impl<S: Sample, const C: usize> BiquadPair<S, C> {
    /// One sample of every channel, as [`LowPassBank`]'s `tick`. The cascade's biquad loop
    /// with fixed bounds, kept apart on purpose: calling the cascade's loop over slices of
    /// two cost the noiseless chain 8 to 10 % (measured, alternating runs).
    #[allow(clippy::needless_range_loop)] // the channel indexes the input and both states
    #[inline(always)]
    pub fn tick(&mut self, x: [S; C]) -> [S; C] {
        let g = self.gain;
        let mut y = x.map(|v| g * v);
        for k in 0..2 {
            for ch in 0..C {
                y[ch] = self.sec[k].unit2(&mut self.s1[k][ch], &mut self.s2[k][ch], y[ch]);
            }
        }
        y
    }
}

impl<S: Sample, const C: usize> LowPassBank<S, C> {
    /// The bank as a [`BiquadPair`] in its present state, when its design is two biquads
    /// (None otherwise: a lock-in filter, an odd order, or another section count). Give the
    /// states back with [`LowPassBank::release_pair`] before the bank ticks again.
    #[inline(always)]
    pub fn hold_pair(&self) -> Option<BiquadPair<S, C>> {
        let c = &self.proto.cascade;
        c.is_biquads(2).then(|| BiquadPair {
            gain: c.gain(),
            sec: [c.section(0), c.section(1)],
            s1: [self.state.s1[0], self.state.s1[1]],
            s2: [self.state.s2[0], self.state.s2[1]],
        })
    }

    /// Takes back the states a [`BiquadPair`] of this bank ran on to.
    #[inline(always)]
    pub fn release_pair(&mut self, pair: &BiquadPair<S, C>) {
        self.state.s1[..2].copy_from_slice(&pair.s1);
        self.state.s2[..2].copy_from_slice(&pair.s2);
    }
}
