//! The noise-model fit of an Allan variance curve (IEEE Std 952-1997 Annex C, IEEE Std 1554):
//! sigma^2(tau) = N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 (+ 3 Q^2 / tau^2), the sum of
//! independent angle random walk N, bias instability B, rate random walk K (and angle
//! quantisation Q), which is linear in their squares. It reads N where the curve never runs
//! along -1/2 (a flicker floor under the white region), which the slope reading cannot.

use super::{AllanPoint, ARW_UNIT, B_UNIT};
use gyroemu_core::sig3;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// Two-sided 95 % normal quantile.
const Z95: f64 = 1.959_963_984_540_054;

/// Least points per fitted coefficient plus this many: a fit through barely more points than
/// terms has no residual to speak of.
const SPARE_POINTS: usize = 2;

/// Relative spacing of the frequency grid of the covariance integral: fine enough that
/// `sin^4(pi nu m)` is resolved where `nu m < OSCILLATION_AVERAGED` (1/16 of its period).
const GRID_RATIO: f64 = 1.0 / 128.0;

/// Above this many periods of `sin^4(pi nu m)` the factor is replaced by its mean 3/8: the
/// integrand there is below 1e-5 of the whole and the grid need not resolve it.
const OSCILLATION_AVERAGED: f64 = 8.0;

/// Reweighting passes (weights from the model, not from the scattered points themselves: a
/// point that happens to read low would weigh more and pull the fit down).
const PASSES: usize = 4;

/// The fitted noise terms of an Allan deviation curve of a rate in deg/s. A term that the
/// curve does not determine (its 95 % interval reaches 0, or it was held at 0 by the
/// non-negativity constraint) is NaN (null in JSON) with a warning, and its interval is
/// `[0, upper bound]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NoiseModelFit {
    /// Angle random walk N, deg/sqrt(h) (60 x deg/s*sqrt(s)).
    pub arw_deg_per_rt_h: f64,
    /// Its 95 % interval `[low, high]`, deg/sqrt(h) (the interval of N^2, square-rooted: not
    /// symmetric about N).
    pub arw_deg_per_rt_h_ci95: [f64; 2],
    pub arw_warning: Option<&'static str>,
    /// Bias instability B, deg/h (its term is the flicker floor (2 ln 2 / pi) B^2).
    pub bias_instability_deg_per_h: f64,
    pub bias_instability_deg_per_h_ci95: [f64; 2],
    pub bias_instability_warning: Option<&'static str>,
    /// Rate random walk K, deg/h/sqrt(h) (216 000 x deg/s/sqrt(s)).
    pub rate_random_walk_deg_per_h_per_rt_h: f64,
    pub rate_random_walk_deg_per_h_per_rt_h_ci95: [f64; 2],
    pub rate_random_walk_warning: Option<&'static str>,
    /// Angle quantisation Q, deg (its term 3 Q^2 / tau^2, slope -1: also white angle noise),
    /// when the 1/tau^2 coefficient is determined and positive.
    pub quantisation_deg: f64,
    pub quantisation_deg_ci95: [f64; 2],
    pub quantisation_warning: Option<&'static str>,
    /// The fitted 1/tau^2 coefficient C = 3 Q^2, (deg/s)^2 s^2, with its 95 % interval (NaN
    /// when the term is not in the model). On a curve that rose before its fitted part it is
    /// fitted with either sign: past the rise a low-pass of time constant t still takes
    /// 1.5 t N^2 / tau^2 off the white term (15 % at ten time constants).
    pub tau_minus2_coefficient_dps2_s2: f64,
    pub tau_minus2_coefficient_dps2_s2_ci95: [f64; 2],
    /// The taus fitted, s: the first and the last point.
    pub tau_min_s: f64,
    pub tau_max_s: f64,
    /// How many points of the curve were fitted.
    pub points: usize,
    /// Why no fit was made (`None` when it was).
    pub warning: Option<&'static str>,
    /// The estimates of N^2, B^2, K^2, Q^2 as fitted ((deg/s)^2 s, (deg/s)^2, (deg/s)^2 / s,
    /// deg^2; 0 for a term held at 0 or left out), undetermined ones included: the fitted
    /// curve.
    #[serde(skip)]
    pub fitted: [f64; 4],
}

