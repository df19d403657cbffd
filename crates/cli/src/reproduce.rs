//! `gyroemu reproduce`: the paper's Figs. 4, 5, 6, 8 and 9 from the emulated board, on the
//! embedded presets, with the exact theory beside every point.

use crate::commands::{check_config, prepare_out};
use crate::progress::Progress;
use crate::report::{sweep_figure, theory_series, write_run};
use anyhow::{Context, Result};
use gyroemu_experiment::presets::preset;
use gyroemu_experiment::{run_sweep, Config, SweepResult};
use gyroemu_io::write_json;
use gyroemu_plot::{render_png, Figure, Series, SeriesStyle};
use serde_json::json;
use std::path::Path;

/// Averaging of Fig. 9 with `--quick`, s (the paper: 500 s).
const QUICK_AVERAGE_S: f64 = 15.0;

struct Job {
    preset: &'static str,
    title: &'static str,
    cfg: Config,
}

/// Runs every figure's experiment and writes the figures and summaries into `out`.
pub fn reproduce(out: &Path, quick: bool) -> Result<()> {
    let specs = [
        (
            "m2tfg-coriolis",
            "Fig. 8: Coriolis phase shift, M^2-TFG-like gyroscope (Q = 2000)",
        ),
        (
            "m2tfg-rotating",
            "Fig. 9: rotating excitation, M^2-TFG-like gyroscope",
        ),
        (
            "baw-coriolis",
            "Fig. 4: Coriolis phase shift, BAW disk (n = 3, lambda = 0.6)",
        ),
        ("baw-rotating", "Fig. 5: rotating excitation, BAW disk"),
        (
            "m2tfg-ratetable",
            "Sinusoidal rate table at Q = 36 000: the mechanical bandwidth",
        ),
    ];
    // Validate everything before the first sample.
    let mut jobs = Vec::new();
    for (name, title) in specs {
        let mut cfg = preset(name).with_context(|| format!("preset {name}"))?;
        if quick && name == "m2tfg-rotating" {
            cfg.experiment.average_s = QUICK_AVERAGE_S;
        }
        check_config(&cfg, name)?;
        jobs.push(Job {
            preset: name,
            title,
            cfg,
        });
    }
    prepare_out(out)?;
    let mut results = Vec::new();
    for job in &jobs {
        let progress = Progress::new(job.preset);
        let r = run_sweep(&job.cfg, &|d, t| progress.update(d, t), None)
            .with_context(|| format!("emulating {}", job.preset))?;
        progress.finish(r.point_samples);
        write_run(&out.join(job.preset), &job.cfg, &r, job.title)?;
        results.push(r);
    }
    let get = |name: &str| {
        let i = jobs.iter().position(|j| j.preset == name).unwrap_or(0);
        (&jobs[i].cfg, &results[i], jobs[i].title)
    };
    for (fig, name) in [
        ("fig8", "m2tfg-coriolis"),
        ("fig9", "m2tfg-rotating"),
        ("fig4", "baw-coriolis"),
        ("fig5", "baw-rotating"),
        ("fig_ratetable", "m2tfg-ratetable"),
    ] {
        let (cfg, r, title) = get(name);
        let mut f = sweep_figure(cfg, r, title);
        if let Some(paper) = paper_i_series(r) {
            f = f.with(paper);
        }
        render_png(&f, &out.join(format!("{fig}.png")))?;
    }
    let (rt_cfg, _, _) = get("m2tfg-ratetable");
    render_png(&bandwidth(rt_cfg, out)?, &out.join("fig_bandwidth.png"))?;
    let (cc, cr, _) = get("baw-coriolis");
    let (_, rr, _) = get("baw-rotating");
    render_png(&fig6(cc, cr, rr), &out.join("fig6.png"))?;
    let pair = |c: &str, rname: &str| {
        let (cfg, rc, _) = get(c);
        let (_, rrot, _) = get(rname);
        let lambda = cfg.device.angular_gain;
        let ratio = rc.fit[0].slope / rrot.fit[0].slope;
        json!({
            "coriolis_slope_deg_per_dps": rc.fit[0].slope,
            "rotating_slope_deg_per_dps": rrot.fit[0].slope,
            "slope_ratio": ratio,
            "angular_gain": lambda,
            "ratio_relative_error": ratio / lambda - 1.0,
        })
    };
    let max_err = |r: &SweepResult| r.max_abs_error_mdeg(0).max(r.max_abs_error_mdeg(1));
    let summary = json!({
        "fig8_fig9": pair("m2tfg-coriolis", "m2tfg-rotating"),
        "fig4_fig5": pair("baw-coriolis", "baw-rotating"),
        "max_abs_error_mdeg": {
            "fig8": max_err(get("m2tfg-coriolis").1),
            "fig9": max_err(get("m2tfg-rotating").1),
            "fig4": max_err(get("baw-coriolis").1),
            "fig5": max_err(get("baw-rotating").1),
        },
        "fig9_average_s": get("m2tfg-rotating").0.experiment.average_s,
        "quick": quick,
    });
    write_json(&out.join("summary.json"), &summary)?;
    eprintln!(
        "wrote {0}/fig4.png fig5.png fig6.png fig8.png fig9.png fig_ratetable.png fig_bandwidth.png summary.json and one folder per experiment",
        out.display()
    );
    Ok(())
}

/// Rate-table frequencies of the bandwidth figure, Hz (the corner is f0/(2Q) = 0.21 Hz).
const BANDWIDTH_FREQS_HZ: [f64; 9] = [0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0];
/// Rate-table amplitude of the bandwidth figure, deg/s (small: the first-order model is linear).
const BANDWIDTH_AMPLITUDE_DPS: f64 = 5.0;

