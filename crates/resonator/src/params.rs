//! Physical parameters of the two-mode plant and their validation.

use crate::STAGE;
use gyroemu_core::error::{finite, positive};
use gyroemu_core::{ParamError, ParamResult};

/// One resonance mode: natural frequency and quality factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeParams {
    /// Natural (undamped) frequency `f0 = w0 / (2 pi)`, Hz.
    pub f0_hz: f64,
    /// Quality factor `Q` (damping term `w0/Q`); the ring-down time constant is `Q/(pi f0)`.
    pub q: f64,
}

/// Everything that defines the plant and its sampling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResonatorParams {
    /// Mode 1 ("I", drive).
    pub mode1: ModeParams,
    /// Mode 2 ("Q", sense).
    pub mode2: ModeParams,
    /// Angular gain `lambda` (Coriolis coupling is `2 lambda Omega_z`).
    pub angular_gain: f64,
    /// Quadrature (stiffness) coupling `k12`, (rad/s)^2; 0 for an ideal device.
    pub quadrature_coupling_rad2_s2: f64,
    /// Motional current per velocity, A per (m/s): `current = transduction * v`.
    pub transduction_a_s_per_m: f64,
    /// Sample rate, Hz (the hold period is `1/fs_hz`).
    pub fs_hz: f64,
}

impl ResonatorParams {
    /// Mode-matched ideal device: both modes at `f0_hz` with quality `q`, no quadrature
    /// coupling, unit transduction.
    pub fn matched(f0_hz: f64, q: f64, angular_gain: f64, fs_hz: f64) -> Self {
        let mode = ModeParams { f0_hz, q };
        Self {
            mode1: mode,
            mode2: mode,
            angular_gain,
            quadrature_coupling_rad2_s2: 0.0,
            transduction_a_s_per_m: 1.0,
            fs_hz,
        }
    }

    /// Checks every parameter: frequencies and Q finite and > 0, `fs_hz` above `2*f0` of both
    /// modes (the exact discretisation needs the carrier below Nyquist to be meaningful), and
    /// the couplings finite.
    pub fn validate(&self) -> ParamResult<()> {
        positive(STAGE, "mode1.f0_hz", self.mode1.f0_hz)?;
        positive(STAGE, "mode1.q", self.mode1.q)?;
        positive(STAGE, "mode2.f0_hz", self.mode2.f0_hz)?;
        positive(STAGE, "mode2.q", self.mode2.q)?;
        let f_max = self.mode1.f0_hz.max(self.mode2.f0_hz);
        if !(self.fs_hz.is_finite() && self.fs_hz > 2.0 * f_max) {
            return Err(ParamError::new(
                STAGE,
                "fs_hz",
                self.fs_hz,
                format!("fs_hz must be above 2*f0 (finite and > {} Hz)", 2.0 * f_max),
            ));
        }
        finite(STAGE, "angular_gain", self.angular_gain)?;
        finite(
            STAGE,
            "quadrature_coupling_rad2_s2",
            self.quadrature_coupling_rad2_s2,
        )?;
        finite(STAGE, "transduction_a_s_per_m", self.transduction_a_s_per_m)?;
        Ok(())
    }

    /// Sample period, s.
    pub(crate) fn ts_s(&self) -> f64 {
        1.0 / self.fs_hz
    }

    /// Angular natural frequencies `[w1, w2]`, rad/s.
    pub(crate) fn w_rad_s(&self) -> [f64; 2] {
        let tau = core::f64::consts::TAU;
        [tau * self.mode1.f0_hz, tau * self.mode2.f0_hz]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_param_and_rule() {
        let ok = ResonatorParams::matched(1e3, 100.0, 1.0, 16e3);
        assert!(ok.validate().is_ok());
        let mut p = ok;
        p.mode2.q = 0.0;
        assert_eq!(p.validate().unwrap_err().param, "mode2.q");
        let mut p = ok;
        p.fs_hz = 2e3;
        let e = p.validate().unwrap_err();
        assert_eq!((e.stage, e.param), ("resonator", "fs_hz"));
        assert!(e.rule.contains("fs_hz must be above 2*f0"));
        let mut p = ok;
        p.quadrature_coupling_rad2_s2 = f64::NAN;
        assert_eq!(
            p.validate().unwrap_err().param,
            "quadrature_coupling_rad2_s2"
        );
    }
}
