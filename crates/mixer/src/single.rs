//! The paper's single real mixer (section 5): each channel mixed with its own drive.
//!
//! `out = 2 y r`. For `y = A cos(w0 t - theta)` and `r = cos(w0 t - phi)` (mode 1: `phi = 0`,
//! `r = cos w0 t`; mode 2: `phi = pi/2`, `r = sin w0 t`):
//! `2 y r = A cos(theta - phi) + A cos(2 w0 t - theta - phi)`, so after a unit-DC-gain low-pass
//! the DC is `A cos(theta - phi)`. That is signed in a lag `theta` only when `y` sits 90 degrees
//! off the reference at zero rate (a displacement output at resonance: `theta = pi/2 + theta_c`
//! gives `-A sin theta_c`). With a current (velocity) output, in phase with the drive at
//! resonance, the DC is `A cos theta_c`, even in the Coriolis phase `theta_c` (THEORY section 6):
//! kept only as the paper-style comparison; read the phase with [`crate::Stage1Mixer`] and atan2.

use core::marker::PhantomData;
use gyroemu_core::{Sample, Stage};

/// Real mixer `(y, r) -> 2 y r`, before the low-pass.
#[derive(Clone, Copy, Debug, Default)]
pub struct SingleMixer<S>(PhantomData<S>);

impl<S: Sample> SingleMixer<S> {
    /// Builds the (parameterless) mixer.
    pub fn new() -> Self {
        Self(PhantomData)
    }
}

impl<S: Sample> Stage for SingleMixer<S> {
    /// `(y, r)`: the sensed sample and the mode's own drive reference.
    type Input = (S, S);
    type Output = S;

    #[inline]
    fn tick(&mut self, (y, r): (S, S)) -> S {
        (y + y) * r
    }

    fn reset(&mut self) {}
}
