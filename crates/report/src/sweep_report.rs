//! What a run writes: `results.csv` (one row per rate), `summary.json` (fits, theory slopes,
//! compensation), and a paper-style plot. Every file is written atomically.

use crate::error::{create_dir, ReportError};
use gyroemu_board::{Health, Shape};
use gyroemu_config::Config;
use gyroemu_experiment::fit::LineFit;
use gyroemu_experiment::{fit_readings, reading_period_deg, theory_deg, SweepResult};
use gyroemu_io::{write_csv, write_json, CsvCell, CsvTable};
use gyroemu_plot::{render_png_copies, Figure, Series, SeriesStyle};
use serde_json::json;
use std::path::{Path, PathBuf};

/// The rows of `results.csv`.
pub fn results_table(r: &SweepResult) -> CsvTable {
    let mut headers: Vec<&str> = vec![
        "rate_dps",
        "phase_mode1_deg",
        "phase_mode2_deg",
        "theory_mode1_deg",
        "theory_mode2_deg",
        "error_mode1_mdeg",
        "error_mode2_mdeg",
    ];
    match r.shape {
        Shape::Coriolis => headers.extend(["single_mixer_dc_mode1_v", "single_mixer_dc_mode2_v"]),
        Shape::RateTable { .. } => headers.extend([
            "table_lag_mode1_deg",
            "table_lag_mode2_deg",
            "table_lag_theory_mode1_deg",
            "table_lag_theory_mode2_deg",
            "table_lag_error_mode1_mdeg",
            "table_lag_error_mode2_mdeg",
        ]),
        Shape::Rotating => headers.extend([
            "paper_i_mode1_deg",
            "paper_i_mode2_deg",
            "raw_psi_mode1_deg",
            "raw_psi_mode2_deg",
            "alpha_mode1_deg",
            "alpha_mode2_deg",
        ]),
    }
    headers.push("averaged_s");
    let rows = r
        .points
        .iter()
        .map(|p| {
            let mut row: Vec<f64> = vec![
                p.rate_dps,
                p.phase_deg[0],
                p.phase_deg[1],
                p.theory_deg[0],
                p.theory_deg[1],
            ];
            row.extend((0..2).map(|k| (p.phase_deg[k] - p.theory_deg[k]) * 1e3));
            for pair in [
                p.single_mixer_dc_v,
                p.table_lag_deg,
                p.paper_i_deg,
                p.raw_psi_deg,
                p.alpha_deg,
            ]
            .into_iter()
            .flatten()
            {
                row.extend(pair);
            }
            if let (Some(lag), Some(t)) = (p.table_lag_deg, p.table_lag_theory_deg) {
                row.extend(t);
                row.extend((0..2).map(|k| (lag[k] - t[k]) * 1e3));
            }
            row.push(p.averaged_s);
            row.into_iter().map(CsvCell::F64).collect()
        })
        .collect();
    CsvTable {
        headers: headers.into_iter().map(String::from).collect(),
        rows,
    }
}

/// The content of `summary.json`: deterministic (no timings), so reruns compare byte for byte.
/// `cfg` is the config the sweep ran (a `[pll]`'s held carrier in place of the section),
/// `judged` the one whose validation warnings stderr gave before the run (the user's).
pub fn summary(cfg: &Config, judged: &Config, r: &SweepResult) -> serde_json::Value {
    summary_with(cfg, judged.validate(), r)
}

/// [`summary`] with the judged config's validation already done (`validated`: its warnings,
/// or the error that stopped it).
pub fn summary_with(
    cfg: &Config,
    validated: Result<Vec<String>, gyroemu_config::ConfigError>,
    r: &SweepResult,
) -> serde_json::Value {
    let fit = |k: usize| {
        json!({
            "slope_deg_per_dps": r.fit[k].slope,
            "intercept_deg": r.fit[k].intercept,
            "r2": r.fit[k].r2,
            "theory_slope_deg_per_dps": r.theory_slope_deg_per_dps[k],
            "slope_relative_error": r.fit[k].slope / r.theory_slope_deg_per_dps[k] - 1.0,
            "max_abs_error_mdeg": r.max_abs_error_mdeg(k),
        })
    };
    json!({
        "gyroemu_version": env!("CARGO_PKG_VERSION"),
        "kind": if r.shape.is_rotating() { "rotating" } else { "coriolis" },
        "rate_table": match r.shape {
            Shape::RateTable { .. } => "sinusoid",
            _ => "constant",
        },
        "mode1": fit(0),
        "mode2": fit(1),
        "compensation_mdeg": r.compensation,
        "settle_s": r.settle_s,
        "fs_hz": r.fs_hz,
        "fs_out_hz": r.fs_out_hz,
        "point_samples_emulated": r.point_samples,
        "converter_counts": health_json(&r.health),
        "problems": r.problems,
        "warnings": with_config_warnings(validated, &r.warnings),
        "config": cfg,
    })
}

