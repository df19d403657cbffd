//! Phases too small for the chain to resolve: a Coriolis or rate-table run whose every
//! non-zero rate gives a phase within about a hundred times the chain's own rounding reads that
//! rounding, and a slope and fit from it, with nothing else amiss (rates of 1e-12 deg/s read
//! -4.3e-12 deg against a theory of +4.2e-14, a slope 44 times the theory's; a gain of 1e-30
//! read every phase exactly 0 and a "perfect" fit of r2 = 1). Stated before any sample.

use crate::config::Config;
use crate::plan::DEG;
use gyroemu_board::Shape;

/// Below this largest theory phase (mdeg) a run's phases are stated as unresolved: about a
/// hundred times the floor of the chain's rounding. On the m2tfg Coriolis preset (0.05 s
/// windows) tiny rates read within 1e-8 mdeg of the theory whatever the rate (2 % off at
/// 1e-8 deg/s, a phase of 4e-7 mdeg; 40 % at 1e-10), and 1e-5 deg/s to 1e-5 relative.
pub const MIN_RESOLVED_PHASE_MDEG: f64 = 1e-6;

/// The floor itself, as measured above (mdeg).
const ROUNDING_FLOOR_MDEG: f64 = 1e-8;

impl Config {
    /// Warns when the largest |theory phase| over the non-zero rates and both modes is below
    /// [`MIN_RESOLVED_PHASE_MDEG`]. Rotating runs are not judged: their rates turn the drive,
    /// and psi grows with them far beyond it before a window can hold a modulation period.
    pub(crate) fn warn_unresolved_phases(&self, warnings: &mut Vec<String>) {
        let dev = self.driven_device();
        let mdeg = |t: f64| (t / DEG * 1e3).abs();
        let phase = |r: f64| match self.shape() {
            Shape::Coriolis => Some(dev.coriolis_phase_rad(r * DEG)),
            Shape::RateTable { freq_hz } => Some(dev.rate_table_response(r.abs() * DEG, freq_hz).0),
            Shape::Rotating => None,
        };
        // The phase grows with |rate| wherever the rule can fire: the largest rate alone
        // clears it, and only a run it does not clear (rare) is weighed at every rate (a
        // sweep may list 1e5 rates, each a solve on a rate table).
        let top = self
            .experiment
            .rates_dps
            .iter()
            .copied()
            .max_by(|a, b| a.abs().total_cmp(&b.abs()));
        let clears = |r: f64| {
            phase(r).is_none_or(|th| {
                th.iter()
                    .any(|&t| mdeg(t) >= MIN_RESOLVED_PHASE_MDEG || t.is_nan())
            })
        };
        if top.is_none_or(|r| r == 0.0 || clears(r)) {
            return;
        }
        let mut largest: Option<(f64, f64)> = None;
        for &r in self.experiment.rates_dps.iter().filter(|&&r| r != 0.0) {
            let Some(th) = phase(r) else { return };
            for m in th.map(mdeg) {
                // A NaN (an unbuildable plant) is reported by the other rules.
                if !m.is_nan() && largest.is_none_or(|(l, _)| m > l) {
                    largest = Some((m, r));
                }
            }
        }
        if let Some((mdeg, r)) = largest.filter(|&(m, _)| m < MIN_RESOLVED_PHASE_MDEG) {
            warnings.push(format!(
                "experiment.rates_dps: the largest phase the rates give is {mdeg:.3e} mdeg (at {r:e} deg/s), below {MIN_RESOLVED_PHASE_MDEG:e} mdeg, about a hundred times the floor of the chain's own rounding ({ROUNDING_FLOOR_MDEG:e} mdeg): the phases carry that rounding ({}), and so does any slope or fit read from them; raise the rates or device.angular_gain",
                if mdeg > 0.0 {
                    format!("{:.1e} times the largest of them here", ROUNDING_FLOOR_MDEG / mdeg)
                } else {
                    "every phase is 0 in the theory".to_string()
                }
            ));
        }
    }
}
