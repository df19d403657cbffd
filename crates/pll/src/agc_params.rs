//! The AGC's parameters and their validation.

use crate::params::validate_loop;
use gyroemu_core::error::{finite, non_negative, positive};
use gyroemu_core::{ParamError, ParamResult};

/// The stage name in the AGC's parameter errors.
pub const AGC_STAGE: &str = "agc";

/// Everything that defines a drive-amplitude AGC (see [`crate::Agc`] for the loop).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgcParams {
    /// The rate of [`gyroemu_core::Stage::tick`] (the decimated rate), Hz, finite and > 0.
    pub update_rate_hz: f64,
    /// The loop's natural frequency `wn / 2 pi`, Hz (as [`crate::PllParams::natural_hz`], with
    /// the same rules).
    pub natural_hz: f64,
    /// The loop's damping ratio, finite and > 0, with `2 zeta wn tau_s >= 1`.
    pub damping: f64,
    /// The locked mode's envelope time constant `Q / (pi f0)`, s, finite and > 0.
    pub tau_s: f64,
    /// The DC group delay of the demodulation low-pass, s (finite, >= 0), only to refuse a
    /// loop too fast for it.
    pub lowpass_delay_s: f64,
    /// The `|z|` to hold, in the units of the demodulated output (finite, > 0).
    pub setpoint: f64,
    /// The drive gain before the first update (the output with no correction), finite, > 0.
    pub initial_gain: f64,
    /// The largest drive gain (e.g. the DAC's full scale over the nominal drive), finite and
    /// above `initial_gain`: from rest the amplitude is far below the setpoint and the loop
    /// asks for all it can get.
    pub max_gain: f64,
    /// The smallest drive gain, finite, >= 0 and below `initial_gain` (0: no floor).
    pub min_gain: f64,
    /// `|z|` at or below this (finite, >= 0) counts as no signal: the AGC holds its gain.
    pub min_amplitude: f64,
}

impl AgcParams {
    /// The parameters with the defaults for the rest: no low-pass, initial gain 1, gain
    /// between 0 and `max_gain`, any nonzero amplitude a signal.
    pub fn new(
        update_rate_hz: f64,
        natural_hz: f64,
        damping: f64,
        tau_s: f64,
        setpoint: f64,
        max_gain: f64,
    ) -> Self {
        Self {
            update_rate_hz,
            natural_hz,
            damping,
            tau_s,
            lowpass_delay_s: 0.0,
            setpoint,
            initial_gain: 1.0,
            max_gain,
            min_gain: 0.0,
            min_amplitude: 0.0,
        }
    }

    /// Checks every parameter; the error names the first bad one, its value and the rule.
    pub fn validate(&self) -> ParamResult<()> {
        validate_loop(
            AGC_STAGE,
            self.update_rate_hz,
            self.natural_hz,
            self.damping,
            self.tau_s,
            self.lowpass_delay_s,
        )?;
        positive(AGC_STAGE, "setpoint", self.setpoint)?;
        let g0 = positive(AGC_STAGE, "initial_gain", self.initial_gain)?;
        let hi = finite(AGC_STAGE, "max_gain", self.max_gain)?;
        if hi <= g0 {
            return Err(ParamError::new(
                AGC_STAGE,
                "max_gain",
                hi,
                format!("must be above initial_gain = {g0}"),
            ));
        }
        let lo = non_negative(AGC_STAGE, "min_gain", self.min_gain)?;
        if lo >= g0 {
            return Err(ParamError::new(
                AGC_STAGE,
                "min_gain",
                lo,
                format!("must be below initial_gain = {g0}"),
            ));
        }
        non_negative(AGC_STAGE, "min_amplitude", self.min_amplitude)?;
        Ok(())
    }
}
