//! What a lot amounts to: the spread of each error over the devices whose numbers can be
//! trusted, and the yield within the spec with its confidence interval.

use super::device::{ColumnKind, DeviceResult, COLUMNS, HEADLINE};
use super::stats::{wilson_interval, Spread};
use serde::Serialize;

/// The fraction of a lot within the spec.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct YieldEstimate {
    /// Devices whose |headline error| is at most the spec.
    pub passed: usize,
    /// Devices in the lot (the unreliable ones count as failing).
    pub devices: usize,
    /// `passed / devices`.
    pub fraction: f64,
    /// The Wilson score 95 % interval of the fraction ([`wilson_interval`]).
    pub ci95_low: f64,
    pub ci95_high: f64,
}

/// The lot's figures.
#[derive(Clone, Debug, PartialEq)]
pub struct LotSummary {
    /// Devices in the lot.
    pub devices: usize,
    pub spec_abs_relative_error: f64,
    /// The error the spec applies to ([`HEADLINE`]).
    pub headline: &'static str,
    pub yield_within_spec: YieldEstimate,
    /// Devices whose numbers cannot be trusted (a refused phase, a non-finite headline error):
    /// left out of the spreads, counted as failing the spec.
    pub unreliable: Vec<u64>,
    /// The spread of every error column ([`ColumnKind::Error`]) over the other devices.
    pub errors: Vec<(&'static str, Spread)>,
}

impl LotSummary {
    /// Whether `d` is within `spec` (a reliable device with |headline error| <= spec).
    pub fn passes(d: &DeviceResult, spec: f64) -> bool {
        d.headline().is_some_and(|e| e.abs() <= spec)
    }

    /// The figures of the lot `devices` (in any order) against `spec`.
    pub fn of(devices: &[DeviceResult], spec: f64) -> Self {
        let reliable: Vec<&DeviceResult> =
            devices.iter().filter(|d| d.headline().is_some()).collect();
        let mut unreliable: Vec<u64> = devices
            .iter()
            .filter(|d| d.headline().is_none())
            .map(|d| d.index)
            .collect();
        unreliable.sort_unstable();
        let passed = devices.iter().filter(|d| Self::passes(d, spec)).count();
        let n = devices.len();
        let (lo, hi) = wilson_interval(passed, n);
        let errors = COLUMNS
            .iter()
            .enumerate()
            .filter(|(_, c)| c.kind == ColumnKind::Error)
            .map(|(i, c)| (c.name, Spread::of(reliable.iter().map(|d| d.values[i]))))
            .collect();
        Self {
            devices: n,
            spec_abs_relative_error: spec,
            headline: HEADLINE,
            yield_within_spec: YieldEstimate {
                passed,
                devices: n,
                fraction: if n == 0 {
                    f64::NAN
                } else {
                    passed as f64 / n as f64
                },
                ci95_low: lo,
                ci95_high: hi,
            },
            unreliable,
            errors,
        }
    }

    /// The spread of the headline error.
    pub fn headline_spread(&self) -> Option<&Spread> {
        self.errors
            .iter()
            .find(|(n, _)| *n == self.headline)
            .map(|(_, s)| s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device whose every column holds `e` (the headline among them).
    fn device(index: u64, e: f64, problem: bool) -> DeviceResult {
        DeviceResult {
            index,
            values: vec![e; COLUMNS.len()],
            problems: if problem {
                vec!["a phase refused".into()]
            } else {
                vec![]
            },
            warnings: vec![],
            point_samples: 0,
        }
    }

    #[test]
    fn yield_and_spreads_of_a_hand_computed_lot() {
        let lot = [
            device(0, 0.01, false),
            device(1, -0.03, false),
            device(2, 0.02, false),
            device(3, 0.001, true),
            device(4, f64::NAN, false),
            device(5, -0.005, false),
        ];
        let s = LotSummary::of(&lot, 0.02);
        // Within |e| <= 0.02: devices 0, 2 (on the limit) and 5; 3 and 4 cannot be trusted.
        assert_eq!(s.unreliable, vec![3, 4]);
        let y = &s.yield_within_spec;
        assert_eq!((y.passed, y.devices), (3, 6));
        assert_eq!(y.fraction, 0.5);
        assert_eq!((y.ci95_low, y.ci95_high), wilson_interval(3, 6));
        // The headline's spread over 0.01, -0.03, 0.02, -0.005: mean -0.00125; sorted
        // -0.03 -0.005 0.01 0.02, median (-0.005 + 0.01) / 2; |e| sorted 0.005 0.01 0.02
        // 0.03, P95 at rank 2.85: 0.02 + 0.85 * 0.01.
        let h = s.headline_spread().unwrap();
        assert_eq!(h.n, 4);
        assert!((h.mean + 0.00125).abs() < 1e-17);
        assert!((h.percentiles[2].1 - 0.0025).abs() < 1e-17);
        assert!((h.abs_percentiles[3].1 - 0.0285).abs() < 1e-16);
        assert_eq!((h.min, h.max), (-0.03, 0.02));
        // Every error column is reported, the headline first among them.
        assert_eq!(s.errors[0].0, HEADLINE);
        assert!(s.errors.iter().all(|(n, _)| COLUMNS
            .iter()
            .any(|c| c.name == *n && c.kind == ColumnKind::Error)));
    }
}
