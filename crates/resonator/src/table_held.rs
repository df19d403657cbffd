//! The periodic steady state of the board's own rate-table recursion: the exactly discretised
//! plant with the drive held over each sample and the step expanded to second order in the
//! rate (`x[n+1] = (E0 + d E1 + d^2 E2) [x[n]; u[n]]`, `d` the rate at the step's midpoint
//! less the expansion centre), by harmonic balance in discrete time. What a noiseless board
//! with ideal converters settles to on a sinusoidal table, hold and step included: the exact
//! figure against which the continuous theory ([`crate::rate_table_steady_state`]) is off.

use crate::discretise::scales;
use crate::Resonator;
use gyroemu_core::detmath::sin_cos_turns;
use gyroemu_core::Complex64;
use nalgebra::{SMatrix, SVector};

/// Sampled states `x[n] = Re{sum_k X_k e^{j (w_c + k w_t) n Ts}}` of `plant` (a rate-table
/// plant: its expansion about `plant.omega_z_rad_s()`) under the held drive `u[n] = Re{F e^{j
/// w_c n Ts}}` and the rate `amplitude sin(w_t (n + 1/2) Ts)` held over step `n` (the board's
/// table oscillator runs half a sample ahead): `X_{-N} .. X_N` of `[q1, q2, v1, v2]`. With
/// `M(d) = sum_p e^{j p w_t n Ts} M_p` (`p` in `-2 ..= 2`), harmonic `k` balances as
/// `e^{j (w_c + k w_t) Ts} X_k = sum_p Mx_p X_{k-p} + Mu_k F`, solved in the balanced
/// coordinates. NaN where singular.
pub fn held_table_steady_state(
    plant: &Resonator<f64>,
    amplitude_rad_s: f64,
    table_hz: f64,
    carrier_hz: f64,
    force: [Complex64; 2],
    harmonics: usize,
) -> Vec<[Complex64; 4]> {
    let zero = Complex64::new(0.0, 0.0);
    let nb = 2 * harmonics + 1;
    let fs = plant.params().fs_hz;
    let s = scales(plant.params());
    let [e0, e1, e2] = plant.expansion();
    // d[n] = c0 + sum_{p = +-1} delta_p e^{j p w_t n Ts}: A sin(w_t (n + 1/2) Ts) - centre.
    let (sh, ch) = sin_cos_turns(0.5 * table_hz / fs);
    let half = Complex64::new(ch, sh); // e^{j w_t Ts / 2}
    let up = Complex64::new(0.0, -0.5 * amplitude_rad_s) * half; // A / 2j e^{j w_t Ts/2}
                                                                 // d is real: the coefficient of e^{-j w_t n Ts} is the conjugate of that of e^{+j ...}.
    let delta = [up.conj(), Complex64::new(-plant.omega_z_rad_s(), 0.0), up];
    let mut gamma = [zero; 5];
    for (p1, d1) in delta.iter().enumerate() {
        for (p2, d2) in delta.iter().enumerate() {
            gamma[p1 + p2] += d1 * d2;
        }
    }
    // M_p[i][col], p in -2 ..= 2.
    let m = |p: i32, i: usize, col: usize| {
        let mut v = gamma[(p + 2) as usize] * e2[i][col];
        if p.abs() <= 1 {
            v += delta[(p + 1) as usize] * e1[i][col];
        }
        if p == 0 {
            v += e0[i][col];
        }
        v
    };
    // The system's entry at (row, col) over harmonics b, b' (4 states each); the unknowns of
    // a padded harmonic nb (when nb is odd) are pinned to zero.
    let entry = |row: usize, col: usize| -> Complex64 {
        let (bk, i) = (row / 4, row % 4);
        let (bl, j) = (col / 4, col % 4);
        if bk >= nb || bl >= nb {
            return if row == col {
                Complex64::new(1.0, 0.0)
            } else {
                zero
            };
        }
        let p = bk as i32 - bl as i32;
        let mut v = if p.abs() <= 2 {
            m(p, i, j) * (s[i] / s[j])
        } else {
            zero
        };
        if row == col {
            let k = bk as f64 - harmonics as f64;
            let (sn, cs) = sin_cos_turns((carrier_hz + k * table_hz) / fs);
            v -= Complex64::new(cs, sn);
        }
        v
    };
    let rhs = |row: usize| -> Complex64 {
        let (bk, i) = (row / 4, row % 4);
        let k = bk as i32 - harmonics as i32;
        if bk >= nb || k.abs() > 2 {
            return zero;
        }
        -(0..2).map(|f| m(k, i, 4 + f) * force[f]).sum::<Complex64>() * s[i]
    };
    // Pairs of harmonics make 8-state blocks, and the balance (coupling harmonics at most two
    // apart) block tridiagonal: block Thomas, O(N), each block's LU pivoted. The blocks far
    // from the carrier are far from resonance, as in the continuous balance.
    type M8 = SMatrix<Complex64, 8, 8>;
    type V8 = SVector<Complex64, 8>;
    let blocks = nb.div_ceil(2);
    let block = |r: usize, c: usize| M8::from_fn(|i, j| entry(8 * r + i, 8 * c + j));
    let nan = [Complex64::new(f64::NAN, f64::NAN); 4];
    let mut cs: Vec<M8> = Vec::with_capacity(blocks);
    let mut ds: Vec<V8> = Vec::with_capacity(blocks);
    for b in 0..blocks {
        let r = V8::from_fn(|i, _| rhs(8 * b + i));
        let (m, r) = if b == 0 {
            (block(0, 0), r)
        } else {
            let lower = block(b, b - 1);
            (block(b, b) - lower * cs[b - 1], r - lower * ds[b - 1])
        };
        let upper = if b + 1 < blocks {
            block(b, b + 1)
        } else {
            M8::zeros()
        };
        let lu = m.lu();
        let (Some(cb), Some(db)) = (lu.solve(&upper), lu.solve(&r)) else {
            return vec![nan; nb];
        };
        cs.push(cb);
        ds.push(db);
    }
    let mut x = vec![V8::zeros(); blocks];
    x[blocks - 1] = ds[blocks - 1];
    for b in (0..blocks - 1).rev() {
        x[b] = ds[b] - cs[b] * x[b + 1];
    }
    (0..nb)
        .map(|h| core::array::from_fn(|i| x[h / 2][4 * (h % 2) + i] / s[i]))
        .collect()
}