impl NoiseModelFit {
    /// No fit, for the reason given.
    pub fn not_fitted(why: &'static str) -> Self {
        Self {
            arw_deg_per_rt_h: f64::NAN,
            arw_deg_per_rt_h_ci95: [f64::NAN; 2],
            arw_warning: None,
            bias_instability_deg_per_h: f64::NAN,
            bias_instability_deg_per_h_ci95: [f64::NAN; 2],
            bias_instability_warning: None,
            rate_random_walk_deg_per_h_per_rt_h: f64::NAN,
            rate_random_walk_deg_per_h_per_rt_h_ci95: [f64::NAN; 2],
            rate_random_walk_warning: None,
            quantisation_deg: f64::NAN,
            quantisation_deg_ci95: [f64::NAN; 2],
            quantisation_warning: None,
            tau_minus2_coefficient_dps2_s2: f64::NAN,
            tau_minus2_coefficient_dps2_s2_ci95: [f64::NAN; 2],
            tau_min_s: f64::NAN,
            tau_max_s: f64::NAN,
            points: 0,
            warning: Some(why),
            fitted: [f64::NAN; 4],
        }
    }

    /// The fitted Allan deviation at `tau`, deg/s (NaN without a fit).
    pub fn adev_dps(&self, tau_s: f64) -> f64 {
        if self.warning.is_some() {
            return f64::NAN;
        }
        model_at(&self.fitted, tau_s).max(0.0).sqrt()
    }

    /// One line naming each determined term with its interval, e.g. for a run's warnings:
    /// `N = 2.10 deg/sqrt(h) (95 %: 2.00 to 2.20), B = ...`. `None` without a fit.
    pub fn summary(&self) -> Option<String> {
        if self.warning.is_some() {
            return None;
        }
        let term = |name: &str, v: f64, ci: [f64; 2], unit: &str| {
            if v.is_finite() {
                format!(
                    "{name} = {} {unit} (95 %: {} to {})",
                    sig3(v),
                    sig3(ci[0]),
                    sig3(ci[1])
                )
            } else {
                format!("{name} below {} {unit} (not determined)", sig3(ci[1]))
            }
        };
        let mut parts = vec![
            term(
                "N",
                self.arw_deg_per_rt_h,
                self.arw_deg_per_rt_h_ci95,
                "deg/sqrt(h)",
            ),
            term(
                "B",
                self.bias_instability_deg_per_h,
                self.bias_instability_deg_per_h_ci95,
                "deg/h",
            ),
            term(
                "K",
                self.rate_random_walk_deg_per_h_per_rt_h,
                self.rate_random_walk_deg_per_h_per_rt_h_ci95,
                "deg/h/sqrt(h)",
            ),
        ];
        if self.quantisation_deg.is_finite() {
            parts.push(term(
                "Q",
                self.quantisation_deg,
                self.quantisation_deg_ci95,
                "deg",
            ));
        }
        Some(format!(
            "{}; fitted over tau {} to {} s ({} points)",
            parts.join(", "),
            sig3(self.tau_min_s),
            sig3(self.tau_max_s),
            self.points
        ))
    }
}

/// deg/h/sqrt(h) per deg/s/sqrt(s): 3600 x 60.
const K_UNIT: f64 = B_UNIT * ARW_UNIT;

/// The terms of the model, in the order of the coefficients (N^2, B^2, K^2, Q^2).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Term {
    Arw,
    Bias,
    Rrw,
    Quant,
}

const TERMS: [Term; 4] = [Term::Arw, Term::Bias, Term::Rrw, Term::Quant];

impl Term {
    /// Its Allan variance per unit coefficient at `tau`.
    fn basis(self, tau: f64) -> f64 {
        match self {
            Term::Arw => 1.0 / tau,
            Term::Bias => 2.0 * core::f64::consts::LN_2 / core::f64::consts::PI,
            Term::Rrw => tau / 3.0,
            Term::Quant => 3.0 / (tau * tau),
        }
    }

