//! The board's phase shifter: a fixed rotation of the carrier phasor.

use gyroemu_core::{detmath, error, ParamResult, Stage};
use num_complex::Complex64;

/// Delays a phasor by `shift_rad`: `output = input * e^{-j shift_rad}`, so
/// `Re(output) = cos(phi - shift)`. The nominal board shifter is +90 degrees (turns the
/// `cos w0t` drive into the `sin w0t` drive); a shifter error is just another shift.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseShifter {
    rot: Complex64,
}

impl PhaseShifter {
    /// A shifter of `shift_rad` radians (finite; any value, reduced modulo 2 pi).
    pub fn new(shift_rad: f64) -> ParamResult<Self> {
        let s = error::finite("phase_shifter", "shift_rad", shift_rad)?;
        let (sin, cos) = detmath::sin_cos(s % core::f64::consts::TAU);
        Ok(Self {
            rot: Complex64::new(cos, -sin),
        })
    }

    /// The exact 90-degree shifter (`rot = -j`), mapping `cos phi` to `sin phi` bit for bit.
    pub fn quadrature() -> Self {
        Self {
            rot: Complex64::new(0.0, -1.0),
        }
    }

    /// The rotation `e^{-j shift}` applied to every input.
    pub fn rotation(&self) -> Complex64 {
        self.rot
    }

    /// `p * e^{-j shift}`.
    #[inline]
    pub fn apply(&self, p: Complex64) -> Complex64 {
        p * self.rot
    }
}

impl Stage for PhaseShifter {
    type Input = Complex64;
    type Output = Complex64;

    #[inline]
    fn tick(&mut self, x: Complex64) -> Complex64 {
        self.apply(x)
    }

    fn reset(&mut self) {}
}
