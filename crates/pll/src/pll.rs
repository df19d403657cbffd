//! The PLL stage: phase detector, PI loop filter, frequency limits and lock detection.

use crate::design::{noise_bandwidth_hz, LoopDesign};
use crate::pi::Pi;
use crate::PllParams;
use core::f64::consts::TAU;
use gyroemu_core::detmath::sin_cos;
use gyroemu_core::{Complex64, ParamResult, Response, Stage};

/// A carrier PLL, ticked once per demodulated (decimated) output sample: input the complex
/// baseband `z` of the locked mode, output the frequency the carrier NCO must run at for the
/// next update (Hz, absolute: `carrier_hz` plus the correction).
///
/// Each tick: the phase error `e = arg(z e^{-j phase_offset})` in `(-pi, pi]`; the integrator
/// `I += Ki T e`; the output `carrier_hz + (Kp e + I) / 2 pi`, clamped to the limits (the
/// integrator is held while the output sits on a limit and the error pushes it further:
/// no wind-up). An input with `|z| <= min_amplitude` or a non-finite part carries no phase:
/// the PLL holds its frequency and integrator and drops lock.
///
/// Timing contract: the output of tick `k` is meant for the samples after the one `z_k`
/// was taken at (the board applies it from the next decimation block); the gains are
/// designed for exactly that (crate docs).
#[derive(Clone, Debug)]
pub struct Pll {
    params: PllParams,
    design: LoopDesign,
    /// `e^{-j phase_offset}`, computed once with `detmath`.
    derot: Complex64,
    min_hz: f64,
    max_hz: f64,
    // State.
    /// The PI filter, in rad/s of carrier per rad of phase error.
    pi: Pi,
    out_hz: f64,
    error_rad: f64,
    run: u32,
    limited: bool,
    signal: bool,
}

impl Pll {
    /// Builds the PLL; every parameter is checked first (stage `"pll"`).
    pub fn new(params: &PllParams) -> ParamResult<Self> {
        params.validate()?;
        let p = *params;
        let phi = p.phase_offset_rad % TAU;
        let (s, c) = sin_cos(phi);
        let design = LoopDesign::new(p.natural_hz, p.damping, p.tau_s, p.update_rate_hz);
        Ok(Self {
            params: p,
            design,
            derot: Complex64::new(c, -s),
            min_hz: p.min_hz.unwrap_or(f64::NEG_INFINITY),
            max_hz: p.max_hz.unwrap_or(f64::INFINITY),
            pi: Pi::new(design.kp_per_s, design.ki_t_per_s),
            out_hz: p.carrier_hz,
            error_rad: 0.0,
            run: 0,
            limited: false,
            signal: false,
        })
    }

    /// The parameters the PLL was built from.
    pub fn params(&self) -> &PllParams {
        &self.params
    }

    /// The loop design: gains `Kp`, `Ki T` and the closed-loop poles.
    pub fn design(&self) -> &LoopDesign {
        &self.design
    }

    /// The one-sided noise bandwidth of the continuous loop, Hz (see
    /// [`crate::design::noise_bandwidth_hz`]).
    pub fn noise_bandwidth_hz(&self) -> f64 {
        let p = &self.params;
        noise_bandwidth_hz(p.natural_hz, p.damping, p.tau_s)
    }

    /// The frequency last commanded, Hz (`carrier_hz` before the first tick).
    pub fn frequency_hz(&self) -> f64 {
        self.out_hz
    }

    /// The phase error of the last tick, rad (0 without a signal).
    pub fn phase_error_rad(&self) -> f64 {
        self.error_rad
    }

    /// The integrator's share of the correction, Hz.
    pub fn integrator_hz(&self) -> f64 {
        self.pi.integrator() / TAU
    }

    /// Whether the last output sat on `min_hz` or `max_hz`.
    pub fn at_limit(&self) -> bool {
        self.limited
    }

    /// Whether the last input carried a phase (`|z| > min_amplitude`, finite).
    pub fn has_signal(&self) -> bool {
        self.signal
    }

    /// Locked: a signal, no limit, and `|phase error| < lock_threshold_rad` on each of the
    /// last `lock_updates` ticks.
    pub fn is_locked(&self) -> bool {
        self.run >= self.params.lock_updates
    }

    /// The ticks since the phase error last left the lock threshold (or the signal or a
    /// limit was lost): [`Pll::is_locked`] once it reaches `lock_updates`.
    pub fn in_band_updates(&self) -> u32 {
        self.run
    }
}

impl Stage for Pll {
    /// The demodulated, low-passed baseband sample `z` of the locked mode.
    type Input = Complex64;
    /// The carrier frequency for the next update, Hz.
    type Output = f64;

    #[inline]
    fn tick(&mut self, z: Complex64) -> f64 {
        let r = z * self.derot;
        let amp = r.norm();
        self.signal = amp.is_finite() && amp > self.params.min_amplitude;
        if !self.signal {
            self.error_rad = 0.0;
            self.run = 0;
            return self.out_hz;
        }
        // The detector: std atan2, once per update, so it is linear over the whole circle (a
        // sine detector, Im z / |z|, would flatten past 90 degrees and slow the pull-in).
        let e = r.im.atan2(r.re);
        let carrier = self.params.carrier_hz;
        let (out, limited) = self
            .pi
            .tick(e, self.min_hz, self.max_hz, |u| carrier + u * (1.0 / TAU));
        self.limited = limited;
        self.error_rad = e;
        self.run = if e.abs() < self.params.lock_threshold_rad && !self.limited {
            self.run.saturating_add(1)
        } else {
            0
        };
        self.out_hz = out;
        out
    }

    /// Back to the nominal carrier, integrator empty, not locked.
    fn reset(&mut self) {
        self.pi.reset();
        self.out_hz = self.params.carrier_hz;
        self.error_rad = 0.0;
        self.run = 0;
        self.limited = false;
        self.signal = false;
    }

    /// 0: the output of a tick already responds to that tick's input (the PI's DC group
    /// delay is undefined: its integrator has infinite DC gain). The loop's own delay of one
    /// update is the board's (it applies the output from the next block) and is designed for.
    fn latency_samples(&self) -> f64 {
        0.0
    }
}

impl Response for Pll {
    /// The loop filter from phase error (rad) to commanded frequency (Hz), limits aside, at
    /// `f_hz` (relative to the update rate): `(Kp + Ki T / (1 - e^{-j 2 pi f T})) / 2 pi`.
    /// Infinite at DC (and at multiples of the update rate), where the integrator's is.
    fn response(&self, f_hz: f64) -> Complex64 {
        self.pi.response(f_hz / self.params.update_rate_hz) * (1.0 / TAU)
    }
}
