//! What `selfcal` writes: selfcal.json, selfcal.csv, selfcal.png, and allan.*,
//! error_vs_tau.*, drift.* for the analyses that ran. Every file is written atomically.

use crate::error::ReportError;
use crate::sweep_report::{health_json, with_config_warnings};
use gyroemu_analysis::allan::fit::NoiseModelFit;
use gyroemu_analysis::allan::AllanPoint;
use gyroemu_analysis::selfcal::SelfcalCore;
use gyroemu_analysis::selfcal_analyses::{AllanResult, DriftCase, DriftPoint, TauPoint};
use gyroemu_analysis::SelfcalReport;
use gyroemu_config::Config;
use gyroemu_core::sig3;
use gyroemu_io::{write_csv, write_json, CsvCell, CsvTable};
use gyroemu_plot::{render_panels_png, render_png, Figure, Series, SeriesStyle};
use serde_json::json;
use std::path::{Path, PathBuf};

/// The files of the analyses, each written only when its analysis runs.
pub const SELFCAL_ANALYSIS_FILES: [&str; 6] = [
    "allan.csv",
    "allan.png",
    "error_vs_tau.csv",
    "error_vs_tau.png",
    "drift.csv",
    "drift.png",
];

/// What [`write_selfcal`] did in the output folder.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SelfcalFiles {
    /// The files written.
    pub written: Vec<PathBuf>,
    /// Analysis files of an earlier run that this one did not write, deleted so that none
    /// sits beside a `selfcal.json` saying its analysis did not run.
    pub removed: Vec<PathBuf>,
}

/// Writes the self-calibration's files into `out`, then deletes the analysis files of an
/// earlier run that this one did not write. `cfg` is the config the sweeps ran (a `[pll]`'s
/// held carrier in place of the section), `judged` the one whose validation warnings stderr
/// gave before the run (the user's).
pub fn write_selfcal(
    out: &Path,
    cfg: &Config,
    judged: &Config,
    report: &SelfcalReport,
) -> Result<SelfcalFiles, ReportError> {
    let written = write_selfcal_files(out, cfg, judged, report)?;
    let mut removed = Vec::new();
    for name in SELFCAL_ANALYSIS_FILES {
        let p = out.join(name);
        if written.contains(&p) || !p.exists() {
            continue;
        }
        std::fs::remove_file(&p).map_err(|source| ReportError::Remove {
            path: p.clone(),
            reason: source,
        })?;
        removed.push(p);
    }
    Ok(SelfcalFiles { written, removed })
}

