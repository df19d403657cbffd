//! The PLL's parameters and their validation.

use crate::STAGE;
use core::f64::consts::{PI, TAU};
use gyroemu_core::error::{finite, non_negative, positive};
use gyroemu_core::{ParamError, ParamResult};

/// The largest natural frequency, as a fraction of the update rate: the design is exact for
/// the sampled loop, but the model behind it also takes the new frequency to start right
/// after the phase is sampled (it starts one input sample later) and the phase to move by
/// much less than a turn per update; both hold comfortably below a tenth of the update rate.
pub const MAX_NATURAL_PER_UPDATE: f64 = 0.1;

/// The largest phase lag, in rad, that the demodulation low-pass's DC group delay `d` may add
/// at the loop's natural frequency (`wn d`). The design leaves the low-pass out of the loop
/// model, which delays the loop's reaction by about `d`: the step response departs from the
/// second-order model by about `Kp d <= 2 zeta wn d` of the step (measured on the chain of
/// tests/closed_loop.rs: 1.1 % at `wn d = 0.013`, 4.4 % and 1 point more overshoot at
/// `wn d = 0.047`, `zeta = 0.7`); beyond this bound it is no longer the loop asked for.
pub const MAX_LOWPASS_LAG_RAD: f64 = 0.05;

/// Everything that defines a carrier PLL (see the crate docs for the loop they define).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PllParams {
    /// The nominal carrier, Hz: the NCO frequency with no correction (finite).
    pub carrier_hz: f64,
    /// The rate of [`gyroemu_core::Stage::tick`] (the decimated rate of the demodulated
    /// output), Hz, finite and > 0.
    pub update_rate_hz: f64,
    /// The loop's natural frequency `fn = wn / 2 pi`, Hz: the closed-loop poles are
    /// `s = -zeta wn +- wn sqrt(zeta^2 - 1)` (not the noise bandwidth; that is
    /// [`crate::Pll::noise_bandwidth_hz`]). Finite, > 0, at most
    /// [`MAX_NATURAL_PER_UPDATE`] x `update_rate_hz`, and with `wn lowpass_delay_s` at most
    /// [`MAX_LOWPASS_LAG_RAD`].
    pub natural_hz: f64,
    /// The loop's damping ratio `zeta`, finite and > 0, with `2 zeta wn tau_s >= 1` (below, the
    /// envelope alone damps the loop more than asked and the proportional gain would be
    /// negative).
    pub damping: f64,
    /// The locked mode's envelope (amplitude) time constant `tau = 2 Q / w0 = Q / (pi f0)`, s,
    /// finite and > 0 ([`PllParams::tau_s_of`]).
    pub tau_s: f64,
    /// The chain's phase at the carrier when locked, rad (finite): `arg z` of the demodulated
    /// output at resonance, i.e. the DAC hold, the TIA (inversion and pole) and any other
    /// stage between the drive and the mixer. The detector measures `arg z - phase_offset_rad`.
    pub phase_offset_rad: f64,
    /// The DC group delay of the demodulation low-pass, s (finite, >= 0; 0 for none): only to
    /// refuse a loop too fast for it (`LowPass::latency_samples() / fs`).
    pub lowpass_delay_s: f64,
    /// Lowest frequency the PLL may command, Hz (`None`: no limit). Below `carrier_hz`.
    pub min_hz: Option<f64>,
    /// Highest frequency the PLL may command, Hz (`None`: no limit). Above `carrier_hz`.
    pub max_hz: Option<f64>,
    /// Lock: `|phase error|` below this, rad, in `(0, pi]` ...
    pub lock_threshold_rad: f64,
    /// ... for this many consecutive updates (>= 1), with a signal and no limit reached.
    pub lock_updates: u32,
    /// `|z|` at or below this (finite, >= 0) counts as no signal: the PLL holds its frequency
    /// and is not locked (a dead channel must not look locked).
    pub min_amplitude: f64,
}

impl PllParams {
    /// The parameters with the defaults for the rest: no phase offset, no low-pass, no
    /// limits, lock within 0.05 rad for one natural period (`update_rate / natural`
    /// updates, at least 1), any nonzero amplitude a signal.
    pub fn new(
        carrier_hz: f64,
        update_rate_hz: f64,
        natural_hz: f64,
        damping: f64,
        tau_s: f64,
    ) -> Self {
        let period = (update_rate_hz / natural_hz).round();
        Self {
            carrier_hz,
            update_rate_hz,
            natural_hz,
            damping,
            tau_s,
            phase_offset_rad: 0.0,
            lowpass_delay_s: 0.0,
            min_hz: None,
            max_hz: None,
            lock_threshold_rad: 0.05,
            lock_updates: if period.is_finite() && period >= 1.0 {
                period.min(u32::MAX as f64) as u32
            } else {
                1
            },
            min_amplitude: 0.0,
        }
    }

