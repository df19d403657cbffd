//! The drive-amplitude AGC: a second loop around the same envelope, holding `|z|` at a
//! setpoint by scaling the drive.

use crate::agc_params::{AgcParams, AGC_STAGE};
use crate::design::LoopDesign;
use crate::pi::Pi;
use gyroemu_core::{Complex64, ParamResult, Response, Stage};

/// An AGC, ticked once per demodulated output: input the mode's `z`, output the drive gain
/// for the next update (the factor on the nominal drive amplitude).
///
/// The loop is a PI on the log amplitude. At resonance the envelope obeys
/// `A' = -(A - k g) / tau` (`k` the steady amplitude per unit gain), so in logs, near the
/// setpoint `S`, `x = ln A` follows `ln g` through the same first-order lag as the PLL's
/// phase: `x' = -(x - ln k - ln g) / tau`. With `e = ln S - x` (neper) and
/// `ln g = ln g0 + Kp e + Ki int e` the loop is `s^2 + ((1 + Kp) / tau) s + Ki / tau = 0`:
/// `Kp = 2 zeta wn tau - 1`, `Ki = wn^2 tau`, i.e. the PLL's gains times `tau` (the
/// envelope's gain is 1 here, `tau` there), and the sampled loop is designed the same way
/// ([`LoopDesign`], gains times `tau`). The amplitude's response to a step of the setpoint
/// (in logs) is the carrier's response to a step of the resonance:
/// `((Kp / tau) s + wn^2) / (s^2 + 2 zeta wn s + wn^2)`.
///
/// The gain is limited to `[min_gain, max_gain]` without wind-up; `|z| <= min_amplitude`
/// (or not finite) holds the gain. `ln` and `exp` are std, once per update. At lock the two
/// loops do not interact: with the carrier on the resonance the envelope stays real, so the
/// drive's scale does not move its phase.
#[derive(Clone, Debug)]
pub struct Agc {
    params: AgcParams,
    design: LoopDesign,
    setpoint: f64,
    pi: Pi,
    out: f64,
    error_np: f64,
    limited: bool,
    signal: bool,
}

impl Agc {
    /// Builds the AGC; every parameter is checked first (stage `"agc"`).
    pub fn new(params: &AgcParams) -> ParamResult<Self> {
        params.validate()?;
        let p = *params;
        let pll = LoopDesign::new(p.natural_hz, p.damping, p.tau_s, p.update_rate_hz);
        let design = LoopDesign {
            kp_per_s: pll.kp_per_s * p.tau_s,
            ki_t_per_s: pll.ki_t_per_s * p.tau_s,
            ..pll
        };
        Ok(Self {
            params: p,
            design,
            setpoint: p.setpoint,
            pi: Pi::new(design.kp_per_s, design.ki_t_per_s),
            out: p.initial_gain,
            error_np: 0.0,
            limited: false,
            signal: false,
        })
    }

    /// The parameters the AGC was built from.
    pub fn params(&self) -> &AgcParams {
        &self.params
    }

    /// The loop design, gains in neper of gain per neper of amplitude error: `kp_per_s` is
    /// `Kp` (dimensionless here) and `ki_t_per_s` is `Ki T`.
    pub fn design(&self) -> &LoopDesign {
        &self.design
    }

    /// Changes the setpoint (finite, > 0) from the next tick on; a bad value is refused and
    /// changes nothing. [`Stage::reset`] restores the built one.
    pub fn set_setpoint(&mut self, setpoint: f64) -> ParamResult<()> {
        self.setpoint = gyroemu_core::error::positive(AGC_STAGE, "setpoint", setpoint)?;
        Ok(())
    }

    /// The setpoint in use.
    pub fn setpoint(&self) -> f64 {
        self.setpoint
    }

    /// The gain last commanded (`initial_gain` before the first tick).
    pub fn gain(&self) -> f64 {
        self.out
    }

    /// The last error `ln(setpoint / |z|)`, neper (0 without a signal).
    pub fn error_np(&self) -> f64 {
        self.error_np
    }

    /// Whether the last output sat on `min_gain` or `max_gain`.
    pub fn at_limit(&self) -> bool {
        self.limited
    }

    /// Whether the last input carried an amplitude (`|z| > min_amplitude`, finite).
    pub fn has_signal(&self) -> bool {
        self.signal
    }
}

impl Stage for Agc {
    /// The demodulated, low-passed baseband sample `z` of the driven mode.
    type Input = Complex64;
    /// The drive gain for the next update.
    type Output = f64;

    #[inline]
    fn tick(&mut self, z: Complex64) -> f64 {
        let amp = z.norm();
        self.signal = amp.is_finite() && amp > self.params.min_amplitude;
        if !self.signal {
            self.error_np = 0.0;
            return self.out;
        }
        let e = (self.setpoint / amp).ln();
        let g0 = self.params.initial_gain;
        let (out, limited) = self
            .pi
            .tick(e, self.params.min_gain, self.params.max_gain, |u| {
                g0 * u.exp()
            });
        self.limited = limited;
        self.error_np = e;
        self.out = out;
        out
    }

    /// Back to the initial gain and the built setpoint, integrator empty.
    fn reset(&mut self) {
        self.pi.reset();
        self.setpoint = self.params.setpoint;
        self.out = self.params.initial_gain;
        self.error_np = 0.0;
        self.limited = false;
        self.signal = false;
    }

    /// 0, as the PLL's: the output of a tick responds to that tick's input.
    fn latency_samples(&self) -> f64 {
        0.0
    }
}

impl Response for Agc {
    /// The loop filter from log-amplitude error (neper) to log gain (neper), limits aside:
    /// `Kp + Ki T / (1 - e^{-j 2 pi f T})`; for small signals the relative gain change per
    /// relative amplitude error. Infinite at DC.
    fn response(&self, f_hz: f64) -> Complex64 {
        self.pi.response(f_hz / self.params.update_rate_hz)
    }
}
