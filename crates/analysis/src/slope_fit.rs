//! The scale factor read from one mode's sweep: the slope of the phase against the rate,
//! linearised (the self-calibration, one mode or both together, and its analyses all read
//! their slopes so).

use gyroemu_experiment::fit::{fit_line, unwrapped_along, LineFit};
use serde::Serialize;

/// A scale factor read from a sweep: the small-angle slope of the phase against the rate,
/// from a line fit of tan(phase) (which undoes the atan of THEORY.md eqs. 2-3 exactly for
/// the Coriolis phase and to O((Omega/w0)^2) for the rotating one), with its standard error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SlopeFit {
    /// Degrees of phase per deg/s (the same number as rad per rad/s, i.e. seconds).
    pub slope_deg_per_dps: f64,
    /// Standard error of that slope (fit residuals).
    pub std_err_deg_per_dps: f64,
    /// Degrees of freedom of the fit (points - 2).
    pub dof: usize,
    /// The paper's plain best linear fit of the phase itself (degrees against deg/s).
    pub plain_fit: LineFit,
}

impl SlopeFit {
    /// The slope's standard error over the slope (signed as the slope).
    pub fn rel_std_err(&self) -> f64 {
        self.std_err_deg_per_dps / self.slope_deg_per_dps
    }
}

/// The linearised slope of `phase_deg` against `rates_dps`.
pub fn linearised_slope(rates_dps: &[f64], phase_deg: &[f64]) -> SlopeFit {
    let t: Vec<f64> = phase_deg.iter().map(|p| p.to_radians().tan()).collect();
    let f = fit_line(rates_dps, &t);
    SlopeFit {
        slope_deg_per_dps: f.slope.to_degrees(),
        std_err_deg_per_dps: f.slope_std_err.to_degrees(),
        dof: rates_dps.len().saturating_sub(2),
        // Across a branch wrap as the linearised slope is (tan's period is a half turn).
        plain_fit: fit_line(rates_dps, &unwrapped_along(rates_dps, phase_deg, 180.0)),
    }
}
