//! Axis ranges and tick labels that survive degenerate data and SI magnitudes.
//!
//! Data in SI units spans 1e-18 (F) to 1e6 (Hz). plotters' tick generator compares spans with
//! `f64::EPSILON` in absolute terms, so such data is first scaled by a power of 1000 (shown as
//! "×10⁻⁹" next to the axis, like matplotlib's offset text), then padded by 5 %.

use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;

/// Fraction of the data span added on each side of the axis.
pub const MARGIN_FRACTION: f64 = 0.05;

/// One axis: plotted range in scaled units, the scale exponent and the tick label format.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisScale {
    /// Lower end of the plotted range, in units of 10^`exp10`.
    pub lo: f64,
    /// Upper end, in units of 10^`exp10`.
    pub hi: f64,
    /// Data are divided by 10^`exp10` before plotting (a multiple of 3, 0 for ordinary magnitudes).
    pub exp10: i32,
    /// Decimals of every tick label (same for all ticks, as in printed figures).
    pub decimals: usize,
    /// Logarithmic: `lo`/`hi` are decades (log10 of the data) and ticks read 10^n.
    pub log: bool,
    factor: f64,
}

/// Smallest and largest finite value, or `None` if there is none.
pub fn finite_bounds(vals: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    vals.into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// Engineering exponent (multiple of 3) for the largest magnitude `m`; 0 when plain numbers read well.
fn engineering_exponent(m: f64) -> i32 {
    if m == 0.0 || (1e-2..1e6).contains(&m) {
        0
    } else {
        (3.0 * (m.log10() / 3.0).floor()).clamp(-306.0, 306.0) as i32
    }
}

impl AxisScale {
    /// Axis for the finite values of `vals` with about `n_ticks` ticks: empty input gives
    /// [0, 1]; a constant `v` gives `v ± 10 %` (± 1 for 0); spans too small for f64 ticks are widened.
    pub fn from_values(vals: impl IntoIterator<Item = f64>, n_ticks: usize) -> Self {
        let (lo, hi, exp10) = match finite_bounds(vals) {
            None => (0.0, 1.0, 0),
            Some((lo, hi)) => {
                let e = engineering_exponent(lo.abs().max(hi.abs()));
                let f = 10f64.powi(e);
                let (mut lo, mut hi) = (lo / f, hi / f);
                let mid = 0.5 * (lo + hi);
                // Below ~1e-12 relative span the tick positions cannot be resolved in f64.
                let min_span = mid.abs() * 1e-12;
                if hi - lo <= min_span {
                    let mut half = if mid != 0.0 { mid.abs() * 0.1 } else { 1.0 };
                    if half < 1e-300 {
                        half = 1.0;
                    }
                    lo = mid - half;
                    hi = mid + half;
                }
                let pad = MARGIN_FRACTION * (hi - lo);
                (lo - pad, hi + pad, e)
            }
        };
        AxisScale {
            lo,
            hi,
            exp10,
            decimals: 0,
            log: false,
            factor: 10f64.powi(exp10),
        }
        .with_range(lo, hi, n_ticks)
    }

    /// Logarithmic axis over the positive finite values of `vals`: their span in decades with
    /// 5 % margins when that holds two whole decades or more (each gets a tick), else the
    /// whole decades around them (at least one) with 2 % margins; `[1, 10]` when there is no
    /// positive value.
    pub fn log_from_values(vals: impl IntoIterator<Item = f64>) -> Self {
        let logs = vals.into_iter().filter(|v| *v > 0.0).map(f64::log10);
        let (lo, hi) = match finite_bounds(logs) {
            None => (-0.02, 1.02),
            Some((lo, hi)) => {
                let pad = MARGIN_FRACTION * (hi - lo);
                let (tlo, thi) = (lo - pad, hi + pad);
                if thi.floor() - tlo.ceil() >= 1.0 {
                    (tlo, thi)
                } else {
                    let (lo, mut hi) = (lo.floor(), hi.ceil());
                    if hi <= lo {
                        hi = lo + 1.0;
                    }
                    let pad = 0.02 * (hi - lo);
                    (lo - pad, hi + pad)
                }
            }
        };
        AxisScale {
            lo,
            hi,
            exp10: 0,
            decimals: 0,
            log: true,
            factor: 1.0,
        }
    }

    /// The same axis (scale, log or linear) over the plotted range `lo..hi` instead, with its
    /// tick labels' decimals for about `n_ticks` ticks there.
    pub fn with_range(&self, lo: f64, hi: f64, n_ticks: usize) -> Self {
        let decimals = if self.log {
            0
        } else {
            let ticks = RangedCoordf64::from(lo..hi).key_points(n_ticks.max(2));
            common_decimals(&ticks, hi - lo)
        };
        AxisScale {
            lo,
            hi,
            decimals,
            ..self.clone()
        }
    }

    /// Tick positions, in plotted units, about `n` of them: plotters' round steps on a linear
    /// axis; on a log axis whole decades every `ceil(decades / (n - 1))`, at least two.
    pub fn ticks(&self, n: usize) -> Vec<f64> {
        if !self.log {
            return RangedCoordf64::from(self.lo..self.hi).key_points(n.max(2));
        }
        let span = (self.hi.floor() - self.lo.ceil()).max(1.0);
        let step = (span / (n.max(2) - 1) as f64).ceil().max(1.0);
        let first = (self.lo / step).ceil() * step;
        let mut t: Vec<f64> = (0..)
            .map(|i| first + i as f64 * step)
            .take_while(|&v| v <= self.hi)
            .collect();
        if t.len() < 2 {
            // A step wider than the axis: its first and last whole decades instead.
            t = vec![self.lo.ceil(), self.hi.floor()];
            t.dedup();
        }
        t
    }

    /// Maps a data value to plotted (scaled) units: log10 on a log axis (NaN for v <= 0, so
    /// the point is skipped).
    #[inline]
    pub fn map(&self, v: f64) -> f64 {
        if self.log {
            if v > 0.0 {
                v.log10()
            } else {
                f64::NAN
            }
        } else {
            v / self.factor
        }
    }

    /// Tick label for the scaled value `v`, never "-0"; `10ⁿ` on a log axis.
    pub fn label(&self, v: f64) -> String {
        if self.log {
            let n = v.round();
            return if (v - n).abs() < 1e-9 {
                power_of_ten(n as i32)
            } else {
                format!("{:.3}", 10f64.powf(v))
            };
        }
        let s = format!("{:.*}", self.decimals, v);
        match s.strip_prefix('-') {
            Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
            _ => s,
        }
    }

    /// "×10ⁿ" to print beside the axis when the data were scaled, else `None`.
    pub fn exponent_text(&self) -> Option<String> {
        if self.exp10 == 0 {
            return None;
        }
        Some(format!("×{}", power_of_ten(self.exp10)))
    }
}

/// "10ⁿ" with a superscript exponent.
fn power_of_ten(n: i32) -> String {
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if n < 0 {
        s.push('⁻');
    }
    for d in n.unsigned_abs().to_string().bytes() {
        s.push(SUP[(d - b'0') as usize]);
    }
    s
}

/// Fewest decimals (0..=12) that print every tick exactly to within 1e-6 of the tick spacing.
fn common_decimals(ticks: &[f64], span: f64) -> usize {
    let step = ticks
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(f64::INFINITY, f64::min);
    let tol = if step.is_finite() && step > 0.0 {
        step * 1e-6
    } else {
        span.abs() * 1e-6
    };
    (0..=12)
        .find(|&d| {
            ticks.iter().all(|&t| {
                let r: f64 = format!("{t:.d$}").parse().unwrap_or(f64::NAN);
                (r - t).abs() <= tol
            })
        })
        .unwrap_or(12)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_skip_non_finite() {
        assert_eq!(
            finite_bounds([f64::NAN, 2.0, f64::INFINITY, -1.0]),
            Some((-1.0, 2.0))
        );
        assert_eq!(finite_bounds([f64::NAN]), None);
        assert_eq!(finite_bounds(Vec::<f64>::new()), None);
    }

    #[test]
    fn margins_are_five_percent() {
        let a = AxisScale::from_values([0.0, 10.0], 8);
        assert_eq!((a.lo, a.hi, a.exp10), (-0.5, 10.5, 0));
    }

    #[test]
    fn degenerate_ranges_have_a_span() {
        for v in [
            vec![],
            vec![f64::NAN],
            vec![0.0],
            vec![3.0, 3.0],
            vec![-2e-12],
            vec![f64::MAX],
            vec![5e-324],
        ] {
            let a = AxisScale::from_values(v.clone(), 8);
            assert!(
                a.lo.is_finite() && a.hi.is_finite() && a.hi > a.lo,
                "{v:?} -> {a:?}"
            );
            for x in v.iter().filter(|x| x.is_finite()) {
                let m = a.map(*x);
                assert!(a.lo <= m && m <= a.hi, "{x} -> {m} outside {a:?}");
            }
        }
        let c = AxisScale::from_values([3.0], 8);
        assert!(
            (c.lo - 2.67).abs() < 1e-12 && (c.hi - 3.33).abs() < 1e-12,
            "{c:?}"
        );
    }

    #[test]
    fn si_magnitudes_are_scaled_by_powers_of_1000() {
        let a = AxisScale::from_values([1.2e-9, 4.5e-9], 8);
        assert_eq!(a.exp10, -9);
        assert_eq!(a.exponent_text().as_deref(), Some("×10⁻⁹"));
        assert!((a.map(4.5e-9) - 4.5).abs() < 1e-12);
        let b = AxisScale::from_values([0.0, 2.5e7], 8);
        assert_eq!(b.exponent_text().as_deref(), Some("×10⁶"));
        assert_eq!(
            AxisScale::from_values([19_990.0, 20_010.0], 8).exponent_text(),
            None
        );
    }

    #[test]
    fn log_axes_span_whole_decades_and_tick_on_them() {
        let a = AxisScale::log_from_values([3e-9, 0.0, -1.0, f64::NAN, 2e-2]);
        assert!(a.log && a.exp10 == 0);
        // The data's decades with 5 % margins: they hold the ticks -8 .. -2.
        let (l, h) = (3e-9f64.log10(), 2e-2f64.log10());
        let pad = 0.05 * (h - l);
        assert!((a.lo - (l - pad)).abs() < 1e-12 && (a.hi - (h + pad)).abs() < 1e-12);
        assert!((a.map(1e-5) + 5.0).abs() < 1e-12);
        assert!(a.map(0.0).is_nan() && a.map(-3.0).is_nan());
        assert_eq!(a.label(-5.0), "10⁻⁵");
        assert_eq!(a.label(0.0), "10⁰");
        assert_eq!(a.label(12.0), "10¹²");
        for n in [2usize, 3, 6, 10] {
            let ticks = a.ticks(n);
            assert!(
                ticks.len() >= 2 && ticks.len() <= n.max(2),
                "{n}: {ticks:?}"
            );
            for t in &ticks {
                assert!((t - t.round()).abs() < 1e-12, "tick {t} is not a decade");
                assert!(a.lo <= *t && *t <= a.hi);
            }
        }
        assert_eq!(a.ticks(10), [-8.0, -7.0, -6.0, -5.0, -4.0, -3.0, -2.0]);
        // Less than two decades of data: whole decades around them.
        let c = AxisScale::log_from_values([0.08, 0.7]);
        assert!(
            (c.lo + 2.04).abs() < 1e-12 && (c.hi - 0.04).abs() < 1e-12,
            "{c:?}"
        );
        // One value: one whole decade around it; nothing positive: 10^0 .. 10^1.
        let b = AxisScale::log_from_values([5.0]);
        assert!(b.lo < 0.0 && b.hi > 1.0 && b.hi < 1.1);
        assert!(AxisScale::log_from_values([0.0, -1.0]).lo < 0.0);
    }

    #[test]
    fn tick_labels_share_decimals_and_never_show_minus_zero() {
        let a = AxisScale::from_values([0.0, 1.0], 8);
        let ticks = RangedCoordf64::from(a.lo..a.hi).key_points(8);
        let labels: Vec<String> = ticks.iter().map(|&t| a.label(t)).collect();
        let decs: Vec<usize> = labels
            .iter()
            .map(|l| l.split('.').nth(1).map_or(0, str::len))
            .collect();
        assert!(decs.windows(2).all(|w| w[0] == w[1]), "{labels:?}");
        for (l, t) in labels.iter().zip(&ticks) {
            assert!((l.parse::<f64>().unwrap() - t).abs() < 1e-9, "{l} vs {t}");
        }
        assert_eq!(
            a.label(-1e-17),
            if a.decimals == 0 {
                "0".to_string()
            } else {
                format!("0.{}", "0".repeat(a.decimals))
            }
        );
    }
}
