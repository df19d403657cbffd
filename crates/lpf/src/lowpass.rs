//! A fixed-capacity cascade of low-pass sections.

use crate::cascade::{Cascade, CascadeState};
use crate::design::{sections, LowPassDesign, MAX_ORDER};
use crate::section::Coefs;
use gyroemu_core::detmath::sin_cos_turns;
use gyroemu_core::{Complex64, ParamResult, Response, Sample, Stage};

/// `u = exp(-j 2 pi f/fs) - 1 = -2 sin^2(w/2) - j sin(w)`, accurate near DC.
pub(crate) fn u_of(turns: f64) -> Complex64 {
    let (sh, ch) = sin_cos_turns(0.5 * turns);
    Complex64::new(-2.0 * sh * sh, -2.0 * sh * ch)
}

/// Cascade of up to 8 sections with fixed capacity (no allocation): Butterworth biquads in
/// transposed direct form II, or lock-in RC one-poles.
///
/// The Butterworth sections run with unit numerators `(1 + z^-1)^2` and the product of their
/// gains `g` is applied once, to the input: two fused steps per section instead of five
/// multiplies. At the input (not the output) every intermediate value stays at or below the
/// size it has in a cascade of scaled sections, so the filter keeps its full range.
///
/// Precision note: direct-form sections with poles near `z = 1` lose relative accuracy of
/// order `eps / (2 pi fc/fs)^2` in their DC gain; [`Response`] uses the stored coefficients,
/// so it stays the exact response of the filter as built.
#[derive(Clone, Debug)]
pub struct LowPass<S> {
    pub(crate) cascade: Cascade<S>,
    pub(crate) state: CascadeState<S, 1>,
    coefs: [Coefs; MAX_ORDER],
    fs_hz: f64,
}

impl<S: Sample> LowPass<S> {
    /// Builds the filter at sample rate `fs_hz`; parameter errors name stage `"lpf"`.
    pub fn new(design: LowPassDesign, fs_hz: f64) -> ParamResult<Self> {
        let (one_pole, n, coefs) = sections(design, fs_hz)?;
        Ok(Self {
            cascade: Cascade::new(one_pole, n, &coefs),
            state: CascadeState::default(),
            coefs,
            fs_hz,
        })
    }

    /// Number of sections in use (biquads plus one first-order section for odd Butterworth
    /// orders; N one-poles for a lock-in filter).
    pub fn sections(&self) -> usize {
        self.cascade.sections()
    }

    /// Sample rate the filter was designed for, in Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }
}

impl<S: Sample> Stage for LowPass<S> {
    type Input = S;
    type Output = S;

    #[inline(always)]
    fn tick(&mut self, x: S) -> S {
        let [y] = self.cascade.tick(&mut self.state, [x]);
        y
    }

    fn reset(&mut self) {
        self.state = CascadeState::default();
    }

    /// DC group delay in samples, the sum of the sections'.
    fn latency_samples(&self) -> f64 {
        self.coefs[..self.sections()]
            .iter()
            .map(Coefs::dc_group_delay)
            .sum()
    }
}

impl<S: Sample> Response for LowPass<S> {
    /// Product of the sections' responses at `z = exp(j 2 pi f/fs)`, from the stored
    /// coefficients (exact for the filter as built).
    fn response(&self, f_hz: f64) -> Complex64 {
        let u = u_of(f_hz / self.fs_hz);
        self.coefs[..self.sections()]
            .iter()
            .fold(Complex64::new(1.0, 0.0), |h, c| h * c.response(u))
    }
}