/// The config's own warnings (`validated`: what its validation, printed before the run, gave)
/// followed by `run`'s: a results file read without the terminal's log still carries every
/// caveat on its numbers (an ADC's rounding, a folded mixer product, the DAC's hold).
pub fn with_config_warnings(
    validated: Result<Vec<String>, gyroemu_config::ConfigError>,
    run: &[String],
) -> Vec<String> {
    let mut w = validated.unwrap_or_default();
    w.extend(run.iter().cloned());
    w
}

/// The converter and rail counts as JSON (samples counted over every point's whole run).
pub fn health_json(h: &Health) -> serde_json::Value {
    json!({
        "samples": h.samples,
        "dac_clipped_samples": h.dac_clipped,
        "dac_zero_samples": h.dac_zero,
        "tia_rail_samples": h.tia_railed,
        "adc_clipped_samples": h.adc_clipped,
        "adc_zero_samples": h.adc_zero,
    })
}

/// Labels of a sweep's axes.
pub fn axis_labels(r: &SweepResult) -> (&'static str, &'static str) {
    match r.shape {
        Shape::Coriolis => ("Rotation rate (deg/s)", "Phase shift (deg)"),
        Shape::RateTable { .. } => (
            "Rate-table amplitude (deg/s)",
            "Phase amplitude at table frequency (deg)",
        ),
        Shape::Rotating => ("Excitation rate Omega (deg/s)", "Phase psi (deg)"),
    }
}

/// The span the theory and fit lines cover: from the origin (where the paper's lines start)
/// out to the farthest rate on each side, so negative rates get their lines too.
pub fn line_span(rates: &[f64]) -> (f64, f64) {
    rates
        .iter()
        .filter(|x| x.is_finite())
        .fold((0.0, 0.0), |(lo, hi), &x| (x.min(lo), x.max(hi)))
}

/// Abscissae of a theory curve: `steps` even steps over `[lo, hi]`, halvings of the first step
/// on each side towards 0 (a phase saturating at large rates turns most steeply there), and
/// the measured `rates` themselves, so the line goes through the theory at every point.
pub fn theory_abscissae(lo: f64, hi: f64, rates: &[f64], steps: usize) -> Vec<f64> {
    let mut xs: Vec<f64> = (0..=steps)
        .map(|i| lo + (hi - lo) * i as f64 / steps as f64)
        .chain((1..=6).flat_map(|j| [lo, hi].map(|e| e / steps as f64 * 0.5f64.powi(j))))
        .chain(rates.iter().copied().filter(|x| x.is_finite()))
        .collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    xs
}

/// The theory of both modes at each of `xs`. A rotating excitation has no psi at Omega = 0
/// (its two sidebands coincide; the config refuses the rate): NaN there, so the line breaks
/// instead of dropping to the ideal device's 0, which an imperfect mode 2 is nowhere near.
pub fn theory_curves(cfg: &Config, xs: &[f64]) -> [Vec<f64>; 2] {
    let rotating = cfg.shape().is_rotating();
    let t: Vec<[f64; 2]> = xs
        .iter()
        .map(|&x| {
            if rotating && x == 0.0 {
                [f64::NAN; 2]
            } else {
                theory_deg(cfg, x)
            }
        })
        .collect();
    [0, 1].map(|k| t.iter().map(|v| v[k]).collect())
}

/// Dense theory curve of one mode over the abscissae `xs` (see [`theory_abscissae`]), the x
/// axis scaled by `x_scale`.
pub fn theory_series(cfg: &Config, xs: &[f64], mode: usize, x_scale: f64, name: &str) -> Series {
    let [t1, t2] = theory_curves(cfg, xs);
    Series {
        name: name.to_string(),
        style: SeriesStyle::Line,
        ys: if mode == 0 { t1 } else { t2 },
        xs: xs.iter().map(|x| x * x_scale).collect(),
    }
}