fn write_selfcal_files(
    out: &Path,
    cfg: &Config,
    judged: &Config,
    report: &SelfcalReport,
) -> Result<Vec<PathBuf>, ReportError> {
    let core = &report.core;
    let (allan, taus, drift) = (
        report.allan.as_ref(),
        report.taus.as_deref(),
        report.drift.as_deref(),
    );
    let (m, c) = (core.modes[0], core.combined);
    let scale_s = m.predicted_deg_per_dps; // rad per rad/s is the same number
    let summary = json!({
        "gyroemu_version": env!("CARGO_PKG_VERSION"),
        "angular_gain": core.angular_gain,
        "averaging_s": cfg.experiment.average_s,
        "rotating_slope_deg_per_dps": m.rotating.slope_deg_per_dps,
        "predicted_coriolis_slope_deg_per_dps": m.predicted_deg_per_dps,
        "predicted_coriolis_scale_factor_s": scale_s,
        "predicted_coriolis_slope_mdeg_per_dph": m.predicted_deg_per_dps * 1e3 / 3600.0,
        "measured_coriolis_slope_deg_per_dps": m.coriolis.slope_deg_per_dps,
        "relative_error": m.relative_error,
        "relative_error_ci95": m.relative_error_ci95,
        "relative_error_theory": m.relative_error_theory,
        "theory_coriolis_slope_deg_per_dps": m.theory_coriolis_deg_per_dps,
        "combined_rotating_slope_deg_per_dps": c.rotating.slope_deg_per_dps,
        "combined_predicted_coriolis_slope_deg_per_dps": c.predicted_deg_per_dps,
        "combined_measured_coriolis_slope_deg_per_dps": c.coriolis.slope_deg_per_dps,
        "combined_relative_error": c.relative_error,
        "combined_relative_error_ci95": c.relative_error_ci95,
        "combined_relative_error_theory": c.relative_error_theory,
        "combined_theory_coriolis_slope_deg_per_dps": c.theory_coriolis_deg_per_dps,
        "modes": core.modes,
        "combined": c,
        "single_channel_vs_iq": {
            "rotating_iq_slope_deg_per_dps": m.rotating.slope_deg_per_dps,
            "rotating_paper_i_slope_deg_per_dps": m.rotating_paper_i.slope_deg_per_dps,
            "relative_error_iq": m.relative_error,
            "relative_error_paper_i": m.relative_error_paper_i,
            "rotating_iq_fit_r2": m.rotating.plain_fit.r2,
            "rotating_paper_i_fit_r2": m.rotating_paper_i.plain_fit.r2,
        },
        "rotating_points": core.rotating.points,
        "coriolis_points": core.coriolis.points,
        "compensation_mdeg": core.rotating.compensation,
        "converter_counts": {
            "rotating": health_json(&core.rotating.health),
            "coriolis": health_json(&core.coriolis.health),
        },
        "problems": core.rotating.problems.iter().chain(&core.coriolis.problems).collect::<Vec<_>>(),
        // The config's warnings and those of the sweeps selfcal derives from it, as stderr
        // gave them, then the run's.
        "warnings": with_config_warnings(
            gyroemu_analysis::selfcal::validate_selfcal(judged),
            &report.warnings()
        ),
        "allan": allan.map(allan_json),
        "error_vs_averaging_time": taus,
        "drift": drift,
        "config": cfg,
    });
    let mut files = Vec::new();
    let mut path = |name: &str| {
        let p = out.join(name);
        files.push(p.clone());
        p
    };
    write_json(&path("selfcal.json"), &summary)?;
    write_csv(&path("selfcal.csv"), &points_table(core))?;
    render_png(&selfcal_figure(core), &path("selfcal.png"))?;
    if let Some(a) = allan {
        write_csv(&path("allan.csv"), &allan_table(a))?;
        render_allan_png(a, &path("allan.png"))?;
    }
    if let Some(t) = taus {
        write_csv(&path("error_vs_tau.csv"), &tau_table(t))?;
        render_png(
            &tau_figure(t, cfg.experiment.average_s),
            &path("error_vs_tau.png"),
        )?;
    }
    if let Some(d) = drift {
        write_csv(&path("drift.csv"), &drift_table(d))?;
        render_panels_png(
            "Drift: self-calibration with the carrier open loop and PLL-tracked",
            &drift_figures(d),
            2,
            1600,
            650,
            &path("drift.png"),
        )?;
    }
    Ok(files)
}

fn table(headers: &[&str], rows: Vec<Vec<f64>>) -> CsvTable {
    CsvTable {
        headers: headers.iter().map(|h| h.to_string()).collect(),
        rows: rows
            .into_iter()
            .map(|r| r.into_iter().map(CsvCell::F64).collect())
            .collect(),
    }
}

fn points_table(core: &SelfcalCore) -> CsvTable {
    // One row per rate-table point. The rotating sweep leaves rate 0 out (it has no sidebands),
    // so its points are matched by rate, in order; a rate it did not run reads NaN there.
    let mut rotating = core.rotating.points.iter().peekable();
    let rows = core
        .coriolis
        .points
        .iter()
        .map(|c| {
            let r = rotating.next_if(|r| r.rate_dps.to_bits() == c.rate_dps.to_bits());
            let psi = r.map_or([f64::NAN; 2], |r| r.phase_deg);
            let paper = r.and_then(|r| r.paper_i_deg).unwrap_or([f64::NAN; 2]);
            vec![
                c.rate_dps,
                psi[0],
                psi[1],
                paper[0],
                paper[1],
                c.phase_deg[0],
                c.phase_deg[1],
                c.theory_deg[0],
            ]
        })
        .collect();
    table(
        &[
            "rate_dps",
            "rotating_psi_mode1_deg",
            "rotating_psi_mode2_deg",
            "rotating_paper_i_mode1_deg",
            "rotating_paper_i_mode2_deg",
            "coriolis_phase_mode1_deg",
            "coriolis_phase_mode2_deg",
            "coriolis_theory_mode1_deg",
        ],
        rows,
    )
}

