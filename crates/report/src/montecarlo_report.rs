//! What a production lot writes: `devices.csv` (one row per device), `montecarlo.json` (the
//! spread of each error, the yield within the spec), `histogram.png` (the headline error with
//! the spec limits) and `percentiles.png` (the fraction of devices above each |error|, with the
//! percentiles). Everything is computed from the device records and the config alone, so a
//! lot merged from shards writes the same bytes as one machine.

use crate::error::{create_dir, ReportError};
use gyroemu_analysis::montecarlo::{
    validate_lot, DeviceResult, LotSummary, Spread, YieldEstimate, COLUMNS, PERCENTILES,
};
use gyroemu_config::{Config, Distribution};
use gyroemu_io::{write_csv, write_json, CsvCell, CsvTable};
use gyroemu_plot::{render_png, Figure, Series, SeriesStyle};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// The files [`write_lot`] writes into its folder.
pub const LOT_FILES: [&str; 4] = [
    "devices.csv",
    "montecarlo.json",
    "histogram.png",
    "percentiles.png",
];

/// The rows of `devices.csv`: `index`, every column of [`COLUMNS`], `pass` (`true` when the
/// device is within the spec) and `problems` (why its numbers cannot be trusted, `; `-joined).
pub fn devices_table(devices: &[DeviceResult], spec: f64) -> CsvTable {
    let mut headers = vec!["index".to_string()];
    headers.extend(COLUMNS.iter().map(|c| c.name.to_string()));
    headers.extend(["pass".to_string(), "problems".to_string()]);
    let rows = devices
        .iter()
        .map(|d| {
            let mut row = vec![CsvCell::Int(d.index as i64)];
            row.extend(d.values.iter().map(|&v| CsvCell::F64(v)));
            row.push(CsvCell::Text(LotSummary::passes(d, spec).to_string()));
            row.push(CsvCell::Text(d.problems.join("; ")));
            row
        })
        .collect();
    CsvTable { headers, rows }
}

fn percent_key(p: f64) -> String {
    format!("p{p}")
}

fn spread_json(s: &Spread) -> Value {
    let table = |t: &[(f64, f64)]| -> Map<String, Value> {
        t.iter().map(|&(p, v)| (percent_key(p), json!(v))).collect()
    };
    json!({
        "n": s.n,
        "mean": s.mean,
        "std": s.std,
        "min": s.min,
        "max": s.max,
        "percentiles": table(&s.percentiles),
        "abs_percentiles": table(&s.abs_percentiles),
    })
}

fn yield_json(y: &YieldEstimate) -> Value {
    json!({
        "passed": y.passed,
        "devices": y.devices,
        "fraction": y.fraction,
        "ci95_low": y.ci95_low,
        "ci95_high": y.ci95_high,
        "interval": "Wilson score, 95 %",
    })
}

/// The content of `montecarlo.json` (no timings: deterministic).
pub fn lot_json(cfg: &Config, devices: &[DeviceResult], s: &LotSummary) -> Value {
    let mc = cfg.montecarlo.as_ref();
    let errors: Map<String, Value> = s
        .errors
        .iter()
        .map(|(name, sp)| (name.to_string(), spread_json(sp)))
        .collect();
    // The validation's warnings first, as the run printed them (the config's, then the drawn
    // devices' grouped by text): a device an ADC leaves only as dither was warned on stderr
    // alone, beside a slope of 1e-14 in devices.csv. Recomputed from the config, so a merged
    // lot states those of every shard's devices.
    let indices: Vec<u64> = devices.iter().map(|d| d.index).collect();
    let mut warnings: Vec<String> = validate_lot(cfg, &indices).unwrap_or_default();
    for d in devices {
        for w in &d.warnings {
            let w = format!("device {}: {w}", d.index);
            warnings.push(w);
        }
    }
    warnings.extend(spread_gaps(s));
    json!({
        "gyroemu_version": env!("CARGO_PKG_VERSION"),
        "devices": s.devices,
        "seed": mc.map(|m| m.seed),
        "distribution": mc.map(|m| match m.distribution {
            Distribution::Normal => "normal",
            Distribution::Uniform => "uniform",
        }),
        "spec_abs_relative_error": s.spec_abs_relative_error,
        "headline": s.headline,
        "yield": yield_json(&s.yield_within_spec),
        "devices_unreliable": s.unreliable,
        "errors": errors,
        "point_samples_emulated": devices.iter().map(|d| d.point_samples).sum::<u64>(),
        "warnings": warnings,
        "config": cfg,
    })
}