    /// Its two-sided density per unit coefficient at `nu` cycles per sample, for block means
    /// of the rate over `tau0` (white rate N^2 / tau0; flicker B^2 / (2 pi nu); rate random
    /// walk K^2 tau0 / (2 pi nu)^2; white angle, differenced, 4 sin^2(pi nu) Q^2 / tau0^2).
    fn density(self, nu: f64, tau0: f64) -> f64 {
        use core::f64::consts::PI;
        match self {
            Term::Arw => 1.0 / tau0,
            Term::Bias => 1.0 / (2.0 * PI * nu),
            Term::Rrw => tau0 / (2.0 * PI * nu).powi(2),
            Term::Quant => 4.0 * (PI * nu).sin().powi(2) / (tau0 * tau0),
        }
    }
}

/// A weighted least-squares solution on a set of terms.
struct Solution {
    /// Coefficient of each of [`TERMS`] (0 for a term left out).
    theta: [f64; 4],
    /// Which terms were fitted.
    active: [bool; 4],
    /// Weighted sum of squared residuals.
    sse: f64,
}

/// Fits the model to `pts` (an Allan deviation curve of a rate in deg/s, `n_terms` summed
/// over pooled records, at sample interval `tau0`): weighted non-negative least squares in the
/// squared coefficients, each point weighted by the inverse variance of its Allan variance,
/// `2 sigma^4 / d` with `d` its independent differences (`n_terms tau0 / tau`, the
/// degrees-of-freedom bound the readings use) and sigma^2 from the model (reweighted from the
/// fit). The 95 % intervals are the coefficients' +- 1.96 standard errors from the sandwich
/// covariance of that fit, with the covariance of the Allan variances between taus (adjacent
/// points of an overlapping curve share most of their data) from the fitted model's spectrum:
/// `cov(s_i, s_j) = (1 / M) int_0^(1/2) |G_i|^2 |G_j|^2 S^2 dnu`, `G_m` the response of the
/// difference of two adjacent means of m samples and M the larger `n_terms` (the asymptotic
/// variance of a quadratic form of a Gaussian series).
///
/// The 1/tau^2 term: on a curve that `rose` before `pts` (a resonator's or filter's roll-off)
/// it is always fitted, with either sign, since a first-order low-pass of time constant t
/// leaves sigma^2 = N^2 / tau - 1.5 t N^2 / tau^2 past a few t (the white term alone read N
/// about 5 % low on the worked example, its interval missing the value the noise densities
/// give). Otherwise it is the angle quantisation 3 Q^2 / tau^2 of IEEE Std 952, kept only if
/// the fit determines it.
pub fn fit_noise_model(pts: &[AllanPoint], tau0: f64, rose: bool) -> NoiseModelFit {
    if pts.len() < 3 + SPARE_POINTS {
        return NoiseModelFit::not_fitted(
            "fewer than 5 reliable points past the Allan curve's initial rise (40 independent \
             differences or more): too few to fit the noise model",
        );
    }
    if rose {
        return fit_terms(pts, tau0, [true; 4], true)
            .map(|mut f| {
                let c = f.tau_minus2_coefficient_dps2_s2_ci95;
                if c[1] < 0.0 {
                    f.quantisation_warning = Some(
                        "the 1/tau^2 term, fitted with either sign past the curve's initial \
                         rise, is negative: the remnant of that roll-off, not quantisation",
                    );
                } else if f.quantisation_deg.is_nan() {
                    f.quantisation_warning = Some(
                        "not determined: the 1/tau^2 term, fitted with either sign past the \
                         curve's initial rise (the roll-off's remnant is negative), has a 95 % \
                         interval reaching 0",
                    );
                }
                f
            })
            .unwrap_or_else(singular);
    }
    let with_q = fit_terms(pts, tau0, [true; 4], false);
    let q_earns = with_q
        .as_ref()
        .is_some_and(|f| f.quantisation_deg.is_finite());
    let fit = if q_earns {
        with_q
    } else {
        fit_terms(pts, tau0, [true, true, true, false], false).map(|mut f| {
            f.quantisation_warning = Some(
                "not fitted: the quantisation term (3 Q^2 / tau^2) was held at 0 or its 95 % \
                 interval reached 0, so the model was refitted without it",
            );
            f
        })
    };
    fit.unwrap_or_else(singular)
}

