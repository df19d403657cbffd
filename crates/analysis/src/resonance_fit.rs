//! The resonance fit of a measured frequency response: the second-order mode model
//! `g j w / (w0^2 - w^2 + j w w0 / Q)` (velocity per force of one mode, `g` = 1 once the chain
//! is divided out) fitted to complex data by a linearised least squares (Levy, then
//! Sanathanan-Koerner iterations), refined by Gauss-Newton on the plain complex residual, with
//! the standard errors of f0 and Q from the residuals.

use gyroemu_core::Complex64;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// Sanathanan-Koerner iterations at most (each reweights by the last denominator).
const SK_ITERATIONS: usize = 30;
/// Gauss-Newton iterations at most.
const GN_ITERATIONS: usize = 100;

/// The mode model at `f_hz`: `g j w / (w0^2 - w^2 + j w w0 / Q)`, `w = 2 pi f_hz`.
pub fn mode_response(f0_hz: f64, q: f64, gain: Complex64, f_hz: f64) -> Complex64 {
    let tau = core::f64::consts::TAU;
    let (w0, w) = (tau * f0_hz, tau * f_hz);
    let j = Complex64::new(0.0, 1.0);
    gain * j * w / Complex64::new((w0 - w) * (w0 + w), w * w0 / q)
}

/// A mode's fitted resonance.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ResonanceFit {
    /// Natural frequency, Hz.
    pub f0_hz: f64,
    /// Its standard error, Hz (from the residuals; 0 for an exact fit).
    pub f0_sigma_hz: f64,
    /// Quality factor.
    pub q: f64,
    /// Its standard error.
    pub q_sigma: f64,
    /// The complex gain `g`, real part (1 for a velocity-per-force response).
    pub gain_re: f64,
    /// The complex gain, imaginary part (0 for a velocity-per-force response).
    pub gain_im: f64,
    /// RMS of the complex residual over the largest response magnitude.
    pub rms_residual_rel: f64,
    /// Points fitted.
    pub points: usize,
}

impl ResonanceFit {
    /// The complex gain `g`.
    pub fn gain(&self) -> Complex64 {
        Complex64::new(self.gain_re, self.gain_im)
    }

    /// The fitted model at `f_hz`.
    pub fn response(&self, f_hz: f64) -> Complex64 {
        mode_response(self.f0_hz, self.q, self.gain(), f_hz)
    }

    /// Half-bandwidth f0/(2Q), Hz.
    pub fn half_bandwidth_hz(&self) -> f64 {
        self.f0_hz / (2.0 * self.q)
    }
}

/// The model in units of a reference frequency `fc`: `s = f / fc`, parameters
/// `p = [r, Q, G_re, G_im]` with `r = f0 / fc` and `G = g / (2 pi fc)`, so that
/// `M(s) = G j s / (r^2 - s^2 + j s r / Q)` (well scaled: every number near 1).
fn model(p: &[f64; 4], s: f64) -> (Complex64, Complex64) {
    let [r, q, gr, gi] = *p;
    // (r - s)(r + s): the difference near resonance without the cancellation of r^2 - s^2.
    let d = Complex64::new((r - s) * (r + s), s * r / q);
    let js = Complex64::new(0.0, s);
    (Complex64::new(gr, gi) * js / d, d)
}

