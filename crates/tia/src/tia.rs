//! The TIA stage: `y[n] = a y[n-1] + (1 - a) G x[n]`, then clamped to the rails.

use gyroemu_core::detmath::sin_cos_turns;
use gyroemu_core::error::positive;
use gyroemu_core::{Complex64, ParamError, ParamResult, Response, Sample, Stage};

const STAGE: &str = "tia";

/// Parameters of a transimpedance amplifier.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TiaParams {
    /// Transimpedance `R` in ohm (V per A at DC), finite and > 0.
    pub gain_ohm: f64,
    /// Feedback pole `1 / (2 pi R C)` in Hz, `0 < pole < fs/2`; `None` for an ideal wide-band TIA.
    pub pole_hz: Option<f64>,
    /// True for the usual inverting topology (DC gain `-R`).
    pub inverting: bool,
    /// Output swing: the output saturates at `+-rail_v` volts; `None` for no rails.
    pub rail_v: Option<f64>,
    /// Sample rate in Hz.
    pub fs_hz: f64,
}

/// A one-pole transimpedance amplifier with saturating output.
///
/// Discretisation: `y[n] = a y[n-1] + (1 - a) G x[n]` with `a = exp(-2 pi pole / fs)` and
/// `G = -R` when inverting (`a = 0`, i.e. `y = G x`, without a pole). The pole matches the
/// continuous one exactly (matched z); the current sample enters without delay, so the
/// discrete response leads `G / (1 + j f/pole)` by about half a sample (`exp(j pi f/fs)`).
///
/// Rails: the output stage of a real TIA saturates, and the feedback capacitor, which sits
/// between the output and the virtual ground, then holds the saturated output voltage. So the
/// output *and* the state (the capacitor voltage, which is the same number here) are clamped
/// to `+-rail`. Recovery after overload is therefore immediate (no integrator wind-up): once
/// the input current returns in range the output decays from the rail with the pole's time
/// constant.
#[derive(Clone, Debug)]
pub struct Tia<S> {
    a: S,
    b: S,
    lo: S,
    hi: S,
    /// Without rails the clamp is skipped (a predictable branch instead of two lane ops).
    has_rails: bool,
    y: S,
    a_f64: f64,
    b_f64: f64,
    g_f64: f64,
    pole_hz: Option<f64>,
    fs_hz: f64,
}

/// The pole coefficient `a = exp(-2 pi pole / fs)` of the discretised one-pole, exactly as
/// [`Tia::new`] builds it.
pub fn pole_coefficient(pole_hz: f64, fs_hz: f64) -> f64 {
    // The pole is a design value: std exp is fine (it does not feed the signal path except
    // through this one constant).
    (-core::f64::consts::TAU * pole_hz / fs_hz).exp()
}

/// The pole, Hz, that [`Tia::new`] realises for `pole_hz`: `-ln(a) fs / (2 pi)` of the
/// coefficient `a` of [`pole_coefficient`]. Below 1, `a` steps in units of 2^-53, so a pole
/// near [`min_pole_hz`] is realised up to twice as high (2.13e-12 Hz at 240 kHz as 4.24e-12);
/// one above 2^-54 x 1e6 x fs / (2 pi) (about 8.8e-12 fs) is always within 1e-6.
pub fn realised_pole_hz(pole_hz: f64, fs_hz: f64) -> f64 {
    // a - 1 is exact (Sterbenz): ln_1p keeps the digits ln(a) would lose near 1.
    -(pole_coefficient(pole_hz, fs_hz) - 1.0).ln_1p() * fs_hz / core::f64::consts::TAU
}

/// The smallest pole, Hz, that [`Tia::new`] can realise at `fs_hz`: below it
/// `2 pi pole / fs` is under about 2^-54 (half the spacing of doubles below 1), so
/// [`pole_coefficient`] rounds to exactly 1 and the gain `(1 - a) G` is exactly 0 at every
/// frequency. Found on [`pole_coefficient`] itself (bisection over the doubles), not from
/// the estimate.
pub fn min_pole_hz(fs_hz: f64) -> f64 {
    let realised = |f: f64| pole_coefficient(f, fs_hz) < 1.0;
    let guess = fs_hz * 2f64.powi(-54) / core::f64::consts::TAU;
    let (lo, hi) = (guess / 4.0, guess * 4.0);
    if !(fs_hz.is_finite() && fs_hz > 0.0) || realised(lo) || !realised(hi) {
        return guess; // not reached for a valid rate (exp is monotone near 1)
    }
    // Positive doubles are ordered as their bits: bisect the bit patterns.
    let (mut l, mut h) = (lo.to_bits(), hi.to_bits());
    while h - l > 1 {
        let m = l + (h - l) / 2;
        if realised(f64::from_bits(m)) {
            h = m;
        } else {
            l = m;
        }
    }
    f64::from_bits(h)
}

/// The rule a pole below [`min_pole_hz`] breaks (the config's validation states it too).
pub fn min_pole_rule(fs_hz: f64) -> String {
    format!(
        "must be at least {:e} Hz at a sample rate fs of {fs_hz} Hz: below it the TIA's discretised pole a = exp(-2 pi pole / fs) rounds to exactly 1 (2 pi pole / fs under about 2^-54, half the spacing of doubles below 1), so its gain (1 - a) x the transimpedance is exactly 0 at every frequency and no signal passes",
        min_pole_hz(fs_hz)
    )
}

