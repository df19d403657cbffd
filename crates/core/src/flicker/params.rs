//! What a flicker source is asked for: its 1/f level and the band where it is 1/f, and the
//! conversions gyro engineers use (a corner against a white floor, a bias instability).

use crate::error::{positive, ParamError, ParamResult};

/// The stage name in parameter errors.
pub(crate) const STAGE: &str = "flicker";

/// A flicker source: the one-sided density `S(f) = psd_at_1hz / f` between `f_lo_hz` and
/// `f_hi_hz`, flat outside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlickerParams {
    /// Sample rate of the sequence, Hz.
    pub fs_hz: f64,
    /// One-sided density at 1 Hz, unit^2/Hz (so `S(f) = psd_at_1hz / f`); 0 gives silence.
    pub psd_at_1hz: f64,
    /// Low corner, Hz: the lowest pole, below which the density flattens (e.g. 1 / record
    /// length: a real 1/f spectrum cannot extend to 0 Hz with finite variance).
    pub f_lo_hz: f64,
    /// High corner, Hz (at most fs/2, at least 100 f_lo): the last zero, above which the
    /// density flattens.
    pub f_hi_hz: f64,
}

/// The lowest low corner, Hz, a flicker source at `fs_hz` is built for: its lowest pole's
/// radius `exp(-2 pi f_lo / fs)` stays 1000 ulps below 1, so that pole is realised within
/// 0.1 % (closer to 1 it rounds toward an integrator, and the lattice's pole count grows
/// without bound).
pub fn min_f_lo_hz(fs_hz: f64) -> f64 {
    1000.0 * f64::EPSILON / 2.0 * fs_hz / core::f64::consts::TAU
}

impl FlickerParams {
    /// Checks every field, naming the key, the value and the rule.
    pub fn validate(&self) -> ParamResult<()> {
        positive(STAGE, "fs_hz", self.fs_hz)?;
        if !(self.psd_at_1hz.is_finite() && self.psd_at_1hz >= 0.0) {
            return Err(ParamError::new(
                STAGE,
                "psd_at_1hz",
                self.psd_at_1hz,
                "must be finite and >= 0",
            ));
        }
        positive(STAGE, "f_lo_hz", self.f_lo_hz)?;
        if self.f_lo_hz < min_f_lo_hz(self.fs_hz) {
            return Err(ParamError::new(
                STAGE,
                "f_lo_hz",
                self.f_lo_hz,
                format!(
                    "must be at least {:e} Hz at fs = {} Hz: below it the lowest pole's radius exp(-2 pi f_lo / fs) lies within 1000 ulps of 1 and is realised off by more than 0.1 %",
                    min_f_lo_hz(self.fs_hz),
                    self.fs_hz
                ),
            ));
        }
        if !(self.f_hi_hz.is_finite() && self.f_hi_hz <= 0.5 * self.fs_hz) {
            return Err(ParamError::new(
                STAGE,
                "f_hi_hz",
                self.f_hi_hz,
                format!("must be finite and <= fs/2 = {} Hz", 0.5 * self.fs_hz),
            ));
        }
        if self.f_hi_hz < 100.0 * self.f_lo_hz {
            return Err(ParamError::new(
                STAGE,
                "f_hi_hz",
                self.f_hi_hz,
                format!(
                    "must be at least 100 f_lo_hz = {} Hz (two decades of 1/f)",
                    100.0 * self.f_lo_hz
                ),
            ));
        }
        Ok(())
    }
}

/// The 1 Hz level of a flicker density that meets the white density `white_psd` (unit^2/Hz)
/// at `corner_hz`: `S(f) = white_psd * corner_hz / f`.
pub fn psd_at_1hz_from_corner(white_psd: f64, corner_hz: f64) -> f64 {
    white_psd * corner_hz
}