fn singular() -> NoiseModelFit {
    NoiseModelFit::not_fitted("the noise model's normal equations are singular on these points")
}

/// [`fit_noise_model`] on the terms `allowed`, the 1/tau^2 one of either sign if `signed`.
fn fit_terms(
    pts: &[AllanPoint],
    tau0: f64,
    allowed: [bool; 4],
    signed: bool,
) -> Option<NoiseModelFit> {
    let n = pts.len();
    let avar: Vec<f64> = pts.iter().map(|p| p.adev * p.adev).collect();
    let independent: Vec<f64> = pts
        .iter()
        .map(|p| p.n_terms as f64 * tau0 / p.tau_s)
        .collect();
    let floor = avar.iter().cloned().fold(0.0, f64::max) * 1e-12;
    let weights = |model: &[f64]| -> Vec<f64> {
        model
            .iter()
            .zip(&independent)
            .map(|(s, d)| d / (2.0 * s.max(floor).powi(2)))
            .collect()
    };
    let mut w = weights(&avar);
    let mut best = nnls(pts, &avar, &w, allowed, signed)?;
    for _ in 1..PASSES {
        let model: Vec<f64> = pts.iter().map(|p| model_at(&best.theta, p.tau_s)).collect();
        w = weights(&model);
        best = nnls(pts, &avar, &w, allowed, signed)?;
    }
    // The covariance of the coefficients, on the active terms and, for each held term, on the
    // active terms and it (its unconstrained estimate and standard error bound it).
    let cov_avar = avar_covariance(pts, tau0, &best.theta);
    let (est, se) = sandwich(pts, &w, &cov_avar, best.active)?;
    let mut out = NoiseModelFit::not_fitted("");
    out.warning = None;
    out.tau_min_s = pts[0].tau_s;
    out.tau_max_s = pts[n - 1].tau_s;
    out.points = n;
    out.fitted = best.theta;
    if allowed[3] && best.active[3] {
        let (c, h) = (3.0 * est[3], 3.0 * Z95 * se[3]);
        out.tau_minus2_coefficient_dps2_s2 = c;
        out.tau_minus2_coefficient_dps2_s2_ci95 = [c - h, c + h];
    }
    for (k, term) in TERMS.iter().enumerate() {
        let unit = match term {
            Term::Arw => ARW_UNIT,
            Term::Bias => B_UNIT,
            Term::Rrw => K_UNIT,
            Term::Quant => 1.0,
        };
        let (value, ci, warning): (f64, [f64; 2], Option<&'static str>) = if !allowed[k] {
            (f64::NAN, [f64::NAN; 2], None)
        } else if best.active[k] {
            let (t, s) = (est[k], se[k]);
            let (lo, hi) = (t - Z95 * s, t + Z95 * s);
            if lo > 0.0 {
                (unit * t.sqrt(), [unit * lo.sqrt(), unit * hi.sqrt()], None)
            } else {
                (
                    f64::NAN,
                    [0.0, unit * hi.max(0.0).sqrt()],
                    Some(
                        "not determined: its 95 % interval reaches 0 (the interval's upper end \
                         bounds it)",
                    ),
                )
            }
        } else {
            let mut with = best.active;
            with[k] = true;
            let bound = sandwich(pts, &w, &cov_avar, with)
                .map_or(f64::NAN, |(e, s)| e[k].max(0.0) + Z95 * s[k]);
            (
                f64::NAN,
                [0.0, unit * bound.sqrt()],
                Some(
                    "not determined: held at 0 by the non-negative fit (the interval's upper \
                     end, from the fit with it free, bounds it)",
                ),
            )
        };
        match term {
            Term::Arw => {
                out.arw_deg_per_rt_h = value;
                out.arw_deg_per_rt_h_ci95 = ci;
                out.arw_warning = warning;
            }
            Term::Bias => {
                out.bias_instability_deg_per_h = value;
                out.bias_instability_deg_per_h_ci95 = ci;
                out.bias_instability_warning = warning;
            }
            Term::Rrw => {
                out.rate_random_walk_deg_per_h_per_rt_h = value;
                out.rate_random_walk_deg_per_h_per_rt_h_ci95 = ci;
                out.rate_random_walk_warning = warning;
            }
            Term::Quant => {
                out.quantisation_deg = value;
                out.quantisation_deg_ci95 = ci;
                out.quantisation_warning = warning;
            }
        }
    }
    Some(out)
}