/// What the mechanical bandwidth does to a rate-table measurement: the phase amplitude per
/// unit rate against the table frequency, emulated, beside the first-order low-pass of
/// THEORY.md section 3 (DC gain 2 Q lambda / w0, corner f0/(2Q)). Writes `bandwidth.csv`.
fn bandwidth(base: &Config, out: &Path) -> Result<Figure> {
    use gyroemu_experiment::theory::rate_table_gain;
    use gyroemu_io::{write_csv, CsvCell, CsvTable};
    use rayon::prelude::*;
    let d = &base.device;
    let runs: Vec<(f64, SweepResult)> = BANDWIDTH_FREQS_HZ
        .par_iter()
        .map(|&f| {
            let mut cfg = base.clone();
            cfg.experiment.table_freq_hz = Some(f);
            cfg.experiment.rates_dps = vec![BANDWIDTH_AMPLITUDE_DPS];
            cfg.experiment.average_s = (2.0 / f).max(4.0);
            check_config(&cfg, "bandwidth")?;
            Ok((f, run_sweep(&cfg, &|_, _| {}, None)?))
        })
        .collect::<Result<_>>()?;
    let gain = |r: &SweepResult, k: usize| r.points[0].phase_deg[k] / BANDWIDTH_AMPLITUDE_DPS;
    let theory = |f: f64| rate_table_gain(d.f0_hz, d.q, d.angular_gain, 1.0, 1.0, f);
    let mut rows = Vec::new();
    for (f, r) in &runs {
        let lag = r.points[0].table_lag_deg.unwrap_or([f64::NAN; 2]);
        let (g, ph) = theory(*f);
        rows.push(
            [
                *f,
                gain(r, 0),
                gain(r, 1),
                g,
                lag[0],
                lag[1],
                ph.to_degrees(),
            ]
            .map(CsvCell::F64)
            .to_vec(),
        );
    }
    let headers = [
        "table_freq_hz",
        "gain_mode1_deg_per_dps",
        "gain_mode2_deg_per_dps",
        "theory_gain_deg_per_dps",
        "lag_mode1_deg",
        "lag_mode2_deg",
        "theory_lag_deg",
    ];
    let dir = out.join("m2tfg-ratetable");
    std::fs::create_dir_all(&dir)?;
    write_csv(
        &dir.join("bandwidth.csv"),
        &CsvTable {
            headers: headers.map(String::from).to_vec(),
            rows,
        },
    )?;
    let fmax = BANDWIDTH_FREQS_HZ[BANDWIDTH_FREQS_HZ.len() - 1];
    let fs: Vec<f64> = (0..=200)
        .map(|i| 0.01 + (fmax - 0.01) * i as f64 / 200.0)
        .collect();
    let corner = d.f0_hz / (2.0 * d.q);
    Ok(Figure::new(
        format!(
            "Mechanical bandwidth: rate table at Q = {}, corner f0/(2Q) = {corner:.3} Hz",
            d.q
        ),
        "Rate-table frequency (Hz)",
        "Phase amplitude per unit rate (deg per deg/s)",
    )
    .with(Series {
        name: format!("mode 1 emulated ({BANDWIDTH_AMPLITUDE_DPS} deg/s amplitude)"),
        style: SeriesStyle::Points,
        xs: runs.iter().map(|r| r.0).collect(),
        ys: runs.iter().map(|r| gain(&r.1, 0)).collect(),
    })
    .with(Series {
        name: "mode 2 emulated".into(),
        style: SeriesStyle::OpenPoints,
        xs: runs.iter().map(|r| r.0).collect(),
        ys: runs.iter().map(|r| gain(&r.1, 1)).collect(),
    })
    .with(Series {
        name: "first-order low-pass: (2 Q lambda / w0) / sqrt(1 + (2 pi f tau)^2)".into(),
        style: SeriesStyle::Line,
        ys: fs.iter().map(|&f| theory(f).0).collect(),
        xs: fs,
    }))
}

/// The paper-style real-I-channel estimate of mode 1, for the rotating figures.
fn paper_i_series(r: &SweepResult) -> Option<Series> {
    let ys: Option<Vec<f64>> = r
        .points
        .iter()
        .map(|p| p.paper_i_deg.map(|v| v[0]))
        .collect();
    Some(Series {
        name: "mode 1, paper-style I-channel estimate".into(),
        style: SeriesStyle::Points,
        xs: r.points.iter().map(|p| p.rate_dps).collect(),
        ys: ys?,
    })
}

/// Fig. 6: the Coriolis phase against the rotation rate, and the rotating-excitation phase
/// against the excitation rate divided by lambda: the two coincide.
fn fig6(cfg: &Config, cor: &SweepResult, rot: &SweepResult) -> Figure {
    let lambda = cfg.device.angular_gain;
    let x_max = cor.points.iter().map(|p| p.rate_dps).fold(0.0, f64::max);
    Figure::new(
        "Fig. 6: Coriolis and rotating excitation coincide (excitation axis / lambda)",
        "Rotation rate, or excitation rate / lambda (deg/s)",
        "Phase (deg)",
    )
    .with(Series {
        name: "Coriolis, mode 1".into(),
        style: SeriesStyle::Points,
        xs: cor.points.iter().map(|p| p.rate_dps).collect(),
        ys: cor.points.iter().map(|p| p.phase_deg[0]).collect(),
    })
    .with(Series {
        name: format!("rotating excitation, mode 1 (Omega / {lambda})"),
        style: SeriesStyle::OpenPoints,
        xs: rot.points.iter().map(|p| p.rate_dps / lambda).collect(),
        ys: rot.points.iter().map(|p| p.phase_deg[0]).collect(),
    })
    .with(theory_series(cfg, x_max, 0, 1.0, "exact theory (eq. 3)"))
}