fn selfcal_figure(core: &SelfcalCore) -> Figure {
    let m = core.modes[0];
    let lambda = core.angular_gain;
    let xs: Vec<f64> = core.coriolis.points.iter().map(|p| p.rate_dps).collect();
    let x_max = xs.iter().cloned().fold(0.0, f64::max);
    let line = |slope: f64| -> Vec<f64> {
        [0.0, x_max]
            .iter()
            .map(|x| (slope.to_radians() * x).atan().to_degrees())
            .collect()
    };
    Figure::new(
        format!(
            "predicted / measured - 1: mode 1 {:+.2e} +- {:.1e}, both modes {:+.2e} +- {:.1e} (95 %)",
            m.relative_error,
            m.relative_error_ci95,
            core.combined.relative_error,
            core.combined.relative_error_ci95
        ),
        "Rotation rate, or excitation rate / lambda (deg/s)",
        "Phase (deg), mode 1",
    )
    .with(Series::new(
        "rate table (Coriolis), measured",
        SeriesStyle::Points,
        xs.clone(),
        core.coriolis
            .points
            .iter()
            .map(|p| p.phase_deg[0])
            .collect(),
    ))
    .with(Series::new(
        "rotating excitation, measured (x / lambda)",
        SeriesStyle::OpenPoints,
        core.rotating
            .points
            .iter()
            .map(|p| p.rate_dps / lambda)
            .collect(),
        // A rotating excitation at Omega gives the Coriolis phase of Omega / lambda; its
        // small-angle slope per Omega is the Coriolis one divided by lambda.
        core.rotating
            .points
            .iter()
            .map(|p| p.phase_deg[0])
            .collect(),
    ))
    .with(Series::new(
        format!(
            "self-calibrated: lambda x rotating slope = {:.6} deg per deg/s",
            m.predicted_deg_per_dps
        ),
        SeriesStyle::Line,
        vec![0.0, x_max],
        line(m.predicted_deg_per_dps),
    ))
    .with(Series::new(
        format!(
            "rate table: {:.6} deg per deg/s",
            m.coriolis.slope_deg_per_dps
        ),
        SeriesStyle::DashedLine,
        vec![0.0, x_max],
        line(m.coriolis.slope_deg_per_dps),
    ))
}

fn allan_table(a: &AllanResult) -> CsvTable {
    let rows = a
        .phase_deg
        .iter()
        .zip(&a.rate_dps)
        .map(|(p, r)| vec![p.tau_s, p.adev, r.adev, r.adev * 3600.0, p.n_terms as f64])
        .collect();
    table(
        &[
            "tau_s",
            "adev_phase_deg",
            "adev_rate_dps",
            "adev_rate_dph",
            "n_terms",
        ],
        rows,
    )
}

/// `allan` of `selfcal.json`: the Allan result with the noise-model fit beside its readings,
/// as `model_fit` (null without readings).
fn allan_json(a: &AllanResult) -> serde_json::Value {
    let mut v = json!(a);
    v["model_fit"] = json!(a.readings.map(|r| r.model_fit));
    v
}

/// The legend of the fitted curve: its determined terms.
fn fit_label(f: &NoiseModelFit) -> String {
    let terms: Vec<String> = [
        ("N", f.arw_deg_per_rt_h, "deg/sqrt(h)"),
        ("B", f.bias_instability_deg_per_h, "deg/h"),
        ("K", f.rate_random_walk_deg_per_h_per_rt_h, "deg/h/sqrt(h)"),
        ("Q", f.quantisation_deg, "deg"),
    ]
    .iter()
    .filter(|t| t.1.is_finite())
    .map(|(name, v, unit)| format!("{name} = {} {unit}", sig3(*v)))
    .collect();
    format!("noise-model fit (IEEE 952): {}", terms.join(", "))
}

