//! What `montecarlo` and `merge` print of a lot on stdout: its percentiles and yield.

use gyroemu_analysis::montecarlo::LotSummary;

/// The lot's figures for the terminal.
pub fn summary_text(s: &LotSummary) -> String {
    // Three decimals of a percent, or four significant digits below 0.1 % (a 1 ppm spec
    // printed as 0.000 %).
    let pct = |x: f64| {
        let v = 100.0 * x;
        if v != 0.0 && v.abs() < 0.1 {
            format!("{v:.3e} %")
        } else {
            format!("{v:.3} %")
        }
    };
    let y = &s.yield_within_spec;
    let mut t = format!(
        "lot of {} devices, self-calibration error `{}`:\n",
        s.devices, s.headline
    );
    if let Some(sp) = s.headline_spread() {
        let list = |v: &[(f64, f64)]| {
            v.iter()
                .map(|&(p, x)| format!("P{p} {}", pct(x)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        t += &format!("  |error|: {}\n", list(&sp.abs_percentiles));
        // One device has no spread (montecarlo.json holds null).
        let std = if sp.std.is_finite() {
            pct(sp.std)
        } else {
            "n/a".to_string()
        };
        t += &format!(
            "  signed:  {}; mean {}, std {std} ({} devices)\n",
            list(&sp.percentiles),
            pct(sp.mean),
            sp.n
        );
    }
    t += &format!(
        "  yield within |error| <= {}: {} of {} = {} (95 % interval {} .. {}, Wilson)\n",
        pct(s.spec_abs_relative_error),
        y.passed,
        y.devices,
        pct(y.fraction),
        pct(y.ci95_low),
        pct(y.ci95_high)
    );
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_spec_keeps_its_digits() {
        // 1 ppm is 1e-4 %: it printed as 0.000 %.
        let text = summary_text(&LotSummary::of(&[], 1e-6));
        assert!(text.contains("|error| <= 1.000e-4 %"), "{text}");
        let text = summary_text(&LotSummary::of(&[], 0.02));
        assert!(text.contains("|error| <= 2.000 %"), "{text}");
    }
}