fn model_at(theta: &[f64; 4], tau: f64) -> f64 {
    TERMS
        .iter()
        .zip(theta)
        .map(|(t, th)| th * t.basis(tau))
        .sum()
}

/// The design of `active` terms at `pts`, each column scaled to unit weighted norm (the
/// coefficients span many decades), with the scales.
fn design(
    pts: &[AllanPoint],
    w: &[f64],
    active: [bool; 4],
) -> (DMatrix<f64>, Vec<usize>, Vec<f64>) {
    let cols: Vec<usize> = (0..4).filter(|&k| active[k]).collect();
    let mut x = DMatrix::<f64>::zeros(pts.len(), cols.len());
    let mut scales = Vec::with_capacity(cols.len());
    for (c, &k) in cols.iter().enumerate() {
        let g: Vec<f64> = pts.iter().map(|p| TERMS[k].basis(p.tau_s)).collect();
        let s = g.iter().zip(w).map(|(g, w)| w * g * g).sum::<f64>().sqrt();
        for (i, g) in g.iter().enumerate() {
            x[(i, c)] = g / s;
        }
        scales.push(s);
    }
    (x, cols, scales)
}

/// Weighted least squares of `y` on the `active` terms. `None` if singular.
fn wls(pts: &[AllanPoint], y: &[f64], w: &[f64], active: [bool; 4]) -> Option<Solution> {
    let (x, cols, scales) = design(pts, w, active);
    let wd = DVector::from_column_slice(w);
    let xtw = x.transpose() * DMatrix::from_diagonal(&wd);
    let beta = (&xtw * &x)
        .cholesky()?
        .solve(&(&xtw * DVector::from_column_slice(y)));
    let mut theta = [0.0; 4];
    for (c, &k) in cols.iter().enumerate() {
        theta[k] = beta[c] / scales[c];
    }
    let sse = pts
        .iter()
        .zip(y)
        .zip(w)
        .map(|((p, y), w)| w * (y - model_at(&theta, p.tau_s)).powi(2))
        .sum();
    Some(Solution { theta, active, sse })
}

/// Non-negative least squares over at most four terms (the 1/tau^2 one free if `signed`): the
/// feasible unconstrained solution of least residual among every subset of the `allowed`
/// terms (the constrained optimum is the unconstrained one on its own support).
fn nnls(
    pts: &[AllanPoint],
    y: &[f64],
    w: &[f64],
    allowed: [bool; 4],
    signed: bool,
) -> Option<Solution> {
    (1u32..16)
        .map(|mask| core::array::from_fn(|k| mask & (1 << k) != 0))
        .filter(|a: &[bool; 4]| (0..4).all(|k| allowed[k] || !a[k]))
        .filter(|a| a.iter().filter(|&&b| b).count() + SPARE_POINTS <= pts.len())
        .filter_map(|a| wls(pts, y, w, a))
        .filter(|s| (0..4).all(|k| s.theta[k] >= 0.0 || (signed && k == 3)))
        .min_by(|a, b| a.sse.total_cmp(&b.sse))
}

/// Estimates and standard errors of the coefficients of the `active` terms (indexed as
/// [`TERMS`]) of a weighted least-squares fit, from the covariance `cov` of the Allan
/// variances: (X'WX)^-1 X'W C W X (X'WX)^-1.
fn sandwich(
    pts: &[AllanPoint],
    w: &[f64],
    cov: &DMatrix<f64>,
    active: [bool; 4],
) -> Option<([f64; 4], [f64; 4])> {
    let avar: Vec<f64> = pts.iter().map(|p| p.adev * p.adev).collect();
    let (x, cols, scales) = design(pts, w, active);
    let xtw = x.transpose() * DMatrix::from_diagonal(&DVector::from_column_slice(w));
    let bread = (&xtw * &x).cholesky()?.inverse();
    let beta = &bread * (&xtw * DVector::from_column_slice(&avar));
    let v = &bread * &xtw * cov * xtw.transpose() * &bread;
    let (mut est, mut se) = ([f64::NAN; 4], [f64::NAN; 4]);
    for (c, &k) in cols.iter().enumerate() {
        est[k] = beta[c] / scales[c];
        se[k] = v[(c, c)].max(0.0).sqrt() / scales[c];
    }
    Some((est, se))
}