/// Whether two theory curves differ anywhere: beyond rounding (the two modes' theories of an
/// ideal device, computed apart, differ in the last digits) or in where they are finite.
pub fn curves_differ(a: &[f64], b: &[f64]) -> bool {
    let scale = a
        .iter()
        .chain(b)
        .filter(|v| v.is_finite())
        .fold(0.0, |m: f64, v| m.max(v.abs()));
    a.iter().zip(b).any(|(x, y)| {
        if x.is_finite() && y.is_finite() {
            (x - y).abs() > 1e-9 * scale
        } else {
            x.is_finite() != y.is_finite()
        }
    })
}

/// Legend of one mode's measured points: a refused phase (NaN) draws no marker, so the legend
/// says how many went rather than leave an empty or thinned series unexplained.
fn points_name(r: &SweepResult, k: usize) -> String {
    let n = r.points.len();
    let refused = r
        .points
        .iter()
        .filter(|p| !p.phase_deg[k].is_finite())
        .count();
    match refused {
        0 => format!("mode {} emulated", k + 1),
        _ if refused == n => format!("mode {}: no finite phase (refused)", k + 1),
        _ => format!(
            "mode {} emulated ({refused} of {n} points refused: no finite phase)",
            k + 1
        ),
    }
}

/// One mode's measured phases, in the order of the points.
pub(crate) fn phases(r: &SweepResult, k: usize) -> Vec<f64> {
    r.points.iter().map(|p| p.phase_deg[k]).collect()
}

/// The legend entry and dashed line of a best linear fit, as every sweep figure draws it: the
/// line `fit` over `span` (see [`line_span`]), labelled "best linear fit, `who`: slope deg per
/// deg/s (R^2)". `fit` is of `ys` against `xs`, in the figure's own axes. A fit that is not a
/// finite number while every point is finite gets a legend entry saying why and no line; one
/// whose points were refused gets nothing (the points' legend already says so).
pub fn fit_series(
    who: &str,
    fit: &LineFit,
    xs: &[f64],
    ys: &[f64],
    span: (f64, f64),
) -> Option<Series> {
    let (lo, hi) = span;
    if fit.slope.is_finite() && fit.intercept.is_finite() {
        return Some(Series {
            name: format!(
                "best linear fit, {who}: {:.6} deg per deg/s (R^2 = {:.6})",
                fit.slope, fit.r2
            ),
            style: SeriesStyle::DashedLine,
            xs: vec![lo, hi],
            ys: vec![
                fit.intercept + fit.slope * lo,
                fit.intercept + fit.slope * hi,
            ],
        });
    }
    if !ys.iter().all(|y| y.is_finite()) {
        return None;
    }
    // No refusal explains the missing fit: say what does, with no line drawn.
    let distinct = xs.first().is_some_and(|&a| xs.iter().any(|&x| x != a));
    Some(Series {
        name: if distinct {
            format!("best linear fit, {who}: not a finite number")
        } else {
            format!("best linear fit, {who}: none (needs two distinct rates)")
        },
        style: SeriesStyle::DashedLine,
        xs: Vec::new(),
        ys: Vec::new(),
    })
}