/// One line per error column whose spread leaves out reliable devices (their value there is
/// not finite): its `n` alone would not tell a reader why it is short of the lot.
fn spread_gaps(s: &LotSummary) -> Vec<String> {
    let reliable = s.devices - s.unreliable.len();
    s.errors
        .iter()
        .filter(|(_, sp)| sp.n < reliable)
        .map(|(name, sp)| {
            format!(
                "{name}: {} of the {reliable} reliable devices have no finite value and are left \
                 out of its spread (n = {})",
                reliable - sp.n,
                sp.n
            )
        })
        .collect()
}

/// The finite headline errors of the reliable devices, in %.
fn headline_percent(devices: &[DeviceResult]) -> Vec<f64> {
    devices
        .iter()
        .filter_map(DeviceResult::headline)
        .map(|e| 100.0 * e)
        .collect()
}

fn yield_text(s: &LotSummary) -> String {
    let y = &s.yield_within_spec;
    format!(
        "yield {:.1} % within |error| <= {} % (95 % CI {:.1} to {:.1} %)",
        100.0 * y.fraction,
        100.0 * s.spec_abs_relative_error,
        100.0 * y.ci95_low,
        100.0 * y.ci95_high
    )
}

/// The headline error's histogram as a staircase, the normal density of the same mean and
/// standard deviation, and the spec limits as markers.
pub fn histogram_figure(devices: &[DeviceResult], s: &LotSummary) -> Figure {
    let e = headline_percent(devices);
    let spec = 100.0 * s.spec_abs_relative_error;
    let title = format!("Lot of {} devices: {}", s.devices, yield_text(s));
    let mut fig = Figure::new(
        title,
        format!("self-calibration error, {} (%)", s.headline),
        "devices per bin",
    )
    .with_marker(-spec, "-spec")
    .with_marker(spec, "+spec");
    let (Some(lo), Some(hi)) = (
        e.iter().copied().reduce(f64::min),
        e.iter().copied().reduce(f64::max),
    ) else {
        return fig;
    };
    let (lo, hi) = (lo.min(-spec), hi.max(spec));
    let bins = ((e.len() as f64).sqrt().ceil() as usize).clamp(8, 60);
    let width = (hi - lo) / bins as f64;
    let mut counts = vec![0usize; bins];
    for &x in &e {
        let b = (((x - lo) / width) as usize).min(bins - 1);
        counts[b] += 1;
    }
    let (mut xs, mut ys) = (vec![lo], vec![0.0]);
    for (b, &c) in counts.iter().enumerate() {
        let (a, z) = (lo + b as f64 * width, lo + (b + 1) as f64 * width);
        xs.extend([a, z]);
        ys.extend([c as f64, c as f64]);
    }
    xs.push(hi);
    ys.push(0.0);
    fig = fig.with(Series::new(
        format!("{} devices, {bins} bins", e.len()),
        SeriesStyle::Line,
        xs,
        ys,
    ));
    if let Some(sp) = s.headline_spread().filter(|sp| sp.std > 0.0) {
        let (m, sd) = (100.0 * sp.mean, 100.0 * sp.std);
        let n = sp.n as f64;
        let xs: Vec<f64> = (0..=200)
            .map(|i| lo + (hi - lo) * i as f64 / 200.0)
            .collect();
        let ys = xs
            .iter()
            .map(|x| {
                let u = (x - m) / sd;
                n * width * (-0.5 * u * u).exp() / (sd * (2.0 * core::f64::consts::PI).sqrt())
            })
            .collect();
        fig = fig.with(Series::new(
            format!("normal of the same mean {m:.3} % and std {sd:.3} %"),
            SeriesStyle::DashedLine,
            xs,
            ys,
        ));
    }
    fig
}

/// Most staircase steps drawn of the empirical distribution (a larger lot is drawn through
/// this many of its order statistics, evenly spaced).
const CDF_STEPS: usize = 2000;