/// The covariance of the Allan variance estimates at `pts` for a series of the model
/// `theta` (two-sided density `sum theta_k S_k(nu)`), Gaussian, long next to each tau:
/// `C_ij = (1 / M_ij) int_0^(1/2) |G_i|^2 |G_j|^2 S^2 dnu` with
/// `|G_m|^2 = 4 sin^4(pi nu m) / (m^2 sin^2(pi nu))` and `M_ij` the larger `n_terms`. The
/// integral runs on a geometric grid; past `OSCILLATION_AVERAGED` (8) periods `sin^4` is
/// replaced by its mean.
pub fn avar_covariance(pts: &[AllanPoint], tau0: f64, theta: &[f64; 4]) -> DMatrix<f64> {
    use core::f64::consts::PI;
    let n = pts.len();
    let ms: Vec<f64> = pts
        .iter()
        .map(|p| (p.tau_s / tau0).round().max(1.0))
        .collect();
    let m_max = ms.iter().cloned().fold(1.0, f64::max);
    let mut acc = DMatrix::<f64>::zeros(n, n);
    let mut v = vec![0.0; n];
    // Geometric cells from 1e-4 / m_max (the integrand is flat or vanishing below) to 1/2.
    let mut lo = 1e-4 / m_max;
    while lo < 0.5 {
        let hi = (lo * (1.0 + GRID_RATIO)).min(0.5);
        let nu = 0.5 * (lo + hi);
        let dnu = hi - lo;
        let density: f64 = TERMS
            .iter()
            .zip(theta)
            .map(|(t, th)| th * t.density(nu, tau0))
            .sum();
        let s2 = (PI * nu).sin().powi(2);
        for (vi, &m) in v.iter_mut().zip(&ms) {
            let osc = if nu * m > OSCILLATION_AVERAGED {
                0.375
            } else {
                (PI * nu * m).sin().powi(4)
            };
            *vi = 4.0 * osc / (m * m * s2) * density;
        }
        for i in 0..n {
            for j in 0..=i {
                acc[(i, j)] += v[i] * v[j] * dnu;
            }
        }
        lo = hi;
    }
    for i in 0..n {
        for j in 0..=i {
            let m = pts[i].n_terms.max(pts[j].n_terms).max(1) as f64;
            let c = acc[(i, j)] / m;
            acc[(i, j)] = c;
            acc[(j, i)] = c;
        }
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(sigma2: impl Fn(f64) -> f64, n_terms: impl Fn(f64) -> usize) -> Vec<AllanPoint> {
        (0..30)
            .map(|k| {
                let tau = 0.1 * 10f64.powf(k as f64 / 8.0);
                AllanPoint {
                    tau_s: tau,
                    adev: sigma2(tau).sqrt(),
                    n_terms: n_terms(tau),
                }
            })
            .collect()
    }

    #[test]
    fn the_covariance_gives_the_textbook_degrees_of_freedom() {
        // Overlapping estimator, long records (M = n_terms >> m), edf = 2 sigma^4 / var:
        // 3 M / (2 m) for white rate noise (NIST SP 1065, exact in this limit), and for
        // flicker 1.17 M / m here against NIST's 5 M / (4 m), an empirical fit.
        let tau0 = 0.01;
        let total = 4_000_000usize;
        for (k, want, tol) in [(0usize, 1.5, 0.02), (1, 1.25, 0.1)] {
            let mut theta = [0.0; 4];
            theta[k] = 1.0;
            let pts = curve(|t| model_at(&theta, t), |_| total);
            let c = avar_covariance(&pts, tau0, &theta);
            for (i, p) in pts.iter().enumerate() {
                let m = (p.tau_s / tau0).round();
                let s2 = model_at(&theta, m * tau0);
                let edf = 2.0 * s2 * s2 / c[(i, i)];
                let ratio = edf / (total as f64 / m);
                assert!((ratio / want - 1.0).abs() < tol, "{k} m {m}: {ratio}");
            }
            // Neighbours an eighth of a decade apart share most of their data.
            let rho = c[(10, 11)] / (c[(10, 10)] * c[(11, 11)]).sqrt();
            assert!(rho > 0.8 && rho < 1.0, "{k}: {rho}");
        }
    }

    #[test]
    fn an_exact_curve_gives_back_its_coefficients() {
        // N = 0.03 deg/s*sqrt(s) (ARW 1.8), B = 0.02 deg/s (72 deg/h), K = 1e-3 deg/s/sqrt(s)
        // (216 deg/h/sqrt(h): the floor's value at tau = 530 s).
        let theta = [9e-4, 4e-4, 1e-6, 0.0];
        let pts = curve(|t| model_at(&theta, t), |t| (4e6 - 2.0 * t / 0.01) as usize);
        let f = fit_noise_model(&pts, 0.01, false);
        let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-9;
        assert!(close(f.arw_deg_per_rt_h, 1.8), "{f:?}");
        assert!(close(f.bias_instability_deg_per_h, 72.0), "{f:?}");
        assert!(close(f.rate_random_walk_deg_per_h_per_rt_h, 216.0), "{f:?}");
        assert!(f.quantisation_deg.is_nan() && f.quantisation_warning.is_some());
        assert!(close(f.adev_dps(3.0), model_at(&theta, 3.0).sqrt()));
        assert!(f.arw_deg_per_rt_h_ci95[0] < 1.8 && f.arw_deg_per_rt_h_ci95[1] > 1.8);
        assert_eq!((f.points, f.tau_min_s), (30, 0.1));
        // A quantisation term that is there is kept.
        let theta = [9e-4, 4e-4, 1e-6, 1e-3];
        let pts = curve(|t| model_at(&theta, t), |t| (4e6 - 2.0 * t / 0.01) as usize);
        let f = fit_noise_model(&pts, 0.01, false);
        assert!(close(f.quantisation_deg, 1e-3f64.sqrt()), "{f:?}");
        assert_eq!(f.quantisation_warning, None);
    }

    #[test]
    fn the_remnant_of_a_roll_off_is_fitted_as_a_negative_tau_minus_2_term() {
        // White noise through a first-order low-pass of time constant t beside a floor:
        // sigma^2 = N^2 / tau (1 - t / (2 tau) (3 - 4 e^(-tau/t) + e^(-2 tau/t))) + F^2, fitted
        // from ten time constants on. The white term alone reads N low.
        let (t, n2, b2) = (0.042, 9e-4, 4e-5);
        let exact = |tau: f64| {
            let x = tau / t;
            n2 / tau * (1.0 - (3.0 - 4.0 * (-x).exp() + (-2.0 * x).exp()) / (2.0 * x))
                + model_at(&[0.0, b2, 0.0, 0.0], tau)
        };
        let pts: Vec<AllanPoint> = curve(exact, |tau| (4e6 - 2.0 * tau / 0.01) as usize)
            .into_iter()
            .filter(|p| p.tau_s >= 10.0 * t)
            .collect();
        let f = fit_noise_model(&pts, 0.01, true);
        let n = 60.0 * n2.sqrt();
        assert!((f.arw_deg_per_rt_h / n - 1.0).abs() < 1e-3, "{f:?}");
        let c = f.tau_minus2_coefficient_dps2_s2;
        assert!((c / (-1.5 * t * n2) - 1.0).abs() < 0.02, "{f:?}");
        assert!(f.quantisation_deg.is_nan() && f.quantisation_warning.is_some());
        let three = fit_noise_model(&pts, 0.01, false);
        assert!(three.arw_deg_per_rt_h < 0.99 * n, "{three:?}");
        assert!(three.tau_minus2_coefficient_dps2_s2.is_nan());
    }
}
