//! Steady-state phasors of the plant: sampled (held input) and continuous (true sinusoid).
//! Both solve in the balanced coordinates `[w q, v]`, where the matrix is well scaled.

use crate::discretise::{scales, state_matrix};
use crate::{Resonator, ResonatorParams};
use gyroemu_core::detmath::sin_cos_turns;
use gyroemu_core::Complex64;
use nalgebra::{Matrix4, Vector4};

/// Solves `(z I - M) X = R` given in physical units, via `S M S^-1` and `S R`.
fn solve_balanced(
    s: &[f64; 6],
    z: Complex64,
    m: &[[f64; 4]; 4],
    rhs: [Complex64; 4],
) -> [Complex64; 4] {
    let mat = Matrix4::from_fn(|i, j| {
        let eye = if i == j { z } else { Complex64::new(0.0, 0.0) };
        eye - Complex64::new(s[i] * m[i][j] / s[j], 0.0)
    });
    let r = Vector4::from_fn(|i, _| rhs[i] * s[i]);
    let zb = mat
        .lu()
        .solve(&r)
        .unwrap_or_else(|| Vector4::repeat(Complex64::new(f64::NAN, f64::NAN)));
    core::array::from_fn(|i| zb[i] / s[i])
}

impl Resonator<f64> {
    /// Steady-state phasors of the *sampled* state `[q1, q2, v1, v2]` for the held sinusoidal
    /// input `u[n] = Re{F e^{j w n Ts}}`: `x[n] = Re{X e^{j w n Ts}}`,
    /// `X = (e^{j w Ts} I - Phi)^-1 Gamma F`. This is what [`gyroemu_core::Stage::tick`]
    /// settles to, hold included. NaN if `e^{j w Ts}` is an eigenvalue of `Phi`.
    pub fn held_steady_state(&self, f_hz: f64, force: [Complex64; 2]) -> [Complex64; 4] {
        let (sn, cs) = sin_cos_turns(f_hz / self.params().fs_hz);
        let gamma = self.gamma();
        let rhs = core::array::from_fn(|i| gamma[i][0] * force[0] + gamma[i][1] * force[1]);
        solve_balanced(
            &scales(self.params()),
            Complex64::new(cs, sn),
            &self.phi(),
            rhs,
        )
    }
}

/// Continuous-time steady state `(j w I - A)^-1 B F` of `[q1, q2, v1, v2]` for the truly
/// sinusoidal force `f(t) = Re{F e^{j w t}}` (no hold), at the constant rate
/// `omega_z_rad_s`: the reference of THEORY.md section 3.
pub fn continuous_steady_state(
    params: &ResonatorParams,
    omega_z_rad_s: f64,
    f_hz: f64,
    force: [Complex64; 2],
) -> [Complex64; 4] {
    let w = core::f64::consts::TAU * f_hz;
    let zero = Complex64::new(0.0, 0.0);
    let rhs = [zero, zero, force[0], force[1]];
    solve_balanced(
        &scales(params),
        Complex64::new(0.0, w),
        &state_matrix(params, omega_z_rad_s),
        rhs,
    )
}