impl<S: Sample> Tia<S> {
    /// Builds the TIA; every parameter is checked (stage `"tia"`).
    pub fn new(p: &TiaParams) -> ParamResult<Self> {
        let fs = positive(STAGE, "fs_hz", p.fs_hz)?;
        let r = positive(STAGE, "gain_ohm", p.gain_ohm)?;
        let a = match p.pole_hz {
            None => 0.0,
            Some(f) => {
                if !(f.is_finite() && f > 0.0 && f < 0.5 * fs) {
                    return Err(ParamError::new(
                        STAGE,
                        "pole_hz",
                        f,
                        format!(
                            "must be finite, > 0 and below Nyquist (fs/2 = {} Hz)",
                            0.5 * fs
                        ),
                    ));
                }
                let a = pole_coefficient(f, fs);
                if a >= 1.0 {
                    return Err(ParamError::new(STAGE, "pole_hz", f, min_pole_rule(fs)));
                }
                a
            }
        };
        let rail = match p.rail_v {
            None => f64::INFINITY,
            Some(v) => positive(STAGE, "rail_v", v)?,
        };
        let g = if p.inverting { -r } else { r };
        let b = (1.0 - a) * g;
        Ok(Self {
            a: S::splat(a),
            b: S::splat(b),
            lo: S::splat(-rail),
            hi: S::splat(rail),
            has_rails: p.rail_v.is_some(),
            y: S::default(),
            a_f64: a,
            b_f64: b,
            g_f64: g,
            pole_hz: p.pole_hz,
            fs_hz: fs,
        })
    }
}

impl Tia<f64> {
    /// The standard deviation of the output for unit-variance white input samples (rails
    /// ignored): `|G| sqrt((1 - a) / (1 + a))`, the root of `b^2 / (1 - a^2)`, exact for the
    /// stage as built (`|G|` without a pole).
    pub fn white_noise_gain(&self) -> f64 {
        let a = self.a_f64;
        self.g_f64.abs() * ((1.0 - a) / (1.0 + a)).sqrt()
    }

    /// The continuous-time prototype `G / (1 + j f/pole)` (or `G` without a pole), for
    /// comparing the discretisation with the analogue circuit.
    pub fn continuous_response(&self, f_hz: f64) -> Complex64 {
        match self.pole_hz {
            None => Complex64::new(self.g_f64, 0.0),
            Some(p) => Complex64::new(self.g_f64, 0.0) / Complex64::new(1.0, f_hz / p),
        }
    }
}

impl<S: Sample> Tia<S> {
    /// Lane `lane` back to rest, as [`Stage::reset`] leaves every lane; the other lanes keep
    /// their bits (a lane refilled with another operating point).
    pub fn reset_lane(&mut self, lane: usize) {
        self.y = self.y.with_lane(lane, 0.0);
    }

    /// The TIA has output rails (else its rail count stays 0, and a loop can skip it).
    #[inline(always)]
    pub fn has_rails(&self) -> bool {
        self.has_rails
    }

    /// 1.0 in the lanes where the output `y` of [`Stage::tick`] sits on a rail (clamped), 0.0
    /// elsewhere and always without rails: a count of saturated samples.
    #[inline(always)]
    pub fn rail_flags(&self, y: S) -> S {
        if self.has_rails {
            y.flag_eq(self.hi) + y.flag_eq(self.lo)
        } else {
            S::splat(0.0)
        }
    }
}

impl<S: Sample> Stage for Tia<S> {
    type Input = S;
    type Output = S;

    #[inline(always)]
    fn tick(&mut self, x: S) -> S {
        let mut y = self.a.mul_add(self.y, self.b * x);
        if self.has_rails {
            y = y.clamp_to(self.lo, self.hi);
        }
        self.y = y;
        y
    }

    fn reset(&mut self) {
        self.y = S::default();
    }

    /// DC group delay of `1 / (1 - a z^-1)`: `a / (1 - a)` samples.
    fn latency_samples(&self) -> f64 {
        self.a_f64 / (1.0 - self.a_f64)
    }
}

