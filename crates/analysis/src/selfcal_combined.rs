//! The two-mode self-calibration: the geometric mean of the two modes' scale factors, which
//! the drive-gain ratio and the Q mismatch leave alone.
//!
//! On a device whose only imperfections are F2/F1 = r and Q2 != Q1, the Coriolis phases are
//! exactly `tan theta1 = 2 lambda Omega r Q2 / w0` and `tan theta2 = 2 lambda Omega Q1 / (r w0)`,
//! and the rotating psi of each mode is `atan(2 Q_k Omega / w0)` to O((Omega/w0)^2). Each mode's
//! prediction is off by `Q_k / (r^{+-1} Q_other)`, equal and opposite; the products of the two
//! modes' slopes are `(2 lambda / w0)^2 Q1 Q2` on both sides, so the geometric means agree
//! whatever r and Q2/Q1 are. docs/selfcal.md gives what is left (mode split, phase-shifter
//! error, quadrature coupling, noise).

use crate::slope_fit::linearised_slope;
use gyroemu_config::Config;
use gyroemu_experiment::fit::{fit_line, t95};
use gyroemu_experiment::SweepResult;
use serde::Serialize;

/// The geometric mean of two modes' linearised slopes and its relative standard error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CombinedSlope {
    /// `sign * sqrt(s1 s2)`, deg per deg/s; NaN when the two slopes differ in sign (no
    /// common scale factor) or either is not finite.
    pub slope_deg_per_dps: f64,
    /// Standard error of that slope over the slope (first order, with the two modes'
    /// correlation through their common rate points).
    pub rel_std_err: f64,
    /// Degrees of freedom (points - 2).
    pub dof: usize,
}

/// The geometric mean of the linearised slopes of `phase_deg[0]` and `phase_deg[1]` against
/// `rates_dps`. Its relative error to first order is half the sum of the two relative slope
/// errors, which is the slope error of the line through `(tan p1 / s1 + tan p2 / s2) / 2`
/// (a line of slope 1, by linearity of least squares): read from its residuals, that counts
/// the two modes' correlated noise once.
pub fn combined_slope(rates_dps: &[f64], phase_deg: [&[f64]; 2]) -> CombinedSlope {
    let s = phase_deg.map(|p| linearised_slope(rates_dps, p));
    let [a, b] = s.map(|f| f.slope_deg_per_dps);
    let slope = if a * b > 0.0 && (a * b).is_finite() {
        a.signum() * (a * b).sqrt()
    } else {
        f64::NAN
    };
    let raw = s.map(|f| f.slope_deg_per_dps.to_radians());
    let y: Vec<f64> = (0..rates_dps.len())
        .map(|i| {
            0.5 * (phase_deg[0][i].to_radians().tan() / raw[0]
                + phase_deg[1][i].to_radians().tan() / raw[1])
        })
        .collect();
    CombinedSlope {
        slope_deg_per_dps: slope,
        rel_std_err: fit_line(rates_dps, &y).slope_std_err,
        dof: rates_dps.len().saturating_sub(2),
    }
}

/// Self-calibration of the two modes together.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CombinedSelfcal {
    /// Geometric mean of the two modes' rotating slopes.
    pub rotating: CombinedSlope,
    /// Geometric mean of the two modes' Coriolis slopes on the rate table.
    pub coriolis: CombinedSlope,
    /// Predicted combined Coriolis slope: lambda times the combined rotating slope.
    pub predicted_deg_per_dps: f64,
    /// Predicted over measured, minus one.
    pub relative_error: f64,
    /// Half-width of the 95 % confidence interval of `relative_error`.
    pub relative_error_ci95: f64,
    /// The same estimator applied to the exact continuous-time theory of both sweeps at the
    /// same rates (what the imperfections alone leave, without noise or board effects).
    pub relative_error_theory: f64,
    /// Small-angle theory of the combined Coriolis slope: 2 lambda sqrt(Q1 Q2) / w0 for any
    /// F2/F1.
    pub theory_coriolis_deg_per_dps: f64,
}

/// Both modes' rates and phases of a sweep: measured, or the exact theory beside them.
fn phases(r: &SweepResult, theory: bool) -> (Vec<f64>, [Vec<f64>; 2]) {
    let rates = r.points.iter().map(|p| p.rate_dps).collect();
    let ph = [0, 1].map(|k| {
        r.points
            .iter()
            .map(|p| {
                if theory {
                    p.theory_deg[k]
                } else {
                    p.phase_deg[k]
                }
            })
            .collect()
    });
    (rates, ph)
}

/// The combined self-calibration of `cfg`'s rotating and rate-table sweeps.
pub fn combined_selfcal(cfg: &Config, rot: &SweepResult, cor: &SweepResult) -> CombinedSelfcal {
    let lambda = cfg.device.angular_gain;
    let fit = |r: &SweepResult, theory: bool| {
        let (rates, [p1, p2]) = phases(r, theory);
        combined_slope(&rates, [&p1, &p2])
    };
    let (rotating, coriolis) = (fit(rot, false), fit(cor, false));
    let predicted = lambda * rotating.slope_deg_per_dps;
    let ratio = predicted / coriolis.slope_deg_per_dps;
    let ci = t95(rotating.dof.min(coriolis.dof))
        * ratio
        * rotating.rel_std_err.hypot(coriolis.rel_std_err);
    let theory = lambda * fit(rot, true).slope_deg_per_dps / fit(cor, true).slope_deg_per_dps - 1.0;
    let d = &cfg.device;
    let w0 = core::f64::consts::TAU * d.f0_hz;
    CombinedSelfcal {
        rotating,
        coriolis,
        predicted_deg_per_dps: predicted,
        relative_error: ratio - 1.0,
        relative_error_ci95: ci.abs(),
        relative_error_theory: theory,
        theory_coriolis_deg_per_dps: 2.0 * lambda * (d.q * d.q_mode2.unwrap_or(d.q)).sqrt() / w0,
    }
}