/// Measured points, theory and best linear fit of one sweep, both modes. Mode 2's theory gets
/// its own line whenever it differs from mode 1's on the plotted span (a mode offset,
/// `q_mode2`, k12, a phase-shifter error or F1 != F2), else one line is labelled for both.
pub fn sweep_figure(cfg: &Config, r: &SweepResult, title: &str) -> Figure {
    let (xl, yl) = axis_labels(r);
    let xs: Vec<f64> = r.points.iter().map(|p| p.rate_dps).collect();
    let (lo, hi) = line_span(&xs);
    let mut fig = Figure::new(title, xl, yl);
    for k in 0..2 {
        fig = fig.with(Series {
            name: points_name(r, k),
            style: if k == 0 {
                SeriesStyle::Points
            } else {
                SeriesStyle::OpenPoints
            },
            xs: xs.clone(),
            ys: phases(r, k),
        });
    }
    // A rate table's theory is the exact harmonic balance (`theory_deg`), not the first-order
    // small-signal model, which only its summary's theory slope uses.
    let theory = if matches!(r.shape, Shape::RateTable { .. }) {
        "exact theory (harmonic balance)"
    } else {
        "exact theory"
    };
    // A rate table's theory is a harmonic balance per abscissa (its overlay had become a fifth
    // of the preset's run); its phase amplitude bends gently with the swing, so 40 steps draw
    // it as smoothly as 100 draw the others.
    let steps = if matches!(r.shape, Shape::RateTable { .. }) {
        40
    } else {
        100
    };
    let txs = theory_abscissae(lo, hi, &xs, steps);
    let [t1, t2] = theory_curves(cfg, &txs);
    let own_mode2 = curves_differ(&t1, &t2);
    let line = |name: String, ys: Vec<f64>| Series {
        name,
        style: SeriesStyle::Line,
        xs: txs.clone(),
        ys,
    };
    if own_mode2 {
        fig = fig
            .with(line(format!("{theory}, mode 1"), t1))
            .with(line(format!("{theory}, mode 2"), t2));
    } else {
        fig = fig.with(line(format!("{theory}, modes 1 and 2"), t1));
    }
    // The line is fitted to the readings unwrapped along rate; where that moved one (psi
    // across its branch cut), the points sit a half turn off it, and the legend says why.
    let ys = phases(r, 0);
    let period = reading_period_deg(r.shape);
    let moved = fit_readings(cfg, &xs, &ys, 0)
        .iter()
        .zip(&ys)
        .any(|(u, y)| u.to_bits() != y.to_bits() && !y.is_nan());
    let who = if moved {
        format!("mode 1, readings unwrapped by {period} deg along rate")
    } else {
        "mode 1".to_string()
    };
    if let Some(s) = fit_series(&who, &r.fit[0], &xs, &ys, (lo, hi)) {
        fig = fig.with(s);
    }
    fig
}

/// The files [`write_run`] writes into its folder.
pub const RUN_FILES: [&str; 3] = ["results.csv", "summary.json", "plot.png"];

/// Writes `results.csv`, `summary.json` and `plot.png` into `dir`; returns their paths. `cfg`
/// and `judged` as for [`summary`].
pub fn write_run(
    dir: &Path,
    cfg: &Config,
    judged: &Config,
    r: &SweepResult,
    title: &str,
) -> Result<Vec<PathBuf>, ReportError> {
    write_run_with(
        dir,
        cfg,
        judged.validate(),
        r,
        &sweep_figure(cfg, r, title),
        &[],
    )
}

/// [`write_run`] with the judged config's validation already done (`validated`, as
/// [`summary_with`] takes it) and the run's figure drawn (`figure`, [`sweep_figure`]'s);
/// `plot.png`'s bytes are also written at each of `copies` (drawn and encoded once).
pub fn write_run_with(
    dir: &Path,
    cfg: &Config,
    validated: Result<Vec<String>, gyroemu_config::ConfigError>,
    r: &SweepResult,
    figure: &Figure,
    copies: &[&Path],
) -> Result<Vec<PathBuf>, ReportError> {
    create_dir(dir)?;
    let [csv, json, png] = RUN_FILES.map(|f| dir.join(f));
    write_csv(&csv, &results_table(r))?;
    write_json(&json, &summary_with(cfg, validated, r))?;
    let mut targets = vec![png.as_path()];
    targets.extend_from_slice(copies);
    render_png_copies(figure, &targets)?;
    Ok(vec![csv, json, png])
}

/// The plot title of a run: each mode's resonance and Q when they differ (mode 1's alone
/// would misdescribe mode 2's points).
pub fn run_title(cfg: &Config) -> String {
    let d = &cfg.device;
    let f0 = if cfg.f0_mode2_hz() != d.f0_hz {
        format!("f01 = {} Hz, f02 = {} Hz", d.f0_hz, cfg.f0_mode2_hz())
    } else {
        format!("f0 = {} Hz", d.f0_hz)
    };
    let q = match d.q_mode2 {
        Some(q2) if q2 != d.q => format!("Q1 = {}, Q2 = {q2}", d.q),
        _ => format!("Q = {}", d.q),
    };
    format!("{:?} run, {f0}, {q}", cfg.experiment.kind)
}