    /// The envelope time constant `Q / (pi f0)` of a mode at `f0_hz` with quality `q`, s.
    pub fn tau_s_of(f0_hz: f64, q: f64) -> f64 {
        q / (PI * f0_hz)
    }

    /// Checks every parameter; the error names the first bad one, its value and the rule.
    pub fn validate(&self) -> ParamResult<()> {
        let carrier = finite(STAGE, "carrier_hz", self.carrier_hz)?;
        validate_loop(
            STAGE,
            self.update_rate_hz,
            self.natural_hz,
            self.damping,
            self.tau_s,
            self.lowpass_delay_s,
        )?;
        finite(STAGE, "phase_offset_rad", self.phase_offset_rad)?;
        if let Some(lo) = self.min_hz {
            if !(lo.is_finite() && lo < carrier) {
                return Err(ParamError::new(
                    STAGE,
                    "min_hz",
                    lo,
                    format!("must be finite and below carrier_hz = {carrier} Hz"),
                ));
            }
        }
        if let Some(hi) = self.max_hz {
            if !(hi.is_finite() && hi > carrier) {
                return Err(ParamError::new(
                    STAGE,
                    "max_hz",
                    hi,
                    format!("must be finite and above carrier_hz = {carrier} Hz"),
                ));
            }
        }
        let th = self.lock_threshold_rad;
        if !(th.is_finite() && th > 0.0 && th <= PI) {
            return Err(ParamError::new(
                STAGE,
                "lock_threshold_rad",
                th,
                "must be finite, > 0 and <= pi",
            ));
        }
        if self.lock_updates == 0 {
            return Err(ParamError::new(STAGE, "lock_updates", 0, "must be >= 1"));
        }
        non_negative(STAGE, "min_amplitude", self.min_amplitude)?;
        Ok(())
    }
}

/// Checks the parameters of a loop around the envelope (the PLL's and the AGC's): rate,
/// natural frequency, damping and time constant finite and positive, the low-pass delay
/// finite and not negative, and the three design rules (natural frequency against the update
/// rate and the low-pass, `2 zeta wn tau >= 1`). Errors name `stage`.
pub(crate) fn validate_loop(
    stage: &'static str,
    update_rate_hz: f64,
    natural_hz: f64,
    damping: f64,
    tau_s: f64,
    lowpass_delay_s: f64,
) -> ParamResult<()> {
    let rate = positive(stage, "update_rate_hz", update_rate_hz)?;
    let fnat = positive(stage, "natural_hz", natural_hz)?;
    let zeta = positive(stage, "damping", damping)?;
    let tau = positive(stage, "tau_s", tau_s)?;
    let delay = non_negative(stage, "lowpass_delay_s", lowpass_delay_s)?;
    if fnat > MAX_NATURAL_PER_UPDATE * rate {
        return Err(ParamError::new(
            stage,
            "natural_hz",
            fnat,
            format!(
                "must be at most {MAX_NATURAL_PER_UPDATE} x update_rate_hz = {} Hz (the loop \
                 would react within a few updates)",
                MAX_NATURAL_PER_UPDATE * rate
            ),
        ));
    }
    let wn = TAU * fnat;
    if wn * delay > MAX_LOWPASS_LAG_RAD {
        return Err(ParamError::new(
            stage,
            "natural_hz",
            fnat,
            format!(
                "must be at most {MAX_LOWPASS_LAG_RAD} / (2 pi lowpass_delay_s) = {} Hz: the \
                 demodulation low-pass (DC group delay {delay} s) would lag the loop by more \
                 than {MAX_LOWPASS_LAG_RAD} rad at its natural frequency and change its \
                 damping; lower natural_hz or raise the low-pass cutoff",
                MAX_LOWPASS_LAG_RAD / (TAU * delay)
            ),
        ));
    }
    if 2.0 * zeta * wn * tau < 1.0 {
        return Err(ParamError::new(
            stage,
            "natural_hz",
            fnat,
            format!(
                "natural_hz x damping must be at least 1 / (4 pi tau_s) = {} Hz (damping \
                 {zeta}, tau_s {tau} s): the resonator's envelope alone damps the loop more \
                 than asked, the proportional gain would be negative; raise natural_hz or \
                 damping",
                1.0 / (2.0 * TAU * tau)
            ),
        ));
    }
    Ok(())
}