fn log_series(name: &str, style: SeriesStyle, pts: &[AllanPoint], scale: f64) -> Series {
    Series::new(
        name,
        style,
        pts.iter().map(|p| p.tau_s).collect(),
        pts.iter().map(|p| p.adev * scale).collect(),
    )
}

/// The overall title of `allan.png`: the noise readings, or why one was not taken.
pub fn allan_title(a: &AllanResult) -> String {
    // Three significant figures, as the fit beside them; a reading that could not be taken
    // says so instead of printing NaN.
    let read = |v: f64, unit: &str| {
        if v.is_finite() {
            format!("{} {unit}", sig3(v))
        } else {
            "not read (see warnings)".to_string()
        }
    };
    match a.readings {
        Some(r) => {
            let mut t = format!(
                "Allan deviation at zero rate: ARW {}, bias instability {}",
                read(r.arw_deg_per_rt_h, "deg/sqrt(h)"),
                read(r.bias_instability_deg_per_h, "deg/h")
            );
            let f = r.model_fit;
            if f.arw_deg_per_rt_h.is_finite() || f.bias_instability_deg_per_h.is_finite() {
                t += &format!("; {}", fit_label(&f));
            }
            t
        }
        None => "Allan deviation at zero rate".to_string(),
    }
}

/// Renders `allan.png` at `path`: [`allan_panels`] side by side under [`allan_title`].
pub fn render_allan_png(a: &AllanResult, path: &Path) -> Result<(), ReportError> {
    render_panels_png(&allan_title(a), &allan_panels(a), 2, 1600, 650, path)?;
    Ok(())
}

/// The two panels of `allan.png`: the Allan deviation of the mode-1 phase output in degrees
/// (what the board reads), and of the rate-equivalent output in deg/h (the same curve over the
/// scale factor, the unit of the readings), with the angle random walk's -1/2 line when it was
/// read and the noise-model fit over the taus it was fitted on.
pub fn allan_panels(a: &AllanResult) -> [Figure; 2] {
    let phase = Figure::new(
        "Phase output, mode 1",
        "tau (s)",
        "Allan deviation of the phase (deg)",
    )
    .log_x()
    .log_y()
    .with(log_series(
        "phase output (deg)",
        SeriesStyle::Points,
        &a.phase_deg,
        1.0,
    ));
    let mut rate = Figure::new(
        format!(
            "Rate-equivalent output: phase / {:.6} deg per deg/s",
            a.scale_deg_per_dps
        ),
        "tau (s)",
        "Allan deviation (deg/h)",
    )
    .log_x()
    .log_y()
    .with(log_series(
        "rate-equivalent output (phase / scale factor)",
        SeriesStyle::Points,
        &a.rate_dps,
        3600.0,
    ));
    if let Some(r) = a.readings.filter(|r| r.arw_deg_per_rt_h.is_finite()) {
        // The -1/2 line of the ARW reading: sigma = N / sqrt(tau), N = ARW / 60 deg/s*sqrt(s).
        let n = r.arw_deg_per_rt_h / 60.0;
        let ends: Vec<f64> = [a.rate_dps[0].tau_s, a.rate_dps[a.rate_dps.len() - 1].tau_s].into();
        rate = rate.with(Series::new(
            "angle random walk: N / sqrt(tau)",
            SeriesStyle::DashedLine,
            ends.clone(),
            ends.iter().map(|t| n / t.sqrt() * 3600.0).collect(),
        ));
    }
    if let Some(f) = a
        .readings
        .map(|r| r.model_fit)
        .filter(|f| f.warning.is_none())
    {
        // 64 points per decade: a smooth curve on the log axes.
        let decades = (f.tau_max_s / f.tau_min_s).log10();
        let k = (64.0 * decades).ceil().max(1.0) as usize;
        let taus: Vec<f64> = (0..=k)
            .map(|i| f.tau_min_s * 10f64.powf(decades * i as f64 / k as f64))
            .collect();
        rate = rate.with(Series::new(
            fit_label(&f),
            SeriesStyle::Line,
            taus.clone(),
            taus.iter().map(|&t| f.adev_dps(t) * 3600.0).collect(),
        ));
    }
    [phase, rate]
}

