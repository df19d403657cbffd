//! Stage 1: complex demodulation by the carrier (THEORY section 6).
//!
//! `z = 2 y e^{-j(w0 t + phi)}`, i.e. `I = 2 y cos(w0 t + phi)`, `Q = -2 y sin(w0 t + phi)`, where
//! `e^{j w0 t}` is the NCO's carrier phasor and `phi` a fixed reference phase. The low-pass that
//! removes the `2 w0` image is a separate stage (`gyroemu-lpf`).
//!
//! Sign convention (derived, and asserted in `tests/stage1.rs`): for `y = A cos(w0 t - theta)`,
//! `z = A e^{-j(theta + phi)} + A e^{-j(2 w0 t - theta + phi)}`, so after a unit-DC-gain low-pass
//! `z = A e^{-j(theta + phi)}`: `I = A cos(theta + phi)`, `Q = -A sin(theta + phi)`. A lag `theta`
//! of `y` behind `cos(w0 t - (-phi))` is a negative `arg z`; [`crate::phase_lag_rad`] reads it back.
//! To reference mode 2 to its own drive `sin w0 t = cos(w0 t - pi/2)`, use `phi = -pi/2`: then
//! `y = A sin(w0 t - theta)` gives `z = A e^{-j theta}`.

use core::f64::consts::TAU;
use core::marker::PhantomData;
use gyroemu_core::{detmath, error, Complex64, ParamResult, Sample, Stage};

use crate::Iq;

const STAGE: &str = "mixer.stage1";

/// Carrier demodulator: `(y, e^{j w0 t}) -> 2 y e^{-j(w0 t + phi)}` (before the low-pass).
#[derive(Clone, Debug)]
pub struct Stage1Mixer<S> {
    ref_phase_rad: f64,
    /// `cos phi`, `sin phi` of the reference rotation, computed once. The carrier is one
    /// scalar phasor for all lanes, so the rotation is done in scalar and broadcast once.
    cos_ref: f64,
    sin_ref: f64,
    /// `phi` is exactly 0 (`cos_ref == 1`, `sin_ref == 0`): the rotation is the identity.
    zero_ref: bool,
    _s: PhantomData<S>,
}

impl<S: Sample> Stage1Mixer<S> {
    /// Builds the mixer with reference phase `ref_phase_rad` (`phi`, added to the carrier
    /// phase). Fails on a non-finite phase.
    pub fn new(ref_phase_rad: f64) -> ParamResult<Self> {
        let phi = error::finite(STAGE, "ref_phase_rad", ref_phase_rad)?;
        // Reduce first: detmath is accurate for |x| <= 1e6 only.
        let (s, c) = detmath::sin_cos(phi - TAU * (phi / TAU).round());
        Ok(Self {
            ref_phase_rad: phi,
            cos_ref: c,
            sin_ref: s,
            zero_ref: c == 1.0 && s == 0.0,
            _s: PhantomData,
        })
    }

    /// The reference phase `phi` this mixer was built with, in radians.
    pub fn ref_phase_rad(&self) -> f64 {
        self.ref_phase_rad
    }

    /// The factors `(2 cos(w0 t + phi), -2 sin(w0 t + phi))` that [`Stage::tick`] multiplies
    /// `y` by at carrier phasor `e^{j w0 t}`, broadcast to every lane. Split from the product
    /// ([`Stage1Mixer::mix`]) so that mixers with the same `phi` on the same carrier can share
    /// them (the board's two channels do: this scalar work is then done once per sample).
    #[inline(always)]
    pub fn factors(&self, carrier: Complex64) -> (S, S) {
        let (pc, ps) = (carrier.re, carrier.im);
        // e^{j(w0 t + phi)} = (pc + j ps)(cos phi + j sin phi); for phi = 0 that is the
        // carrier itself (the products by 1 and 0 change no bit of a nonzero value), so the
        // rotation is skipped (a predictable branch instead of four multiplies).
        let (cos_th, sin_th) = if self.zero_ref {
            (pc, ps)
        } else {
            (
                pc * self.cos_ref - ps * self.sin_ref,
                ps * self.cos_ref + pc * self.sin_ref,
            )
        };
        // 2y cos = y (2 cos) and -(2y sin) = y (-2 sin) exactly: doubling (as an add, which
        // is the same bits as the product by 2) and negation do not round.
        (S::splat(cos_th + cos_th), S::splat(-(sin_th + sin_th)))
    }

    /// `y` times the factors of [`Stage1Mixer::factors`]: `tick((y, c)) == mix(y, factors(c))`
    /// bit for bit.
    #[inline(always)]
    pub fn mix(y: S, (f_i, f_q): (S, S)) -> Iq<S> {
        Iq::new(y * f_i, y * f_q)
    }
}

impl<S: Sample> Stage for Stage1Mixer<S> {
    /// `(y, e^{j w0 t})`: the sensed sample and the carrier phasor from the NCO.
    type Input = (S, Complex64);
    type Output = Iq<S>;

    #[inline]
    fn tick(&mut self, (y, carrier): (S, Complex64)) -> Iq<S> {
        Self::mix(y, self.factors(carrier))
    }

    fn reset(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_non_finite_phase() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let e = Stage1Mixer::<f64>::new(bad).unwrap_err();
            assert_eq!(e.param, "ref_phase_rad");
            assert!(e.stage.contains("mixer"));
        }
        assert!(Stage1Mixer::<f64>::new(-1e9).is_ok());
    }

    #[test]
    fn one_sample_by_hand() {
        // y = 1, carrier e^{j pi/2} = j, phi = 0: z = 2 e^{-j pi/2} = -2j.
        let mut m = Stage1Mixer::<f64>::new(0.0).unwrap();
        let z = m.tick((1.0, Complex64::new(0.0, 1.0)));
        assert_eq!((z.i, z.q), (0.0, -2.0));
    }
}
