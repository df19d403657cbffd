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

    /// `sum_k 1 / |A_k(1)|` over the sections: how much a rounding in a section's recursion,
    /// relative to the signal's level, is multiplied at DC on its way out (a narrow section's
    /// states sit near `1 / A(1)` times its input, and each sample rounds them). Times
    /// `f64::EPSILON` it is the order of the relative error the filter's own arithmetic can
    /// leave at DC, channel by channel: about `eps / (2 pi fc/fs)^2` per biquad.
    pub fn rounding_gain(&self) -> f64 {
        self.coefs[..self.sections()]
            .iter()
            .map(|c| 1.0 / c.a_sum().abs())
            .sum()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounding gain of one Butterworth biquad is `1 / A(1)` of the bilinear design,
    /// `(1 + sin w / sqrt 2) / (2 (1 - cos w))`, `w = 2 pi fc/fs`, written from the analogue
    /// prototype (to the coefficients' own rounding, `eps / A(1)` relative); the third order's
    /// pair (Q = 1) `(1 + sin w / 2) / (2 (1 - cos w))` and its first-order section
    /// `(1 + tan(w/2)) / (2 tan(w/2))` add.
    #[test]
    fn rounding_gain_is_the_bilinear_designs_inverse_dc_denominator() {
        let fs = 240_000.0;
        for r in [1e-2, 1e-3, 1e-5, 1e-6] {
            let w = core::f64::consts::TAU * r;
            let biquad = (1.0 + w.sin() / core::f64::consts::SQRT_2) / (2.0 * (1.0 - w.cos()));
            let tol = 1e-9 + 10.0 * f64::EPSILON * biquad;
            let lp = |order| {
                LowPass::<f64>::new(
                    LowPassDesign::Butterworth {
                        order,
                        cutoff_hz: r * fs,
                    },
                    fs,
                )
                .unwrap()
                .rounding_gain()
            };
            let g2 = lp(2);
            assert!(
                (g2 / biquad - 1.0).abs() < tol,
                "fc/fs {r}: {g2} against {biquad}"
            );
            let k = (0.5 * w).tan();
            let third = (1.0 + 0.5 * w.sin()) / (2.0 * (1.0 - w.cos())) + (1.0 + k) / (2.0 * k);
            let g3 = lp(3);
            assert!(
                (g3 / third - 1.0).abs() < tol,
                "fc/fs {r}: {g3} against {third}"
            );
        }
    }
}
