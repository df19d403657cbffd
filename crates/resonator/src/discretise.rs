//! Exact zero-order-hold discretisation and its expansion in the rate.
//!
//! `A*Ts` is badly scaled (`w0^2 Ts` beside `Ts`), so every exponential is taken of the
//! balanced matrix `S M S^-1` with `S = diag(w1, w2, 1, 1, 1/w1, 1/w1)` (state `[w q, v]`,
//! input `u/w1`), whose entries are all of order `w Ts`, and transformed back exactly.

use crate::ResonatorParams;
use nalgebra::SMatrix;

/// Augmented size: 4 states + 2 held inputs.
const N: usize = 6;

/// A 4x6 block `[Phi | Gamma]` in physical units.
pub(crate) type Block = [[f64; N]; 4];

/// Continuous state matrix `A(Omega) = A0 + Omega Ac`, physical units.
pub(crate) fn state_matrix(p: &ResonatorParams, omega_z_rad_s: f64) -> [[f64; 4]; 4] {
    let [w1, w2] = p.w_rad_s();
    let k12 = p.quadrature_coupling_rad2_s2;
    let c = 2.0 * p.angular_gain * omega_z_rad_s;
    [
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
        [-w1 * w1, -k12, -w1 / p.mode1.q, c],
        [-k12, -w2 * w2, -c, -w2 / p.mode2.q],
    ]
}

/// Balancing scales `s_i` of the augmented state `[q1, q2, v1, v2, u1, u2]`.
pub(crate) fn scales(p: &ResonatorParams) -> [f64; N] {
    let [w1, w2] = p.w_rad_s();
    [w1, w2, 1.0, 1.0, 1.0 / w1, 1.0 / w1]
}

/// Balanced augmented `[[A, B], [0, 0]] * Ts` at rate `omega` (`B = [0; I]`).
fn balanced_augmented(p: &ResonatorParams, omega_z_rad_s: f64) -> SMatrix<f64, N, N> {
    let a = state_matrix(p, omega_z_rad_s);
    let s = scales(p);
    let ts = p.ts_s();
    let mut m = SMatrix::<f64, N, N>::zeros();
    for i in 0..4 {
        for j in 0..4 {
            m[(i, j)] = s[i] * a[i][j] / s[j] * ts;
        }
    }
    for k in 0..2 {
        m[(2 + k, 4 + k)] = s[2 + k] / s[4 + k] * ts;
    }
    m
}

/// Balanced `Ac * Ts` (the rate derivative of the augmented matrix; it only couples the
/// velocities, whose scale is 1).
fn balanced_rate_part(p: &ResonatorParams) -> SMatrix<f64, N, N> {
    let c = 2.0 * p.angular_gain * p.ts_s();
    let mut m = SMatrix::<f64, N, N>::zeros();
    m[(2, 3)] = c;
    m[(3, 2)] = -c;
    m
}

/// Rows 0..4 of a balanced 6-column block, back in physical units.
fn unbalance(eb: impl Fn(usize, usize) -> f64, s: &[f64; N], factor: f64) -> Block {
    let mut out = [[0.0; N]; 4];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, e) in row.iter_mut().enumerate() {
            *e = eb(i, j) * s[j] / s[i] * factor;
        }
    }
    out
}

/// `[E0, E1, E2]` such that `[Phi | Gamma](Omega) = E0 + d E1 + d^2 E2 + O((d Ts)^3)`,
/// `d = Omega - omega_c`. `E0` is the exact ZOH step at `omega_c` (6x6 exponential); `E1`,
/// `E2` are blocks (0,1), (0,2) of the exponential of the block bidiagonal
/// `[[M0, c Mc, 0], [0, M0, c Mc], [0, 0, M0]] Ts` (the Taylor coefficients of
/// `exp((M0 + e c Mc) Ts)` in `e`), the scale `c = w1` balancing the rate block.
pub(crate) fn zoh_expansion(p: &ResonatorParams, omega_c_rad_s: f64) -> [Block; 3] {
    let s = scales(p);
    let m0 = balanced_augmented(p, omega_c_rad_s);
    let e0b = m0.exp();
    let c = p.w_rad_s()[0];
    let mc = balanced_rate_part(p) * c;
    let mut big = SMatrix::<f64, { 3 * N }, { 3 * N }>::zeros();
    for b in 0..3 {
        big.fixed_view_mut::<N, N>(b * N, b * N).copy_from(&m0);
    }
    for b in 0..2 {
        big.fixed_view_mut::<N, N>(b * N, (b + 1) * N)
            .copy_from(&mc);
    }
    let eb = big.exp();
    [
        unbalance(|i, j| e0b[(i, j)], &s, 1.0),
        unbalance(|i, j| eb[(i, N + j)], &s, 1.0 / c),
        unbalance(|i, j| eb[(i, 2 * N + j)], &s, 1.0 / (c * c)),
    ]
}
