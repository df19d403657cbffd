//! The two-mode plant identified from its whole 2 x 2 frequency response: with both modes
//! driven in turn and both read, `H(w)` (velocity per force) of `M q'' + C q' + K q = f` obeys
//! `j w H(w)^-1 = K - w^2 M + j w C`, which is linear in `K`, `M` and `C` entry by entry. So the
//! uncoupled resonances, the Qs and the quadrature coupling `k12` come out of a linear least
//! squares, exactly for this model, where a one-mode fit of each driven response reads a
//! coupled mode with the neighbour's residue in it.

use gyroemu_core::Complex64;
use nalgebra::{Matrix2, Vector2};
use serde::Serialize;

/// The plant's matrices, mass-normalised, and what they say of each mode.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MatrixFit {
    /// Each mode's own resonance `sqrt(K_kk / M_kk) / 2 pi`, Hz (the configured f0 when the
    /// chain is divided out exactly).
    pub f0_hz: [f64; 2],
    /// Each mode's own Q, `sqrt(K_kk M_kk) / C_kk`.
    pub q: [f64; 2],
    /// The stiffness coupling `K_12 / sqrt(M_11 M_22)`, (rad/s)^2
    /// (`device.quadrature_coupling_rad2_s2`).
    pub coupling_rad2_s2: f64,
    /// `K_21 / sqrt(M_11 M_22)`, (rad/s)^2: equal to `coupling_rad2_s2` for a reciprocal plant.
    pub coupling_21_rad2_s2: f64,
    /// The damping coupling `C_12 / sqrt(M_11 M_22)`, rad/s (0 for the model's plant).
    pub damping_coupling_rad_s: f64,
    /// `M_11`, `M_22`: 1 when the chain's gains are divided out exactly.
    pub mass: [f64; 2],
    /// Frequencies used (those with a finite, invertible response).
    pub frequencies: usize,
}

