//! Stage 2: demodulation of the low-passed stage-1 output at the modulation rate Omega
//! (THEORY section 6, rotating excitation).
//!
//! With references `(r_c, r_s) ~ (cos Omega t, sin Omega t)` the outputs are the C-term `2 z r_c`
//! and the S-term `2 z r_s`; averaged over a whole number of half modulation periods they give
//! `C` and `S`, from which [`crate::sideband_estimate`] reads psi and alpha. A common phase shift
//! of `z` and the references leaves psi unchanged, so the low-pass term `-arg L(j Omega)` can be
//! compensated by filtering the references too; the board instead takes the references at the
//! decimated instants and removes the term from the filter's exact response (fewer channels).

use core::marker::PhantomData;
use gyroemu_core::{Sample, Stage};

use crate::Iq;

/// The two stage-2 products of one sample: `c = 2 z r_c`, `s = 2 z r_s`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stage2Out<S> {
    /// C-term `2 z r_c` (average it to get `C`).
    pub c: Iq<S>,
    /// S-term `2 z r_s` (average it to get `S`).
    pub s: Iq<S>,
}

/// Demodulator at Omega: `(z, [r_c, r_s]) -> (2 z r_c, 2 z r_s)`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stage2Mixer<S>(PhantomData<S>);

impl<S: Sample> Stage2Mixer<S> {
    /// Builds the (parameterless) mixer.
    pub fn new() -> Self {
        Self(PhantomData)
    }
}

impl<S: Sample> Stage for Stage2Mixer<S> {
    /// `(z, [r_c, r_s])`: the low-passed stage-1 output and the Omega references.
    type Input = (Iq<S>, [S; 2]);
    type Output = Stage2Out<S>;

    #[inline(always)]
    fn tick(&mut self, (z, [rc, rs]): (Iq<S>, [S; 2])) -> Stage2Out<S> {
        // Doubling is exact, so 2 z r = z (2 r) bit for bit.
        Stage2Out {
            c: z * (rc + rc),
            s: z * (rs + rs),
        }
    }

    fn reset(&mut self) {}
}