fn tau_table(t: &[TauPoint]) -> CsvTable {
    let rows = t
        .iter()
        .map(|p| {
            vec![
                p.tau_s,
                p.averaged_s,
                p.predicted_deg_per_dps,
                p.relative_error,
                p.relative_error_ci95,
                p.relative_error_vs_theory,
                p.combined_predicted_deg_per_dps,
                p.combined_relative_error,
                p.combined_relative_error_ci95,
            ]
        })
        .collect();
    table(
        &[
            "tau_s",
            "averaged_s",
            "predicted_deg_per_dps",
            "relative_error",
            "relative_error_ci95",
            "relative_error_vs_theory",
            "combined_predicted_deg_per_dps",
            "combined_relative_error",
            "combined_relative_error_ci95",
        ],
        rows,
    )
}

fn tau_figure(t: &[TauPoint], average_s: f64) -> Figure {
    let lg = |v: f64| v.abs().max(1e-12);
    let mut fig = Figure::new(
        "Self-calibration error against averaging time",
        "Averaging time (s)",
        "|relative error|",
    )
    .log_x()
    .log_y()
    .with(Series::new(
        "|predicted / rate table - 1|, mode 1",
        SeriesStyle::Points,
        t.iter().map(|p| p.tau_s).collect(),
        t.iter().map(|p| lg(p.relative_error)).collect(),
    ))
    .with(Series::new(
        "the same, both modes combined",
        SeriesStyle::Points,
        t.iter().map(|p| p.tau_s).collect(),
        t.iter().map(|p| lg(p.combined_relative_error)).collect(),
    ))
    .with(Series::new(
        "95 % confidence half-width, mode 1",
        SeriesStyle::DashedLine,
        t.iter().map(|p| p.tau_s).collect(),
        t.iter().map(|p| lg(p.relative_error_ci95)).collect(),
    ))
    .with(Series::new(
        "95 % confidence half-width, both modes",
        SeriesStyle::DashedLine,
        t.iter().map(|p| p.tau_s).collect(),
        t.iter()
            .map(|p| lg(p.combined_relative_error_ci95))
            .collect(),
    ));
    // Ringed on both series: the legend may cover the mode-1 row, which sits at the top.
    for (name, at) in [("500 s (the paper)", 500.0), ("this config", average_s)] {
        if let Some(p) = t.iter().find(|p| p.tau_s == at) {
            fig = fig.with(Series::new(
                name,
                SeriesStyle::OpenPoints,
                vec![p.tau_s; 2],
                vec![lg(p.relative_error), lg(p.combined_relative_error)],
            ));
        }
    }
    fig
}

fn drift_table(d: &[DriftPoint]) -> CsvTable {
    let case = |c: Option<&DriftCase>| {
        c.map_or([f64::NAN; 8], |c| {
            [
                c.carrier_hz,
                c.measured_deg_per_dps,
                c.selfcal_deg_per_dps,
                c.selfcal_relative_error,
                c.selfcal_relative_error_ci95,
                c.stale_relative_error,
                c.combined_selfcal_relative_error,
                c.combined_selfcal_relative_error_ci95,
            ]
        })
    };
    let rows = d
        .iter()
        .map(|p| {
            let mut r = vec![p.delta_t_k, p.f0_hz, p.q];
            r.extend(case(Some(&p.open_loop)));
            r.extend(case(p.pll.as_ref()));
            r.push(p.pll_lock_time_s.unwrap_or(f64::NAN));
            r
        })
        .collect();
    table(
        &[
            "delta_t_k",
            "f0_hz",
            "q",
            "open_loop_carrier_hz",
            "open_loop_measured_deg_per_dps",
            "open_loop_selfcal_deg_per_dps",
            "open_loop_selfcal_relative_error",
            "open_loop_selfcal_relative_error_ci95",
            "open_loop_stale_relative_error",
            "open_loop_combined_selfcal_relative_error",
            "open_loop_combined_selfcal_relative_error_ci95",
            "pll_carrier_hz",
            "pll_measured_deg_per_dps",
            "pll_selfcal_deg_per_dps",
            "pll_selfcal_relative_error",
            "pll_selfcal_relative_error_ci95",
            "pll_stale_relative_error",
            "pll_combined_selfcal_relative_error",
            "pll_combined_selfcal_relative_error_ci95",
            "pll_lock_time_s",
        ],
        rows,
    )
}

