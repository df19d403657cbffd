//! Several channels through one low-pass design, sample by sample.

use crate::cascade::CascadeState;
use crate::lowpass::LowPass;
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