/// The residuals `M(s_i) - H_i` (real parts, then imaginary parts) and their Jacobian in `p`.
fn residuals(p: &[f64; 4], s: &[f64], h: &[Complex64]) -> (DVector<f64>, DMatrix<f64>) {
    let n = s.len();
    let mut r = DVector::zeros(2 * n);
    let mut jac = DMatrix::zeros(2 * n, 4);
    let [rr, q, gr, gi] = *p;
    let g = Complex64::new(gr, gi);
    let j = Complex64::new(0.0, 1.0);
    for (i, (&si, &hi)) in s.iter().zip(h).enumerate() {
        let (m, d) = model(p, si);
        let e = m - hi;
        let js = j * si;
        let d2 = d * d;
        let cols = [
            // dM/dr = -G j s (2 r + j s / Q) / D^2
            -g * js * Complex64::new(2.0 * rr, si / q) / d2,
            // dM/dQ = G j s (j s r / Q^2) / D^2
            g * js * Complex64::new(0.0, si * rr / (q * q)) / d2,
            js / d,
            j * js / d,
        ];
        r[i] = e.re;
        r[n + i] = e.im;
        for (c, v) in cols.iter().enumerate() {
            jac[(i, c)] = v.re;
            jac[(n + i, c)] = v.im;
        }
    }
    (r, jac)
}

