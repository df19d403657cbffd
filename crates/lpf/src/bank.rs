//! Several channels through one low-pass design, sample by sample.

use crate::lowpass::LowPass;
use crate::section::SectionCoefs;
use crate::MAX_ORDER;
use gyroemu_core::{Complex64, Response, Sample, Stage};

/// `C` channels through the same [`LowPass`] (the board's I and Q of both modes): each
/// channel's output equals a `LowPass` of its own bit for bit, but the cascade's shape
/// (section count, first-order section, filter kind) is read once per sample for all
/// channels and each coefficient is loaded once for all of them. Per channel and per sample
/// that removed about 25 instructions of loop control.
#[derive(Clone, Debug)]
pub struct LowPassBank<S, const C: usize> {
    proto: LowPass<S>,
    coefs: [SectionCoefs<S>; MAX_ORDER],
    s1: [[S; C]; MAX_ORDER],
    s2: [[S; C]; MAX_ORDER],
}

impl<S: Sample, const C: usize> LowPassBank<S, C> {
    /// `C` channels of `lp`'s design, each in `lp`'s state.
    pub fn new(lp: &LowPass<S>) -> Self {
        let mut proto = lp.clone();
        let coefs = core::array::from_fn(|k| *proto.sec[k].coefs());
        let s1 = core::array::from_fn(|k| [proto.sec[k].state().0; C]);
        let s2 = core::array::from_fn(|k| [proto.sec[k].state().1; C]);
        proto.reset();
        Self {
            proto,
            coefs,
            s1,
            s2,
        }
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
        let n = self.proto.n;
        let (coefs, s1, s2) = (&self.coefs[..n], &mut self.s1[..n], &mut self.s2[..n]);
        if self.proto.one_pole {
            let mut y = x;
            for (c, s) in coefs.iter().zip(s1) {
                for ch in 0..C {
                    y[ch] = c.one_pole(&mut s[ch], y[ch]);
                }
            }
            return y;
        }
        let g = self.proto.gain;
        let mut y = x.map(|v| g * v);
        let first = usize::from(self.proto.first_order);
        if first == 1 {
            for ch in 0..C {
                y[ch] = coefs[0].unit1(&mut s1[0][ch], y[ch]);
            }
        }
        for ((c, a), b) in coefs[first..]
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

    fn reset(&mut self) {
        self.s1 = [[S::default(); C]; MAX_ORDER];
        self.s2 = [[S::default(); C]; MAX_ORDER];
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
