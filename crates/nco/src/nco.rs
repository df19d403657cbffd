//! The oscillator: a 64-bit phase accumulator and its phasor.

use crate::trig::{phasor_with, table, Table};
use crate::word::{ratio_to_word, turns_of_word};
use gyroemu_core::{error, ParamError, ParamResult, Stage};
use num_complex::Complex64;

const STAGE: &str = "nco";
const TWO_POW_64: f64 = 18_446_744_073_709_551_616.0;

/// A numerically controlled oscillator. Each [`Stage::tick`] returns `e^{j phase}` and then
/// advances the phase by one step; the phase is an integer word (2^-64 turn units), so it
/// never drifts and [`Nco::jump`] lands exactly where the same number of ticks would.
#[derive(Clone, Debug)]
pub struct Nco {
    phase: u64,
    step: u64,
    phase0: u64,
    step0: u64,
    fs_hz: f64,
    table: &'static Table,
}

impl Nco {
    /// An oscillator at `f_hz` (signed; 0 allowed; `|f_hz| < fs_hz/2`) sampled at `fs_hz`
    /// (finite, > 0), starting at `phase_rad` (finite). The step word is the exact nearest
    /// integer to `f_hz / fs_hz * 2^64`, so the realised frequency is within `fs/2^65` of the
    /// request.
    pub fn new(f_hz: f64, fs_hz: f64, phase_rad: f64) -> ParamResult<Self> {
        let fs_hz = error::positive(STAGE, "fs_hz", fs_hz)?;
        let step = step_of(f_hz, fs_hz)?;
        let phase_rad = error::finite(STAGE, "phase_rad", phase_rad)?;
        let turns = phase_rad.rem_euclid(core::f64::consts::TAU) / core::f64::consts::TAU;
        // turns is in [0, 1]; 1 maps to word 2^64 = 0 by the truncating cast.
        let phase0 = (turns * TWO_POW_64).round() as u128 as u64;
        Ok(Self {
            phase: phase0,
            step,
            phase0,
            step0: step,
            fs_hz,
            table: table(),
        })
    }

    /// The realised (step-quantised) frequency, signed, in Hz.
    pub fn f_hz(&self) -> f64 {
        (self.step as i64) as f64 * (self.fs_hz / TWO_POW_64)
    }

    /// The sample rate in Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// The phase increment per sample, in 2^-64 turn.
    pub fn step_word(&self) -> u64 {
        self.step
    }

    /// The current phase, in 2^-64 turn.
    pub fn phase_word(&self) -> u64 {
        self.phase
    }

    /// The current phase in radians, in `[0, 2 pi)`.
    pub fn phase_rad(&self) -> f64 {
        turns_of_word(self.phase) * core::f64::consts::TAU
    }

    /// Changes the frequency to `f_hz` (finite, `|f_hz| < fs_hz/2`) from the next tick on,
    /// with the phase continuous: only the step word is replaced (by the exact nearest word,
    /// as in [`Nco::new`]), the phase accumulator is kept. So the next output is the phasor
    /// the old frequency would have given, and every later one advances by the new step.
    /// A bad frequency is refused and changes nothing. [`Stage::reset`] restores the
    /// frequency the oscillator was built with.
    pub fn set_frequency_hz(&mut self, f_hz: f64) -> ParamResult<()> {
        self.step = step_of(f_hz, self.fs_hz)?;
        Ok(())
    }

    /// Advances exactly `n_samples` steps at once (wrapping integer arithmetic).
    pub fn jump(&mut self, n_samples: u64) {
        self.phase = self.phase.wrapping_add(self.step.wrapping_mul(n_samples));
    }

    /// `e^{j phase}` at the current phase, without advancing.
    #[inline]
    pub fn phasor(&self) -> Complex64 {
        phasor_with(self.table, self.phase)
    }
}

impl Stage for Nco {
    type Input = ();
    type Output = Complex64;

    /// `e^{j phase}` (re = cos, im = sin) at the current phase, then one step forward.
    #[inline]
    fn tick(&mut self, _x: ()) -> Complex64 {
        let p = phasor_with(self.table, self.phase);
        self.phase = self.phase.wrapping_add(self.step);
        p
    }

    /// Back to the start phase and the frequency the oscillator was built with.
    fn reset(&mut self) {
        self.phase = self.phase0;
        self.step = self.step0;
    }
}

/// The step word of `f_hz` at `fs_hz` (`fs_hz` already checked), refusing a non-finite
/// frequency or one at or above Nyquist.
pub(crate) fn step_of(f_hz: f64, fs_hz: f64) -> ParamResult<u64> {
    let f_hz = error::finite(STAGE, "f_hz", f_hz)?;
    if f_hz.abs() >= 0.5 * fs_hz {
        return Err(ParamError::new(
            STAGE,
            "f_hz",
            f_hz,
            format!("|f_hz| must be below Nyquist (fs/2 = {} Hz)", 0.5 * fs_hz),
        ));
    }
    Ok(ratio_to_word(f_hz, fs_hz) as u64)
}