/// Least-squares solution of `a x = b` (SVD of the column-equilibrated `a`, so parameters of
/// very different sizes keep their precision), `None` if it is not finite.
fn lstsq(mut a: DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    let norms: Vec<f64> = a.column_iter().map(|c| c.norm()).collect();
    for (mut c, &n) in a.column_iter_mut().zip(&norms) {
        if n > 0.0 {
            c /= n;
        }
    }
    let mut x = a.svd(true, true).solve(b, 0.0).ok()?;
    for (v, &n) in x.iter_mut().zip(&norms) {
        if n > 0.0 {
            *v /= n;
        }
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The linearised fit (Levy, reweighted by Sanathanan-Koerner): `H (B - s^2 + j s A) = G j s`
/// is linear in `(B, A, G)`; each pass weights a point by `1 / |B - s^2 + j s A|` of the last
/// pass, which turns the equation error into the model error. Returns `[r, Q, G_re, G_im]`.
fn sanathanan_koerner(s: &[f64], h: &[Complex64]) -> Option<[f64; 4]> {
    let n = s.len();
    let mut prev: Option<[f64; 4]> = None;
    let mut x4 = [0.0; 4];
    for _ in 0..SK_ITERATIONS {
        let mut a = DMatrix::zeros(2 * n, 4);
        let mut b = DVector::zeros(2 * n);
        for (i, (&si, &hi)) in s.iter().zip(h).enumerate() {
            let w = match prev {
                Some([bb, aa, _, _]) => 1.0 / Complex64::new(bb - si * si, si * aa).norm(),
                None => 1.0,
            };
            // Real part: h_r B - s h_i A + s G_i = h_r s^2; imaginary part:
            // h_i B + s h_r A - s G_r = h_i s^2.
            a[(i, 0)] = w * hi.re;
            a[(i, 1)] = -w * si * hi.im;
            a[(i, 3)] = w * si;
            b[i] = w * hi.re * si * si;
            a[(n + i, 0)] = w * hi.im;
            a[(n + i, 1)] = w * si * hi.re;
            a[(n + i, 2)] = -w * si;
            b[n + i] = w * hi.im * si * si;
        }
        let x = lstsq(a, &b)?;
        x4 = [x[0], x[1], x[2], x[3]];
        let done = prev.is_some_and(|p| {
            (0..2).all(|k| (x4[k] - p[k]).abs() <= 1e-15 * x4[k].abs().max(1e-300))
        });
        prev = Some(x4);
        if done {
            break;
        }
    }
    let [bb, aa, gr, gi] = x4;
    if !(bb > 0.0 && aa > 0.0) {
        return None;
    }
    let r = bb.sqrt();
    Some([r, r / aa, gr, gi])
}

/// Fits the mode model to the complex response `h` at `f_hz` (finite points only; at least
/// three). `None` when there are too few points or no resonance (a fitted f0^2 or damping
/// that is not positive).
pub fn fit_resonance(f_hz: &[f64], h: &[Complex64]) -> Option<ResonanceFit> {
    let (f, h): (Vec<f64>, Vec<Complex64>) = f_hz
        .iter()
        .zip(h)
        .filter(|(f, h)| f.is_finite() && **f > 0.0 && h.re.is_finite() && h.im.is_finite())
        .map(|(f, h)| (*f, *h))
        .unzip();
    let n = f.len();
    if n < 3 {
        return None;
    }
    // The reference frequency: the largest response (near the resonance); the data in units
    // of that response.
    let peak = (0..n).max_by(|&a, &b| h[a].norm().total_cmp(&h[b].norm()))?;
    let fc = f[peak];
    let hmax = h[peak].norm();
    if hmax.is_nan() || hmax <= 0.0 {
        return None;
    }
    let h: Vec<Complex64> = h.iter().map(|v| v / hmax).collect();
    let s: Vec<f64> = f.iter().map(|x| x / fc).collect();
    let mut p = sanathanan_koerner(&s, &h)?;
    let cost = |p: &[f64; 4]| residuals(p, &s, &h).0.norm_squared();
    let mut c = cost(&p);
    for _ in 0..GN_ITERATIONS {
        let (r, jac) = residuals(&p, &s, &h);
        let Some(step) = lstsq(jac, &(-r)) else { break };
        // Halve the step until the cost does not rise (the linearised start is close, so the
        // full step nearly always holds).
        let mut t = 1.0;
        let mut accepted = false;
        for _ in 0..30 {
            let trial: [f64; 4] = core::array::from_fn(|k| p[k] + t * step[k]);
            let ct = cost(&trial);
            if trial[0] > 0.0 && trial[1] > 0.0 && ct <= c {
                p = trial;
                c = ct;
                accepted = true;
                break;
            }
            t *= 0.5;
        }
        let small = (0..2).all(|k| (t * step[k]).abs() <= 1e-15 * p[k].abs());
        if !accepted || small {
            break;
        }
    }
    let (_, jac) = residuals(&p, &s, &h);
    // Standard errors: the residual variance per real equation times (J^T J)^-1, from the SVD
    // of J (J = U S V^T: (J^T J)^-1 = V S^-2 V^T), its columns equilibrated.
    let dof = (2 * n).saturating_sub(4).max(1) as f64;
    let var = c / dof;
    let norms: Vec<f64> = jac.column_iter().map(|c| c.norm()).collect();
    let mut scaled = jac;
    for (mut col, &nm) in scaled.column_iter_mut().zip(&norms) {
        col /= nm;
    }
    let svd = scaled.svd(false, true);
    let v_t = svd.v_t?;
    let sigma = |k: usize| {
        let sum: f64 = (0..4)
            .map(|i| (v_t[(i, k)] / svd.singular_values[i]).powi(2))
            .sum();
        (var * sum).sqrt() / norms[k]
    };
    let g = Complex64::new(p[2], p[3]) * (core::f64::consts::TAU * fc * hmax);
    Some(ResonanceFit {
        f0_hz: p[0] * fc,
        f0_sigma_hz: sigma(0) * fc,
        q: p[1],
        q_sigma: sigma(1),
        gain_re: g.re,
        gain_im: g.im,
        rms_residual_rel: (c / n as f64).sqrt(),
        points: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form written out on its own (not through `mode_response`): velocity per
    /// force of `q'' + (w0/Q) q' + w0^2 q = f`, i.e. `j w / (w0^2 - w^2 + j w w0 / Q)`.
    fn closed_form(f0: f64, q: f64, f: f64) -> Complex64 {
        let (w0, w) = (
            2.0 * std::f64::consts::PI * f0,
            2.0 * std::f64::consts::PI * f,
        );
        let den = Complex64::new(w0 * w0 - w * w, w * w0 / q);
        Complex64::new(0.0, w) / den
    }

    fn grid(f0: f64, q: f64, n: usize, span: f64) -> Vec<f64> {
        let b = f0 / (2.0 * q);
        (0..n)
            .map(|i| f0 + b * span * (2.0 * i as f64 / (n - 1) as f64 - 1.0))
            .collect()
    }

    #[test]
    fn recovers_the_closed_form_exactly() {
        for (f0, q, g) in [
            (15e3, 2000.0, Complex64::new(1.0, 0.0)),
            (15e3, 36000.0, Complex64::new(-0.3, 2.0)),
            (3e6, 10000.0, Complex64::new(1e-6, 0.0)),
            (1e3, 5.0, Complex64::new(1.0, 0.0)),
        ] {
            // Off-centre and uneven: the fit must not rely on a symmetric grid.
            let f: Vec<f64> = grid(f0, q, 41, 7.0)
                .into_iter()
                .map(|x| x + 0.37 * f0 / (2.0 * q))
                .collect();
            let h: Vec<Complex64> = f.iter().map(|&x| g * closed_form(f0, q, x)).collect();
            let fit = fit_resonance(&f, &h).unwrap();
            assert!((fit.f0_hz / f0 - 1.0).abs() < 1e-13, "{fit:?}");
            assert!((fit.q / q - 1.0).abs() < 1e-9, "{fit:?}");
            assert!((fit.gain() - g).norm() < 1e-9 * g.norm(), "{fit:?}");
            // The data's own rounding: w0^2 - w^2 loses about 2Q ulps near resonance.
            assert!(fit.rms_residual_rel < 1e-15 * q, "{fit:?}");
            // Exact data: the standard errors vanish with the residual.
            assert!(fit.f0_sigma_hz < 1e-9 * fit.half_bandwidth_hz(), "{fit:?}");
        }
    }

    #[test]
    fn noise_is_reported_in_the_standard_errors() {
        // Additive complex noise of 1e-3 of the peak on 101 points, seeded (a fixed LCG keeps
        // the test deterministic): the estimates scatter about the truth by their sigma.
        let (f0, q) = (15e3, 2000.0);
        let f = grid(f0, q, 101, 10.0);
        let peak = q / (2.0 * std::f64::consts::PI * f0);
        let mut state = 12345u64;
        let mut u = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (mut zf, mut zq) = (Vec::new(), Vec::new());
        for _ in 0..40 {
            let h: Vec<Complex64> = f
                .iter()
                .map(|&x| closed_form(f0, q, x) + Complex64::new(u(), u()) * 3.46e-3 * peak)
                .collect();
            let fit = fit_resonance(&f, &h).unwrap();
            zf.push((fit.f0_hz - f0) / fit.f0_sigma_hz);
            zq.push((fit.q - q) / fit.q_sigma);
        }
        // The normalised errors have unit variance (within the scatter of 40 draws).
        for z in [zf, zq] {
            let var = z.iter().map(|v| v * v).sum::<f64>() / z.len() as f64;
            eprintln!("normalised error variance {var}");
            assert!(var > 0.5 && var < 1.7, "{var} {z:?}");
        }
    }

    #[test]
    fn no_resonance_or_too_few_points_gives_none() {
        let f = [1.0, 2.0];
        let h = [Complex64::new(1.0, 0.0); 2];
        assert!(fit_resonance(&f, &h).is_none());
        // A flat response has no positive damping and stiffness to find.
        let f: Vec<f64> = (1..20).map(|i| i as f64).collect();
        let h = vec![Complex64::new(1.0, 0.0); f.len()];
        assert!(fit_resonance(&f, &h).is_none());
        // Non-finite points are dropped, not fitted.
        let (f0, q) = (100.0, 50.0);
        let mut f = grid(f0, q, 21, 6.0);
        let mut h: Vec<Complex64> = f.iter().map(|&x| closed_form(f0, q, x)).collect();
        f.push(f64::NAN);
        h.push(Complex64::new(f64::NAN, 0.0));
        let fit = fit_resonance(&f, &h).unwrap();
        assert_eq!(fit.points, 21);
        assert!((fit.f0_hz / f0 - 1.0).abs() < 1e-12);
    }
}