/// The empirical distribution of |headline error| with its percentiles and the spec, drawn as
/// the fraction of devices above each |error| (1 at 0, falling to 0): the tail the spec cuts
/// off is read directly, and the legend's corner stays clear of the curve.
pub fn percentiles_figure(devices: &[DeviceResult], s: &LotSummary) -> Figure {
    let mut a: Vec<f64> = headline_percent(devices).iter().map(|x| x.abs()).collect();
    a.sort_by(f64::total_cmp);
    let spec = 100.0 * s.spec_abs_relative_error;
    let title = format!("Lot of {} devices: {}", s.devices, yield_text(s));
    let mut fig = Figure::new(
        title,
        format!("|self-calibration error|, {} (%)", s.headline),
        "fraction of devices above",
    )
    .with_marker(spec, "spec");
    let n = a.len();
    if n == 0 {
        return fig;
    }
    let (mut xs, mut ys) = (vec![0.0], vec![1.0]);
    let steps = n.min(CDF_STEPS);
    let mut prev = 1.0;
    for j in 0..steps {
        let i = if steps == n {
            j
        } else {
            j * (n - 1) / (steps - 1)
        };
        let above = 1.0 - (i + 1) as f64 / n as f64;
        xs.extend([a[i], a[i]]);
        ys.extend([prev, above]);
        prev = above;
    }
    let unreliable = if s.unreliable.is_empty() {
        String::new()
    } else {
        format!(", {} unreliable left out", s.unreliable.len())
    };
    fig = fig.with(Series::new(
        format!("empirical, {n} devices{unreliable}"),
        SeriesStyle::Line,
        xs,
        ys,
    ));
    if let Some(sp) = s.headline_spread() {
        let names: Vec<String> = sp
            .abs_percentiles
            .iter()
            .map(|&(p, v)| format!("P{p} {:.3} %", 100.0 * v))
            .collect();
        fig = fig.with(Series::new(
            names.join(", "),
            SeriesStyle::Points,
            sp.abs_percentiles.iter().map(|&(_, v)| 100.0 * v).collect(),
            PERCENTILES.iter().map(|p| 1.0 - p / 100.0).collect(),
        ));
    }
    fig
}

/// Writes the lot's files into `dir` from its devices (every index of the lot, in index
/// order); returns their paths and the lot's figures.
pub fn write_lot(
    dir: &Path,
    cfg: &Config,
    devices: &[DeviceResult],
) -> Result<(Vec<PathBuf>, LotSummary), ReportError> {
    create_dir(dir)?;
    let spec = cfg
        .montecarlo
        .as_ref()
        .map_or(f64::NAN, |m| m.spec_abs_relative_error);
    let s = LotSummary::of(devices, spec);
    let [csv, json, hist, cdf] = LOT_FILES.map(|f| dir.join(f));
    write_csv(&csv, &devices_table(devices, spec))?;
    write_json(&json, &lot_json(cfg, devices, &s))?;
    render_png(&histogram_figure(devices, &s), &hist)?;
    render_png(&percentiles_figure(devices, &s), &cdf)?;
    Ok((vec![csv, json, hist, cdf], s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_analysis::montecarlo::HEADLINE;

    fn device(index: u64, values: Vec<f64>, problem: bool) -> DeviceResult {
        DeviceResult {
            index,
            values,
            problems: if problem {
                vec!["refused".into()]
            } else {
                vec![]
            },
            warnings: vec![],
            point_samples: 0,
        }
    }

    #[test]
    fn a_column_short_of_the_reliable_devices_is_named_with_its_count() {
        let finite = vec![0.01; COLUMNS.len()];
        // Device 1 is reliable but has no combined error; device 2 is unreliable (refused).
        let other = COLUMNS
            .iter()
            .position(|c| c.name == "board_combined_relative_error")
            .unwrap();
        let mut gap = finite.clone();
        gap[other] = f64::NAN;
        let lot = [
            device(0, finite.clone(), false),
            device(1, gap, false),
            device(2, finite.clone(), true),
            device(3, finite, false),
        ];
        let s = LotSummary::of(&lot, 0.02);
        let w = spread_gaps(&s);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].starts_with("board_combined_relative_error: 1 of the 3 reliable devices")
                && w[0].contains("(n = 2)"),
            "{}",
            w[0]
        );
        // The unreliable device alone shortens no column: the lot's own count says so.
        let whole = LotSummary::of(&lot[2..], 0.02);
        assert!(spread_gaps(&whole).is_empty());
        assert!(s.errors.iter().any(|(n, _)| *n == HEADLINE));
    }
}