/// The 1 Hz level of the one-sided rate density whose Allan floor is the bias instability
/// `b`: `S(f) = b^2 / (pi f)`. IEEE Std 952 writes the two-sided density, `b^2 / (2 pi f)`,
/// whose flat Allan variance is `(2 ln 2 / pi) b^2`.
pub fn psd_at_1hz_from_bias_instability(b: f64) -> f64 {
    b * b / core::f64::consts::PI
}

/// The Allan deviation of 1/f noise of one-sided density `psd_at_1hz / f`:
/// `sqrt(2 ln 2 psd_at_1hz)`, the same at every tau (Allan 1966; IEEE Std 952 Annex C).
pub fn flicker_adev(psd_at_1hz: f64) -> f64 {
    (2.0 * core::f64::consts::LN_2 * psd_at_1hz).sqrt()
}

/// The Allan floor of flicker over its bias instability: `sqrt(2 ln 2 / pi) = 0.6643`, the
/// 0.664 of IEEE Std 952.
pub const ADEV_PER_BIAS_INSTABILITY: f64 = 0.664_282_470_267_960_1;

#[cfg(test)]
mod tests {
    use super::*;

    fn ok() -> FlickerParams {
        FlickerParams {
            fs_hz: 1000.0,
            psd_at_1hz: 1e-6,
            f_lo_hz: 0.01,
            f_hi_hz: 500.0,
        }
    }

    #[test]
    fn the_ieee_constant_is_sqrt_2ln2_over_pi() {
        let v = (2.0 * core::f64::consts::LN_2 / core::f64::consts::PI).sqrt();
        assert!((ADEV_PER_BIAS_INSTABILITY - v).abs() < 1e-15);
        // The one-sided B^2 / pi fed to the flicker Allan formula gives 0.664 B.
        let b = 3.7;
        let a = flicker_adev(psd_at_1hz_from_bias_instability(b));
        assert!((a / b - ADEV_PER_BIAS_INSTABILITY).abs() < 1e-14);
        assert_eq!(psd_at_1hz_from_corner(4e-18, 250.0), 1e-15);
    }

    #[test]
    fn the_lowest_corner_keeps_its_pole_realised_within_a_thousandth() {
        let fs = ok().fs_hz;
        let min = min_f_lo_hz(fs);
        // 1 - exp(-x) at the bound is 1000 ulps of 1 (eps/2 each below 1), to rounding.
        let gap = -(-core::f64::consts::TAU * min / fs).exp_m1();
        assert!(
            (gap / (1000.0 * f64::EPSILON / 2.0) - 1.0).abs() < 1e-3,
            "{gap:e}"
        );
        let at = |f_lo_hz| FlickerParams { f_lo_hz, ..ok() };
        assert!(at(min).validate().is_ok());
        for f in [min * (1.0 - 1e-12), 1e-300, 1e-310] {
            let e = at(f).validate().unwrap_err();
            assert_eq!(e.param, "f_lo_hz", "{e}");
        }
    }

    #[test]
    fn bad_fields_are_named() {
        assert!(ok().validate().is_ok());
        let cases: [(FlickerParams, &str); 6] = [
            (FlickerParams { fs_hz: 0.0, ..ok() }, "fs_hz"),
            (
                FlickerParams {
                    psd_at_1hz: -1.0,
                    ..ok()
                },
                "psd_at_1hz",
            ),
            (
                FlickerParams {
                    psd_at_1hz: f64::NAN,
                    ..ok()
                },
                "psd_at_1hz",
            ),
            (
                FlickerParams {
                    f_lo_hz: 0.0,
                    ..ok()
                },
                "f_lo_hz",
            ),
            (
                FlickerParams {
                    f_hi_hz: 501.0,
                    ..ok()
                },
                "f_hi_hz",
            ),
            (
                FlickerParams {
                    f_lo_hz: 6.0,
                    ..ok()
                },
                "f_hi_hz",
            ),
        ];
        for (p, key) in cases {
            let e = p.validate().unwrap_err();
            assert_eq!(e.param, key, "{e}");
            assert!(e.to_string().contains("flicker"));
        }
    }
}
