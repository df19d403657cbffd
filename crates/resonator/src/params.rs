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
        // With damping on both modes and a gyroscopic (skew) Coriolis term, the plant is
        // asymptotically stable exactly when its stiffness matrix [[w1^2, k12], [k12, w2^2]] is
        // positive definite (energy decreases; Kelvin-Tait-Chetaev): |k12| < w1 w2. Beyond,
        // one combination of the modes has a negative stiffness and grows without bound.
        let [w1, w2] = self.w_rad_s();
        if self.quadrature_coupling_rad2_s2.abs() >= w1 * w2 {
            return Err(ParamError::new(
                STAGE,
                "quadrature_coupling_rad2_s2",
                self.quadrature_coupling_rad2_s2,
                format!(
                    "must be below w1 w2 = {:e} (rad/s)^2 in magnitude: a larger coupling makes the stiffness matrix indefinite and the plant unstable",
                    w1 * w2
                ),
            ));
        }
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

    /// The free plant integrated by classical RK4 (independent of the exact discretisation):
    /// its squared displacement plus squared velocity over w1^2 after `t_s`, from a unit
    /// displacement of mode 1 (a norm of the state: with an indefinite stiffness the energy
    /// itself can go negative).
    fn state_norm_after(p: &ResonatorParams, t_s: f64) -> f64 {
        let [w1, w2] = p.w_rad_s();
        let k = p.quadrature_coupling_rad2_s2;
        let f = |x: [f64; 4]| {
            [
                x[2],
                x[3],
                -w1 * w1 * x[0] - k * x[1] - w1 / p.mode1.q * x[2],
                -k * x[0] - w2 * w2 * x[1] - w2 / p.mode2.q * x[3],
            ]
        };
        let h = 1.0 / (200.0 * p.mode1.f0_hz);
        let mut x = [1.0, 0.0, 0.0, 0.0];
        for _ in 0..(t_s / h) as usize {
            let add = |a: [f64; 4], b: [f64; 4], s: f64| core::array::from_fn(|i| a[i] + s * b[i]);
            let k1 = f(x);
            let k2 = f(add(x, k1, h / 2.0));
            let k3 = f(add(x, k2, h / 2.0));
            let k4 = f(add(x, k3, h));
            x = core::array::from_fn(|i| {
                x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        x[0] * x[0] + x[1] * x[1] + (x[2] * x[2] + x[3] * x[3]) / (w1 * w1)
    }

    #[test]
    fn a_coupling_beyond_w1_w2_is_refused_and_is_unstable_where_a_smaller_one_is_not() {
        let mut p = ResonatorParams::matched(1e3, 50.0, 1.0, 16e3);
        p.mode2.f0_hz = 1.1e3;
        let [w1, w2] = p.w_rad_s();
        let e0 = 1.0;
        // 0.99 w1 w2: stable, the state decays.
        p.quadrature_coupling_rad2_s2 = 0.99 * w1 * w2;
        assert!(p.validate().is_ok());
        assert!(state_norm_after(&p, 0.5) < e0);
        // 1.01 w1 w2: refused, and indeed the free response grows.
        p.quadrature_coupling_rad2_s2 = -1.01 * w1 * w2;
        let err = p.validate().unwrap_err();
        assert_eq!(err.param, "quadrature_coupling_rad2_s2");
        assert!(err.rule.contains("unstable"), "{err}");
        assert!(state_norm_after(&p, 0.5) > 1e3 * e0);
    }
}
