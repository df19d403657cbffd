//! Validation of the `[montecarlo]` section: each spread a standard deviation, the spec
//! positive, and no draw able to make a device impossible. A draw is bounded (a normal one is
//! truncated, a uniform one is flat over +-sqrt(3) sigma), so the bound is checked here once:
//! a spread that could reach Q <= 0, F2 <= 0, lambda <= 0 or a mode-2 resonance <= 0 is
//! refused, never clamped. Every other rule is checked on each drawn device before the lot runs.

use crate::config::{Config, Distribution, MonteCarloConfig};
use crate::rules::Rules;

/// The widest `truncate_sigma` accepted: a normal exceeds 8 standard deviations with
/// probability 1.2e-15, so 8 is all but untruncated.
pub const MAX_TRUNCATE_SIGMA: f64 = 8.0;

impl MonteCarloConfig {
    /// The largest |draw| in standard deviations: `truncate_sigma` (normal) or sqrt(3)
    /// (uniform).
    pub fn z_limit(&self) -> f64 {
        match self.distribution {
            Distribution::Normal => self.truncate_sigma,
            Distribution::Uniform => 3f64.sqrt(),
        }
    }

    /// The relative spreads, each with its key and what it scales.
    pub fn relative_spreads(&self) -> [(&'static str, f64, &'static str); 4] {
        [
            ("montecarlo.q_sigma_rel", self.q_sigma_rel, "Q"),
            (
                "montecarlo.q_mismatch_sigma_rel",
                self.q_mismatch_sigma_rel,
                "Q of mode 2",
            ),
            (
                "montecarlo.drive_gain_sigma_rel",
                self.drive_gain_sigma_rel,
                "F2",
            ),
            (
                "montecarlo.lambda_sigma_rel",
                self.lambda_sigma_rel,
                "lambda",
            ),
        ]
    }
}

impl Config {
    /// The rules of the `[montecarlo]` section.
    pub(crate) fn validate_montecarlo(&self, p: &mut Rules) {
        let Some(m) = &self.montecarlo else {
            return;
        };
        p.check(
            m.truncate_sigma.is_finite() && (1.0..=MAX_TRUNCATE_SIGMA).contains(&m.truncate_sigma),
            "montecarlo.truncate_sigma",
            m.truncate_sigma,
            format!("must be a finite number from 1 to {MAX_TRUNCATE_SIGMA} (standard deviations)"),
        );
        let sd = "must be a finite number >= 0 (a standard deviation)";
        for (key, v, _) in m.relative_spreads() {
            p.check(v.is_finite() && v >= 0.0, key, v, sd);
        }
        for (key, v) in [
            ("montecarlo.mode_split_sigma_hz", m.mode_split_sigma_hz),
            (
                "montecarlo.phase_shifter_sigma_deg",
                m.phase_shifter_sigma_deg,
            ),
        ] {
            p.check(v.is_finite() && v >= 0.0, key, v, sd);
        }
        p.check(
            m.spec_abs_relative_error.is_finite() && m.spec_abs_relative_error > 0.0,
            "montecarlo.spec_abs_relative_error",
            m.spec_abs_relative_error,
            "must be a finite number > 0 (a bound on |predicted / measured - 1|)",
        );
        if !p.clean(&["montecarlo.truncate_sigma"]) {
            return;
        }
        let k = m.z_limit();
        let (at, k_text) = match m.distribution {
            Distribution::Normal => (
                format!("{k} standard deviations (truncate_sigma)"),
                format!("{k}"),
            ),
            Distribution::Uniform => (
                "sqrt(3) standard deviations (uniform)".to_string(),
                "sqrt(3)".to_string(),
            ),
        };
        // The bound rounded down (a spread at it would be refused).
        let below = (1e6 / k).floor() / 1e6;
        for (key, v, what) in m.relative_spreads() {
            p.check(
                v * k < 1.0,
                key,
                v,
                format!(
                    "must be below {below} so that no device has {what} <= 0: the draws reach {at}"
                ),
            );
        }
        let split_ok = p.clean(&[
            "device.f0_hz",
            "device.mode2_f0_offset_hz",
            "montecarlo.mode_split_sigma_hz",
        ]);
        if split_ok {
            let lowest = self.f0_mode2_hz() - k * m.mode_split_sigma_hz;
            p.check(
                lowest > 0.0,
                "montecarlo.mode_split_sigma_hz",
                m.mode_split_sigma_hz,
                format!(
                    "must keep the mode-2 resonance > 0 where the draws reach {at}: f0_hz + mode2_f0_offset_hz - {k_text} x this = {lowest} Hz"
                ),
            );
        }
    }
}
