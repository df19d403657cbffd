//! The stationary law of the modal states: a Cholesky factor of their covariance, so a start
//! state drawn as `L xi` (xi unit Gaussian) is a draw from the infinite past.

use super::FlickerDesign;

/// Lower-triangular `L` (row-major, `n x n`) with `L L^T = C`, `C_ij = 1 / (1 - a_i a_j)`.
///
/// Factored as the correlation matrix `C_ij / sqrt(C_ii C_jj)` (states differ in variance by
/// the ratio of their poles, their correlations do not): for poles two per decade its
/// condition number stays near 1e3 however many decades, so plain Cholesky is exact to
/// rounding. A pivot that rounding drives to or below zero (a state the others determine)
/// gets a zero column.
pub(crate) fn cholesky_factor(d: &FlickerDesign) -> Vec<f64> {
    let n = d.poles();
    let scale: Vec<f64> = (0..n).map(|i| d.mode_covariance(i, i).sqrt()).collect();
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let corr = d.mode_covariance(i, j) / (scale[i] * scale[j]);
            let dot: f64 = (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum();
            let v = corr - dot;
            l[i * n + j] = if i == j {
                v.max(0.0).sqrt()
            } else if l[j * n + j] > 0.0 {
                v / l[j * n + j]
            } else {
                0.0
            };
        }
    }
    for i in 0..n {
        for j in 0..=i {
            l[i * n + j] *= scale[i];
        }
    }
    l
}