/// The drift scenario in two panels: the self-calibration errors (small, so not under the
/// open-loop stale error's hundreds of percent), and the calibration kept from the nominal
/// temperature.
fn drift_figures(d: &[DriftPoint]) -> [Figure; 2] {
    let xs: Vec<f64> = d.iter().map(|p| p.delta_t_k).collect();
    let pct = |v: f64| 100.0 * v;
    let series = |name: &str, style: SeriesStyle, f: &dyn Fn(&DriftPoint) -> Option<f64>| {
        let (x, y): (Vec<f64>, Vec<f64>) = xs
            .iter()
            .zip(d)
            .filter_map(|(&x, p)| f(p).map(|y| (x, y)))
            .unzip();
        Series::new(name, style, x, y)
    };
    let selfcal = Figure::new(
        "Self-calibrated at each temperature",
        "Temperature offset (K)",
        "Scale-factor error against the rate table (%)",
    )
    .with(series(
        "PLL-tracked carrier, mode 1",
        SeriesStyle::Points,
        &|p| p.pll.as_ref().map(|c| pct(c.selfcal_relative_error)),
    ))
    .with(series(
        "PLL-tracked carrier, both modes combined",
        SeriesStyle::Points,
        &|p| {
            p.pll
                .as_ref()
                .map(|c| pct(c.combined_selfcal_relative_error))
        },
    ))
    .with(series(
        "open loop at the nominal carrier, mode 1",
        SeriesStyle::OpenPoints,
        &|p| Some(pct(p.open_loop.selfcal_relative_error)),
    ));
    let stale = Figure::new(
        "Calibrated once, at the nominal temperature",
        "Temperature offset (K)",
        "Scale-factor error against the rate table (%)",
    )
    .with(series("PLL-tracked carrier", SeriesStyle::Points, &|p| {
        p.pll.as_ref().map(|c| pct(c.stale_relative_error))
    }))
    .with(series(
        "open loop at the nominal carrier",
        SeriesStyle::OpenPoints,
        &|p| Some(pct(p.open_loop.stale_relative_error)),
    ));
    [selfcal, stale]
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_analysis::selfcal::run_selfcal_core;
    use gyroemu_config::presets::preset;

    fn quiet(_: u64, _: u64) {}

    #[test]
    fn each_csv_row_holds_one_rate_from_both_sweeps_when_rate_0_is_listed() {
        // The rotating sweep leaves rate 0 out; the rows had paired each rotating point with
        // the rate-table point before it and lost the last one.
        let mut c = preset("m2tfg-rotating").unwrap();
        c.experiment.rates_dps = vec![0.0, 50.0, 100.0, 175.0];
        c.experiment.average_s = 3.6;
        c.experiment.settle_s = Some(0.8);
        let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
        assert_eq!(core.rotating.points.len(), 3);
        let t = points_table(&core);
        assert_eq!(t.rows.len(), 4);
        let num = |cell: &CsvCell| match cell {
            CsvCell::F64(v) => *v,
            other => panic!("{other:?}"),
        };
        for (row, c) in t.rows.iter().zip(&core.coriolis.points) {
            let rate = num(&row[0]);
            assert_eq!(rate, c.rate_dps);
            assert_eq!(num(&row[5]).to_bits(), c.phase_deg[0].to_bits());
            match core.rotating.points.iter().find(|r| r.rate_dps == rate) {
                Some(r) => assert_eq!(num(&row[1]).to_bits(), r.phase_deg[0].to_bits()),
                None => assert!(rate == 0.0 && num(&row[1]).is_nan()),
            }
        }
        // The rotating psi grows with the rate it was read at (about 2 Q Omega / w0).
        let psi: Vec<f64> = t.rows[1..].iter().map(|r| num(&r[1])).collect();
        assert!(psi.windows(2).all(|w| w[1] > w[0]), "{psi:?}");
    }
}