impl<S: Sample> Response for Tia<S> {
    /// `G (1 - a) / (1 - a e^{-j 2 pi f/fs})`, exact for the stage as built (rails ignored).
    fn response(&self, f_hz: f64) -> Complex64 {
        let (s, c) = sin_cos_turns(f_hz / self.fs_hz);
        let den = Complex64::new(1.0 - self.a_f64 * c, self.a_f64 * s);
        Complex64::new(self.b_f64, 0.0) / den
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> TiaParams {
        TiaParams {
            gain_ohm: 1e5,
            pole_hz: Some(1e4),
            inverting: true,
            rail_v: Some(2.5),
            fs_hz: 1e6,
        }
    }

    #[test]
    fn rejects_bad_parameters_naming_them() {
        let bad = [
            (
                TiaParams {
                    gain_ohm: 0.0,
                    ..params()
                },
                "gain_ohm",
            ),
            (
                TiaParams {
                    gain_ohm: f64::NAN,
                    ..params()
                },
                "gain_ohm",
            ),
            (
                TiaParams {
                    pole_hz: Some(5e5),
                    ..params()
                },
                "pole_hz",
            ),
            (
                TiaParams {
                    pole_hz: Some(-1.0),
                    ..params()
                },
                "pole_hz",
            ),
            (
                TiaParams {
                    pole_hz: Some(f64::INFINITY),
                    ..params()
                },
                "pole_hz",
            ),
            (
                TiaParams {
                    rail_v: Some(0.0),
                    ..params()
                },
                "rail_v",
            ),
            (
                TiaParams {
                    rail_v: Some(f64::NAN),
                    ..params()
                },
                "rail_v",
            ),
            (
                TiaParams {
                    fs_hz: f64::NAN,
                    ..params()
                },
                "fs_hz",
            ),
            (
                TiaParams {
                    fs_hz: -1.0,
                    ..params()
                },
                "fs_hz",
            ),
        ];
        for (p, name) in bad {
            let e = Tia::<f64>::new(&p).unwrap_err();
            assert_eq!((e.stage, e.param), ("tia", name), "{e}");
        }
        assert!(Tia::<f64>::new(&params()).is_ok());
        let no_pole = TiaParams {
            pole_hz: None,
            rail_v: None,
            ..params()
        };
        assert!(Tia::<f64>::new(&no_pole).is_ok());
    }

    #[test]
    fn the_smallest_pole_is_the_first_with_a_nonzero_gain() {
        for fs in [240e3, 1e6, 3.0, 1e12] {
            let min = min_pole_hz(fs);
            let below = f64::from_bits(min.to_bits() - 1);
            assert!(pole_coefficient(min, fs) < 1.0, "{fs}");
            assert_eq!(pole_coefficient(below, fs), 1.0, "{fs}");
            // About fs 2^-54 / (2 pi).
            let est = fs * 2f64.powi(-54) / core::f64::consts::TAU;
            assert!((min / est - 1.0).abs() < 1e-6, "{fs}: {min} vs {est}");
            let at = |pole| TiaParams {
                pole_hz: Some(pole),
                fs_hz: fs,
                ..params()
            };
            let t = Tia::<f64>::new(&at(min)).unwrap();
            assert!(t.response(0.25 * fs).norm() > 0.0);
            for pole in [below, 1e-120, 1e-300, f64::MIN_POSITIVE] {
                let e = Tia::<f64>::new(&at(pole)).unwrap_err();
                assert_eq!((e.stage, e.param), ("tia", "pole_hz"), "{e}");
                assert!(e.rule.contains("exactly 0"), "{e}");
            }
        }
    }

    #[test]
    fn the_realised_pole_is_that_of_the_built_coefficient() {
        let tau = core::f64::consts::TAU;
        // Near the minimum a = 1 - k 2^-53 exactly, k = round(2 pi p / fs 2^53), and
        // -ln(a) = k 2^-53 (1 + k 2^-54 + ...): the pole realised is k 2^-53 fs / (2 pi).
        let fs = 240e3;
        for (p, k) in [(2.13e-12, 1.0), (1e-11, 2.0), (4e-11, 9.0)] {
            assert_eq!(k, (tau * p / fs * 2f64.powi(53)).round(), "{p}");
            let want = k * 2f64.powi(-53) * fs / tau;
            let got = realised_pole_hz(p, fs);
            assert!((got / want - 1.0).abs() < 1e-14, "{p}: {got:e} vs {want:e}");
        }
        // 2.13e-12 Hz is realised as 4.24e-12 (+99 %), 1e-11 as 8.48e-12.
        assert!((realised_pole_hz(2.13e-12, fs) / 4.2407e-12 - 1.0).abs() < 1e-4);
        // Far from the minimum the quantisation is below 1e-6; the realised pole rebuilds
        // the same coefficient.
        for (p, fs) in [(60e3, 240e3), (12e6, 48e6), (1.0, 240e3), (3e-6, 240e3)] {
            let got = realised_pole_hz(p, fs);
            assert!((got / p - 1.0).abs() < 1e-6, "{p} at {fs}: {got:e}");
            let a = pole_coefficient(p, fs);
            assert_eq!(pole_coefficient(got, fs), a, "{p} at {fs}");
        }
    }

    #[test]
    fn white_noise_gain_is_the_output_deviation_of_unit_white_input() {
        // sum of the squared impulse response b^2 a^(2n) = b^2 / (1 - a^2).
        let t = Tia::<f64>::new(&params()).unwrap();
        let a = pole_coefficient(1e4, 1e6);
        let b = (1.0 - a) * 1e5;
        let want = (b * b / (1.0 - a * a)).sqrt();
        assert!((t.white_noise_gain() / want - 1.0).abs() < 1e-12);
        let flat = TiaParams {
            pole_hz: None,
            ..params()
        };
        assert_eq!(Tia::<f64>::new(&flat).unwrap().white_noise_gain(), 1e5);
    }
}
