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

/// The periodic steady state of the plant on a sinusoidal rate table, by harmonic balance
/// (THEORY.md section 3): with `Omega_z(t) = amplitude sin(2 pi table_hz t)` and the force
/// `f(t) = Re{F e^{j w_c t}}` at `carrier_hz`, the state is `x(t) = Re{sum_n X_n e^{j (w_c + n
/// w_t) t}}` with, for every `n`, `(j w_n I - A0) X_n - (amplitude / 2j) Ac (X_{n-1} -
/// X_{n+1}) = B F delta_n0` (`w_n = w_c + n w_t`, `A = A0 + Omega Ac`). Truncated at `|n| <=
/// harmonics` (the harmonics fall off like Bessel functions of the phase swing); returns
/// `X_{-N} .. X_N` of `[q1, q2, v1, v2]`. Exact for the continuous plant and drive (no hold).
pub fn rate_table_steady_state(
    params: &ResonatorParams,
    amplitude_rad_s: f64,
    table_hz: f64,
    carrier_hz: f64,
    force: [Complex64; 2],
    harmonics: usize,
) -> Vec<[Complex64; 4]> {
    type M4 = nalgebra::Matrix4<Complex64>;
    let nb = 2 * harmonics + 1;
    let s = scales(params);
    let a0 = state_matrix(params, 0.0);
    // The rate part Ac couples only the velocities (scale 1), so it is its own balance.
    let ac = state_matrix(params, 1.0);
    let zero = Complex64::new(0.0, 0.0);
    let nan = [Complex64::new(f64::NAN, f64::NAN); 4];
    let half = Complex64::new(0.0, 0.5 * amplitude_rad_s); // j A / 2
                                                           // X_{n-1} enters block n with +jA/2 Ac, X_{n+1} with -jA/2 Ac.
    let lower = M4::from_fn(|i, j| half * (ac[i][j] - a0[i][j]));
    let upper = -lower;
    let diag = |b: usize| {
        let w = core::f64::consts::TAU * (carrier_hz + (b as f64 - harmonics as f64) * table_hz);
        M4::from_fn(|i, j| {
            let eye = if i == j { Complex64::new(0.0, w) } else { zero };
            eye - Complex64::new(s[i] * a0[i][j] / s[j], 0.0)
        })
    };
    let rhs = |b: usize| {
        let mut r = nalgebra::Vector4::from_element(zero);
        if b == harmonics {
            for k in 0..2 {
                r[2 + k] = force[k] * s[2 + k];
            }
        }
        r
    };
    // Block tridiagonal elimination (block Thomas), O(N): the blocks far from the carrier are
    // far from resonance and the exact system is well posed, so no pivoting across blocks.
    let mut c = Vec::with_capacity(nb);
    let mut d = Vec::with_capacity(nb);
    for b in 0..nb {
        let (m, r) = if b == 0 {
            (diag(0), rhs(0))
        } else {
            (diag(b) - lower * c[b - 1], rhs(b) - lower * d[b - 1])
        };
        let lu = m.lu();
        let (Some(cb), Some(db)) = (lu.solve(&upper), lu.solve(&r)) else {
            return vec![nan; nb];
        };
        c.push(cb);
        d.push(db);
    }
    let mut x = vec![nalgebra::Vector4::from_element(zero); nb];
    x[nb - 1] = d[nb - 1];
    for b in (0..nb - 1).rev() {
        x[b] = d[b] - c[b] * x[b + 1];
    }
    x.iter()
        .map(|xb| core::array::from_fn(|i| xb[i] / s[i]))
        .collect()
}
