//! What a run writes: `results.csv` (one row per rate), `summary.json` (fits, theory slopes,
//! compensation), and a paper-style plot. Every file is written atomically.

use crate::error::{create_dir, ReportError};
use gyroemu_board::{Health, Shape};
use gyroemu_config::Config;
use gyroemu_experiment::{theory_deg, SweepResult};
use gyroemu_io::{write_csv, write_json, CsvCell, CsvTable};
use gyroemu_plot::{render_png, Figure, Series, SeriesStyle};
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
pub fn summary(cfg: &Config, r: &SweepResult) -> serde_json::Value {
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
        "warnings": with_config_warnings(cfg.validate(), &r.warnings),
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

/// Dense theory curve over `[0, x_max]` for one mode, the x axis scaled by `x_scale`.
pub fn theory_series(cfg: &Config, x_max: f64, mode: usize, x_scale: f64, name: &str) -> Series {
    let xs: Vec<f64> = (0..=100).map(|i| x_max * i as f64 / 100.0).collect();
    Series {
        name: name.to_string(),
        style: SeriesStyle::Line,
        ys: xs.iter().map(|&x| theory_deg(cfg, x)[mode]).collect(),
        xs: xs.iter().map(|x| x * x_scale).collect(),
    }
}

/// Measured points, theory and best linear fit of one sweep, both modes.
pub fn sweep_figure(cfg: &Config, r: &SweepResult, title: &str) -> Figure {
    let (xl, yl) = axis_labels(r);
    let xs: Vec<f64> = r.points.iter().map(|p| p.rate_dps).collect();
    let x_max = xs.iter().cloned().fold(0.0, f64::max);
    let mut fig = Figure::new(title, xl, yl);
    for k in 0..2 {
        fig = fig.with(Series {
            name: format!("mode {} emulated", k + 1),
            style: if k == 0 {
                SeriesStyle::Points
            } else {
                SeriesStyle::OpenPoints
            },
            xs: xs.clone(),
            ys: r.points.iter().map(|p| p.phase_deg[k]).collect(),
        });
    }
    let theory_name = if matches!(r.shape, Shape::RateTable { .. }) {
        "small-signal theory (first-order low-pass), mode 1"
    } else {
        "exact theory, mode 1"
    };
    fig = fig.with(theory_series(cfg, x_max, 0, 1.0, theory_name));
    if (cfg.drive.f1 - cfg.f2()).abs() > 0.0 {
        fig = fig.with(theory_series(cfg, x_max, 1, 1.0, "exact theory, mode 2"));
    }
    let f = r.fit[0];
    fig.with(Series {
        name: format!(
            "best linear fit, mode 1: {:.6} deg per deg/s (R^2 = {:.6})",
            f.slope, f.r2
        ),
        style: SeriesStyle::DashedLine,
        xs: vec![0.0, x_max],
        ys: vec![f.intercept, f.intercept + f.slope * x_max],
    })
}

/// The files [`write_run`] writes into its folder.
pub const RUN_FILES: [&str; 3] = ["results.csv", "summary.json", "plot.png"];

/// Writes `results.csv`, `summary.json` and `plot.png` into `dir`; returns their paths.
pub fn write_run(
    dir: &Path,
    cfg: &Config,
    r: &SweepResult,
    title: &str,
) -> Result<Vec<PathBuf>, ReportError> {
    create_dir(dir)?;
    let [csv, json, png] = RUN_FILES.map(|f| dir.join(f));
    write_csv(&csv, &results_table(r))?;
    write_json(&json, &summary(cfg, r))?;
    render_png(&sweep_figure(cfg, r, title), &png)?;
    Ok(vec![csv, json, png])
}

/// The plot title of a run.
pub fn run_title(cfg: &Config) -> String {
    format!(
        "{:?} run, f0 = {} Hz, Q = {}",
        cfg.experiment.kind, cfg.device.f0_hz, cfg.device.q
    )
}