/// Fits `K`, `M`, `C` to the responses `h[i][m][k]` (velocity of mode k per force on mode m,
/// as `stepped_sine` gives them) at `f_hz`. Entry by entry, `Im Z_kl = w C_kl` with
/// `Z = j w H^-1`; on the diagonal `Re Z_kk = a_kk - (w^2 - w_r^2) M_kk` with
/// `K_kk = a_kk + w_r^2 M_kk` (`w_r` the mean `w`, which keeps the two columns apart). The
/// model's modes have no mass coupling (`M_12 = 0`), so off the diagonal `Re Z_kl = K_kl`:
/// fitting an `M_12` there too would extrapolate a band of a few bandwidths to w = 0 and
/// turn the smallest error of `Z` into a large one of `K_12`. Each frequency is weighted by
/// `1 / |Z|`, so every point counts by its relative error. `None` with fewer than three
/// usable frequencies.
pub fn fit_matrix(f_hz: &[f64], h: &[[[Complex64; 2]; 2]]) -> Option<MatrixFit> {
    let tau = core::f64::consts::TAU;
    let j = Complex64::new(0.0, 1.0);
    let z: Vec<(f64, Matrix2<Complex64>)> = f_hz
        .iter()
        .zip(h)
        .filter_map(|(&f, r)| {
            // Row k, column m: the output k per the input m.
            let hm = Matrix2::new(r[0][0], r[1][0], r[0][1], r[1][1]);
            let w = tau * f;
            let inv = hm.try_inverse()?;
            let zm = inv * (j * w);
            zm.iter()
                .all(|v| v.re.is_finite() && v.im.is_finite())
                .then_some((w, zm))
        })
        .collect();
    if z.len() < 3 {
        return None;
    }
    let wr = z.iter().map(|(w, _)| w).sum::<f64>() / z.len() as f64;
    let weight: Vec<f64> = z.iter().map(|(_, zm)| 1.0 / zm.norm()).collect();
    // Normal equations of the two-column fit (x = w^2 - w_r^2, in units of w_r^2), solved per
    // entry; the damping is a one-column fit.
    let mut k = [[0.0; 2]; 2];
    let mut m = [[0.0; 2]; 2];
    let mut c = [[0.0; 2]; 2];
    for r in 0..2 {
        for col in 0..2 {
            let (mut ata, mut atb) = (Matrix2::<f64>::zeros(), Vector2::<f64>::zeros());
            let (mut cc, mut cb) = (0.0, 0.0);
            for ((w, zm), &wt) in z.iter().zip(&weight) {
                let x = (w * w - wr * wr) / (wr * wr);
                let diagonal = if r == col { 1.0 } else { 0.0 };
                let row = Vector2::new(wt, -wt * x * diagonal);
                let v = zm[(r, col)];
                ata += row * row.transpose();
                atb += row * (wt * v.re / (wr * wr));
                cc += (wt * w / wr).powi(2);
                cb += wt * w / wr * wt * v.im / wr;
            }
            if r != col {
                // No mass column: the one-parameter fit (the zero column's diagonal set to 1
                // keeps the system regular and gives M_kl = 0).
                ata[(1, 1)] = 1.0;
            }
            let sol = ata.lu().solve(&atb)?;
            m[r][col] = sol[1];
            k[r][col] = (sol[0] + sol[1]) * wr * wr;
            c[r][col] = cb / cc;
        }
    }
    let mass = [m[0][0], m[1][1]];
    let norm = (mass[0] * mass[1]).sqrt();
    let fit = MatrixFit {
        f0_hz: core::array::from_fn(|i| (k[i][i] / m[i][i]).sqrt() / tau),
        q: core::array::from_fn(|i| (k[i][i] * m[i][i]).sqrt() / c[i][i]),
        coupling_rad2_s2: k[0][1] / norm,
        coupling_21_rad2_s2: k[1][0] / norm,
        damping_coupling_rad_s: c[0][1] / norm,
        mass,
        frequencies: z.len(),
    };
    fit.f0_hz
        .iter()
        .chain(&fit.q)
        .all(|v| v.is_finite() && *v > 0.0)
        .then_some(fit)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of the coupled plant at rest, written out: velocity per force
    /// `j w (K - w^2 I + j w C)^-1` with `K = [[w1^2, k], [k, w2^2]]`, `C = diag(w1/Q1, w2/Q2)`,
    /// the 2 x 2 inverse by its adjugate; returned as `h[m][k]`.
    fn closed_form(f: [f64; 2], q: [f64; 2], k: f64, freq: f64) -> [[Complex64; 2]; 2] {
        let tau = std::f64::consts::TAU;
        let (w1, w2, w) = (tau * f[0], tau * f[1], tau * freq);
        let a = Complex64::new(w1 * w1 - w * w, w * w1 / q[0]);
        let d = Complex64::new(w2 * w2 - w * w, w * w2 / q[1]);
        let det = a * d - k * k;
        let jw = Complex64::new(0.0, w);
        // inverse = [[d, -k], [-k, a]] / det; h[m][k] = (row k, column m).
        let inv = [[d / det, -k / det], [-k / det, a / det]];
        [
            [inv[0][0] * jw, inv[1][0] * jw],
            [inv[0][1] * jw, inv[1][1] * jw],
        ]
    }

    #[test]
    fn recovers_a_coupled_plant_exactly() {
        let (f, q, k) = ([15e3, 15e3 + 0.5], [36000.0, 30000.0], 2e4);
        let freqs: Vec<f64> = (0..41).map(|i| 14998.0 + 0.125 * i as f64).collect();
        let h: Vec<_> = freqs.iter().map(|&x| closed_form(f, q, k, x)).collect();
        let fit = fit_matrix(&freqs, &h).unwrap();
        for i in 0..2 {
            assert!((fit.f0_hz[i] - f[i]).abs() < 1e-9, "{fit:?}");
            assert!((fit.q[i] / q[i] - 1.0).abs() < 1e-6, "{fit:?}");
            assert!((fit.mass[i] - 1.0).abs() < 1e-9, "{fit:?}");
        }
        assert!((fit.coupling_rad2_s2 / k - 1.0).abs() < 1e-6, "{fit:?}");
        assert!((fit.coupling_21_rad2_s2 / k - 1.0).abs() < 1e-6, "{fit:?}");
        assert!(fit.damping_coupling_rad_s.abs() < 1e-6, "{fit:?}");
    }

    #[test]
    fn an_uncoupled_plant_has_no_coupling_and_a_singular_response_is_skipped() {
        let (f, q) = ([1e3, 1.01e3], [50.0, 80.0]);
        let mut freqs: Vec<f64> = (0..21).map(|i| 990.0 + 1.5 * i as f64).collect();
        let mut h: Vec<_> = freqs.iter().map(|&x| closed_form(f, q, 0.0, x)).collect();
        // A frequency where nothing was read (a dead channel): not invertible, left out.
        freqs.push(1000.0);
        h.push([[Complex64::new(0.0, 0.0); 2]; 2]);
        let fit = fit_matrix(&freqs, &h).unwrap();
        assert_eq!(fit.frequencies, 21);
        assert!(fit.coupling_rad2_s2.abs() < 1e-6, "{fit:?}");
        assert!((fit.f0_hz[1] - f[1]).abs() < 1e-9 && (fit.q[0] / q[0] - 1.0).abs() < 1e-9);
    }
}
