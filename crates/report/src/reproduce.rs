//! `gyroemu reproduce`: the paper's Figs. 4, 5, 6, 8 and 9 from the emulated board, on the
//! embedded presets, with the exact theory beside every point.

use crate::dump_figures::write_dump_figures;
use crate::dump_set::read_dump_set;
use crate::error::{check_problems, create_dir, ReportError};
use crate::sweep_report::{
    fit_series, line_span, phases, sweep_figure, theory_abscissae, theory_series, write_run_with,
};
use gyroemu_analysis::bandwidth::{
    bandwidth_configs, bandwidth_points, BandwidthPoint, BANDWIDTH_AMPLITUDE_DPS,
    BANDWIDTH_FREQS_HZ,
};
use gyroemu_config::presets::preset;
use gyroemu_config::{Config, DumpConfig};
use gyroemu_experiment::fit::LineFit;
use gyroemu_experiment::mutex::lock;
use gyroemu_experiment::prepared::PreparedSweep;
use gyroemu_experiment::queue::{run_longest_first, sweep_items, table_items, Item};
use gyroemu_experiment::table_sweep::{tables_work, PreparedTables};
use gyroemu_experiment::{
    finish_sweep_with, DumpPlan, Reporter, Stage2Leaks, SweepOptions, SweepResult, SweepRun,
    DUMP_STEM,
};
use gyroemu_io::{write_csv, write_json, CsvCell, CsvTable};
use gyroemu_plot::{
    render_png, render_rgb_antialiased, write_rgb_png, Figure, Series, SeriesStyle,
};
use gyroemu_theory::rate_table_gain;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};

/// Averaging of Fig. 9 with `--quick`, s (the paper: 500 s).
const QUICK_AVERAGE_S: f64 = 15.0;

/// Most full-rate frames of the dump each experiment writes (12 channels: about 0.8 MB in
/// all formats; 128 carrier periods at 16 samples per period, Welch bins of fs/512).
pub const DUMP_FULL_FRAMES: f64 = 2048.0;
/// Most decimated frames of that dump (14 channels: about 0.5 MB).
pub const DUMP_DECIMATED_FRAMES: f64 = 1024.0;

/// The dump `reproduce` records of an experiment: every node at the largest rate from the end
/// of settling (the `[dump]` defaults), the full-rate window cut to [`DUMP_FULL_FRAMES`], the
/// decimated one [`DUMP_DECIMATED_FRAMES`] long, both within the point's run.
pub fn reproduce_dump(cfg: &Config) -> DumpPlan {
    let mut with_dump = cfg.clone();
    with_dump.dump = Some(DumpConfig {
        rate_dps: None,
        start_s: None,
        duration_s: None,
        nodes: None,
    });
    let d = DumpPlan::from_config(&with_dump).expect("the config has a dump section now");
    let p = cfg.plan_point(d.rate_dps);
    let end_s = (cfg.n_settle_out() + p.window.samples()) as f64 / cfg.fs_out_hz();
    DumpPlan {
        duration_s: d.duration_s.min(DUMP_FULL_FRAMES / cfg.fs_hz()),
        decimated_duration_s: (DUMP_DECIMATED_FRAMES / cfg.fs_out_hz()).min(end_s - d.start_s),
        ..d
    }
}

/// What an experiment's read-out gives: its run, its result and its files (when it has no
/// problems), its figure among them.
type JobOutput = (
    SweepRun,
    SweepResult,
    Option<Result<(Vec<PathBuf>, Option<PathBuf>), ReportError>>,
);

/// A figure drawn in memory: its description (for its size) and its RGB pixels.
type DrawnFigure = (Figure, Vec<u8>);

/// What the bandwidth sweep's read-out gives: its point-samples, its table and its figure.
type BandwidthOutput = (u64, [PathBuf; 2]);

/// What a queue's item left in `m` (every item has run once the queue returns).
fn taken<T>(m: &Mutex<Option<T>>) -> T {
    lock(m).take().expect("every item ran")
}

/// The relative cost of a sample of `cfg`'s chain, for ordering the lane groups: a rate table
/// steps its time-varying plant, about a third dearer than a constant-rate one.
fn chain_cost(cfg: &Config) -> f64 {
    match cfg.board_params().shape {
        gyroemu_board::Shape::RateTable { .. } => 1.35,
        _ => 1.0,
    }
}

/// The work of an experiment of `reproduce`: its sweep split as it runs, with its dump.
fn job_work(cfg: &Config) -> gyroemu_experiment::Work {
    let d = reproduce_dump(cfg);
    let dump_end_s = d.start_s + d.duration_s.max(d.decimated_duration_s);
    gyroemu_experiment::work::split_work(cfg, Some(dump_end_s))
}

struct Job {
    preset: &'static str,
    title: &'static str,
    cfg: Config,
    /// The config's validation warnings (the plan's, for its `summary.json`).
    warnings: Vec<String>,
}

/// What `reproduce` checked before running: every experiment's config, validated.
pub struct ReproducePlan {
    jobs: Vec<Job>,
    /// The bandwidth sweep's configs (one per table frequency), validated.
    bandwidth: Vec<Config>,
    quick: bool,
    /// The configs' warnings, each prefixed with its preset.
    pub warnings: Vec<String>,
}

impl ReproducePlan {
    /// The emulation the figures' sweeps and the bandwidth sweep will run (its points as
    /// each would run alone: the work the results report; its longest lane as its long
    /// points' segments run).
    pub fn work(&self) -> gyroemu_experiment::Work {
        let bandwidth = tables_work(&self.bandwidth, true).unwrap_or_else(|_| {
            // Validated rate-table configs plan without error; were one not, its points
            // would count as they run whole.
            let each = self.bandwidth.iter().map(gyroemu_experiment::sweep_work);
            each.reduce(|a, b| a.plus(b)).unwrap_or_default()
        });
        self.jobs
            .iter()
            .map(|j| job_work(&j.cfg))
            .chain([bandwidth])
            .reduce(|a, b| a.plus(b))
            .expect("reproduce has jobs")
    }

    /// The folders, below the output folder, that each preset's files go into.
    pub fn preset_folders(&self) -> Vec<&'static str> {
        self.jobs.iter().map(|j| j.preset).collect()
    }

    /// The config of the experiment with the most point-samples (to measure the chain's
    /// throughput on: its chain sets most of the run's time; Fig. 9's rotating one).
    pub fn heaviest_config(&self) -> &Config {
        &self
            .jobs
            .iter()
            .max_by_key(|j| job_work(&j.cfg).point_samples)
            .expect("reproduce has jobs")
            .cfg
    }
}

/// The presets of the figures (with `quick`, Fig. 9 averages 15 s instead of 500 s), each
/// validated before any sample is computed.
pub fn plan_reproduce(quick: bool) -> Result<ReproducePlan, ReportError> {
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
    let mut jobs = Vec::new();
    for (name, title) in specs {
        let mut cfg = preset(name)?;
        if quick && name == "m2tfg-rotating" {
            cfg.experiment.average_s = QUICK_AVERAGE_S;
        }
        jobs.push(Job {
            preset: name,
            title,
            cfg,
            warnings: Vec::new(),
        });
    }
    // Every config validated in parallel before the first sample (the rate-table rules alone
    // kept one core busy for tens of milliseconds while the other waited); the first error
    // and the warnings in the order of a sequential validation.
    let rt_cfg = &jobs[job_index(&jobs, "m2tfg-ratetable")].cfg;
    let (checked, bandwidth) = rayon::join(
        || {
            use rayon::prelude::*;
            jobs.par_iter()
                .map(|j| j.cfg.validate())
                .collect::<Vec<_>>()
        },
        || bandwidth_configs(rt_cfg),
    );
    let mut warnings = Vec::new();
    for (job, found) in jobs.iter_mut().zip(checked) {
        job.warnings = found?;
        let name = job.preset;
        warnings.extend(job.warnings.iter().map(|w| format!("{name}: {w}")));
    }
    let bandwidth = bandwidth?;
    Ok(ReproducePlan {
        jobs,
        bandwidth,
        quick,
        warnings,
    })
}

/// Runs every figure's experiment of `plan` and writes the figures and summaries into `out`
/// (which must exist); returns the files written.
///
/// Every lane group of every experiment and of the bandwidth sweep runs from one queue, the
/// costliest first (one experiment alone often has fewer lane groups than the machine has
/// cores; Fig. 9's long points are split so that none bounds the run), reported as one task;
/// each experiment's files and figure are written as soon as its last group has run. The
/// files and their order are those of a sequential run.
pub fn reproduce(
    plan: &ReproducePlan,
    out: &Path,
    reporter: &dyn Reporter,
) -> Result<Vec<PathBuf>, ReportError> {
    let (jobs, quick) = (&plan.jobs, plan.quick);
    for job in jobs {
        create_dir(&out.join(job.preset))?;
    }
    let task = reporter.task("reproduce");
    // Each experiment's (done, total) input samples; the task sees their sums.
    let slots: Vec<[AtomicU64; 2]> = jobs.iter().map(|_| Default::default()).collect();
    let report = |i: usize, d: u64, t: u64| {
        slots[i][0].store(d, Ordering::Relaxed);
        slots[i][1].store(t, Ordering::Relaxed);
        let sum = |k: usize| slots.iter().map(|s| s[k].load(Ordering::Relaxed)).sum();
        task.update(sum(0), sum(1));
    };
    let rt_cfg = &jobs[job_index(jobs, "m2tfg-ratetable")].cfg;
    let dirs: Vec<PathBuf> = jobs.iter().map(|j| out.join(j.preset)).collect();
    // The dump and its figures as soon as its window is recorded, by the group that recorded
    // it: the last experiment's would otherwise be drawn at the end of the run.
    let dump_figures: Vec<_> = dirs
        .iter()
        .map(|dir| {
            move |_: &[PathBuf]| -> Result<Vec<PathBuf>, String> {
                let set = read_dump_set(&dir.join(DUMP_STEM)).map_err(|e| e.to_string())?;
                write_dump_figures(&set, dir).map_err(|e| e.to_string())
            }
        })
        .collect();
    let progress: Vec<_> = (0..jobs.len())
        .map(|i| move |d: u64, t: u64| report(i, d, t))
        .collect();
    // Every board of every experiment built before the first sample, the experiments on every
    // thread at once (built one after another they kept the other thread waiting); the first
    // error in the experiments' order.
    let prepare = |i: usize| {
        let job = &jobs[i];
        // The dump only records: the results are those of a run without it. Groups sized
        // for one thread and long points split into segments (Fig. 9's 500 s): every group
        // is as wide as the CPU runs and none is long enough to run alone at the end (bits
        // do not depend on either).
        let opts = SweepOptions {
            dump: Some(reproduce_dump(&job.cfg)),
            group_threads: Some(1),
            on_dump_early: Some(&dump_figures[i]),
            split: true,
            ..Default::default()
        };
        PreparedSweep::new(&job.cfg, &progress[i], Some(&dirs[i]), opts)
    };
    let (prepared, tables) = rayon::join(
        || {
            use rayon::prelude::*;
            (0..jobs.len())
                .into_par_iter()
                .map(prepare)
                .collect::<Vec<_>>()
        },
        || PreparedTables::new(&plan.bandwidth, Some(1), true),
    );
    let mut sweeps = Vec::with_capacity(jobs.len());
    for sweep in prepared {
        sweeps.push(sweep?);
    }
    let tables = tables?;
    // Every lane group of every experiment and of the bandwidth sweep runs from one queue,
    // the costliest first. The stage-2 leaks depend on the configs alone: items beside the
    // groups compute them, or the read-out that needs them first (an error resurfaces in the
    // read-out).
    let leaks: Vec<OnceLock<Stage2Leaks>> = jobs.iter().map(|_| OnceLock::new()).collect();
    let leaks_of =
        |i: usize| leaks[i].get_or_init(|| Stage2Leaks::of_sweep(&jobs[i].cfg).unwrap_or_default());
    // Each experiment's read-out and files as soon as its last group has run, on that thread,
    // while the other experiments' groups go on; the bandwidth sweep's likewise.
    let outputs: Vec<Mutex<Option<Result<JobOutput, ReportError>>>> =
        jobs.iter().map(|_| Mutex::new(None)).collect();
    // Fig. 6 drawn (in memory) as soon as both BAW experiments are read out, beside the
    // second one's files (a thread with nothing left to run takes either), while other items
    // still run: drawn at the end it kept one thread alone while the other waited. It is
    // written at the end, once every experiment has passed its checks, as before.
    let (baw_c, baw_r) = (
        job_index(jobs, "baw-coriolis"),
        job_index(jobs, "baw-rotating"),
    );
    let fig6_left = AtomicUsize::new(2);
    let fig6_in: [Mutex<Option<SweepResult>>; 2] = Default::default();
    let fig6_drawn: Mutex<Option<Result<DrawnFigure, ReportError>>> = Mutex::new(None);
    let fig6_hand_in = |i: usize, r: &SweepResult| {
        let k = match i {
            _ if i == baw_c => 0,
            _ if i == baw_r => 1,
            _ => return,
        };
        // Only from clean read-outs: otherwise the run stops at their problems first.
        if r.problems.is_empty() {
            *lock(&fig6_in[k]) = Some(r.clone());
        }
        if fig6_left.fetch_sub(1, Ordering::AcqRel) == 1 {
            let (c, rot) = (lock(&fig6_in[0]), lock(&fig6_in[1]));
            if let (Some(c), Some(rot)) = (&*c, &*rot) {
                let fig = fig6(&jobs[baw_c].cfg, c, rot);
                let drawn = render_rgb_antialiased(&fig)
                    .map(|rgb| (fig, rgb))
                    .map_err(ReportError::from);
                *lock(&fig6_drawn) = Some(drawn);
            }
        }
    };
    let finishers: Vec<_> = (0..jobs.len())
        .map(|i| {
            let (sweeps, outputs, fig6_hand_in) = (&sweeps, &outputs, &fig6_hand_in);
            move || {
                let job = &jobs[i];
                let res = (|| -> Result<JobOutput, ReportError> {
                    let run = sweeps[i].finish()?;
                    let r = finish_sweep_with(&job.cfg, &run.lanes, leaks_of(i))?;
                    let written = if r.problems.is_empty() {
                        let (w, ()) =
                            rayon::join(|| write_job(out, job, &run, &r), || fig6_hand_in(i, &r));
                        Some(w)
                    } else {
                        fig6_hand_in(i, &r);
                        None
                    };
                    Ok((run, r, written))
                })();
                *lock(&outputs[i]) = Some(res);
            }
        })
        .collect();
    // The bandwidth sweep's point-samples and files.
    let bandwidth_out: Mutex<Option<Result<BandwidthOutput, ReportError>>> = Mutex::new(None);
    let bandwidth_finish = || {
        let res = (|| -> Result<_, ReportError> {
            let results = tables.finish()?;
            let work = results.iter().map(|r| r.point_samples).sum::<u64>();
            let runs = bandwidth_points(rt_cfg, &results);
            let (figure, csv) = bandwidth_outputs(rt_cfg, &runs, out)?;
            let path = out.join("fig_bandwidth.png");
            render_png(&figure, &path)?;
            // The bandwidth sweep's table goes before its figure.
            Ok((work, [csv, path]))
        })();
        *lock(&bandwidth_out) = Some(res);
    };
    let mut items = Vec::new();
    for (i, (job, sweep)) in jobs.iter().zip(&sweeps).enumerate() {
        let then: &(dyn Fn() + Sync) = &finishers[i];
        items.extend(sweep_items(sweep, chain_cost(&job.cfg), Some(then)));
    }
    items.extend(table_items(
        &tables,
        chain_cost(rt_cfg),
        Some(&bandwidth_finish),
    ));
    for i in 0..jobs.len() {
        let item: Item = Box::new(move || {
            leaks_of(i);
        });
        items.push((0.0, item));
    }
    run_longest_first(items);
    let swept: Vec<Result<JobOutput, ReportError>> = outputs.iter().map(taken).collect();
    let bandwidth_files = taken(&bandwidth_out);
    let mut runs = Vec::with_capacity(jobs.len());
    for s in swept {
        runs.push(s?);
    }
    let bandwidth_files = bandwidth_files?;
    // The work of every point: the figures' sweeps' and the bandwidth sweep's (each point as
    // it would run alone; Fig. 9's split points run 1 % more, their segments' settling).
    let (bandwidth_work, bandwidth_files) = bandwidth_files;
    let point_samples: u64 =
        runs.iter().map(|(_, r, _)| r.point_samples).sum::<u64>() + bandwidth_work;
    let written = runs.iter().map(|(run, _, _)| run.written()).fold(
        Default::default(),
        |a: gyroemu_experiment::Written, w| gyroemu_experiment::Written {
            files: a.files + w.files,
            bytes: a.bytes + w.bytes,
            seconds: a.seconds + w.seconds,
        },
    );
    task.finish_writing(Some(point_samples), written);
    for (job, (run, r, _)) in jobs.iter().zip(&runs) {
        // The run's warnings, then why a dump recording has no WAV (as `run` says it).
        for w in r.warnings.iter().chain(&run.dump_notes) {
            reporter.warn(&format!("{}: {w}", job.preset));
        }
        check_problems(job.preset, &r.problems)?;
    }
    // In the order of a sequential run: each experiment's files, then the figures.
    let mut files = Vec::new();
    let mut job_figures = Vec::new();
    let mut results: Vec<SweepResult> = Vec::with_capacity(jobs.len());
    for (_, r, w) in runs {
        // Every experiment passed `check_problems`, so each wrote its outputs.
        if let Some(w) = w {
            let (f, fig) = w?;
            files.extend(f);
            job_figures.extend(fig);
        }
        results.push(r);
    }
    let get = |name: &str| {
        let i = job_index(jobs, name);
        (&jobs[i].cfg, &results[i], jobs[i].title)
    };
    for fig in ["fig8", "fig9", "fig4", "fig5", "fig_ratetable"] {
        if let Some(p) = job_figures
            .iter()
            .find(|p| p.ends_with(format!("{fig}.png")))
        {
            files.push(p.clone());
        }
    }
    files.extend(bandwidth_files);
    // Drawn in the queue (both read-outs passed their checks above, so it was), written now.
    let path = out.join("fig6.png");
    match lock(&fig6_drawn).take() {
        Some(drawn) => {
            let (fig, rgb) = drawn?;
            write_rgb_png(&path, fig.width_px, fig.height_px, &rgb)?;
        }
        None => {
            let ((cc, cr, _), (_, rr, _)) = (get("baw-coriolis"), get("baw-rotating"));
            render_png(&fig6(cc, cr, rr), &path)?;
        }
    }
    files.push(path);
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
    let path = out.join("summary.json");
    write_json(&path, &summary)?;
    files.push(path);
    Ok(files)
}

/// The outputs of the rate-table preset's bandwidth sweep: writes `m2tfg-ratetable/bandwidth.csv`
/// and returns its figure (the emulated gains against the first-order low-pass of THEORY.md
/// section 3) and the CSV's path.
fn bandwidth_outputs(
    base: &Config,
    runs: &[BandwidthPoint],
    out: &Path,
) -> Result<(Figure, PathBuf), ReportError> {
    let d = &base.device;
    let rows = runs
        .iter()
        .map(|p| {
            [
                p.table_freq_hz,
                p.gain_deg_per_dps[0],
                p.gain_deg_per_dps[1],
                p.theory_gain_deg_per_dps,
                p.lag_deg[0],
                p.lag_deg[1],
                p.theory_lag_deg,
            ]
            .map(CsvCell::F64)
            .to_vec()
        })
        .collect();
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
    create_dir(&dir)?;
    let csv = dir.join("bandwidth.csv");
    write_csv(
        &csv,
        &CsvTable {
            headers: headers.map(String::from).to_vec(),
            rows,
        },
    )?;
    let theory = |f: f64| rate_table_gain(d.f0_hz, d.q, d.angular_gain, 1.0, 1.0, f);
    let fmax = BANDWIDTH_FREQS_HZ[BANDWIDTH_FREQS_HZ.len() - 1];
    // Log-spaced: the figure's axes are logarithmic (a low-pass is a line in decades).
    let fs: Vec<f64> = (0..=200)
        .map(|i| 0.01 * (fmax / 0.01).powf(i as f64 / 200.0))
        .collect();
    let corner = d.f0_hz / (2.0 * d.q);
    let figure = Figure::new(
        format!(
            "Mechanical bandwidth: rate table at Q = {}, corner f0/(2Q) = {corner:.3} Hz",
            d.q
        ),
        "Rate-table frequency (Hz)",
        "Phase amplitude per unit rate (deg per deg/s)",
    )
    .log_x()
    .log_y()
    .with(Series {
        name: format!("mode 1 emulated ({BANDWIDTH_AMPLITUDE_DPS} deg/s amplitude)"),
        style: SeriesStyle::Points,
        xs: runs.iter().map(|r| r.table_freq_hz).collect(),
        ys: runs.iter().map(|r| r.gain_deg_per_dps[0]).collect(),
    })
    .with(Series {
        name: "mode 2 emulated".into(),
        style: SeriesStyle::OpenPoints,
        xs: runs.iter().map(|r| r.table_freq_hz).collect(),
        ys: runs.iter().map(|r| r.gain_deg_per_dps[1]).collect(),
    })
    .with(Series {
        name: "first-order low-pass: (2 Q lambda / w0) / sqrt(1 + (2 pi f tau)^2)".into(),
        style: SeriesStyle::Line,
        ys: fs.iter().map(|&f| theory(f).0).collect(),
        xs: fs,
    });
    Ok((figure, csv))
}

/// The figure `reproduce` draws of an experiment alone.
fn figure_name(preset: &str) -> Option<&'static str> {
    Some(match preset {
        "m2tfg-coriolis" => "fig8",
        "m2tfg-rotating" => "fig9",
        "baw-coriolis" => "fig4",
        "baw-rotating" => "fig5",
        "m2tfg-ratetable" => "fig_ratetable",
        _ => return None,
    })
}

/// An experiment's outputs: its results, and its dump and the dump's figures (written by the
/// sweep, in `run`) in its folder, and its own figure in `out`. Returns the files of its
/// folder, then its figure.
fn write_job(
    out: &Path,
    job: &Job,
    swept: &SweepRun,
    r: &SweepResult,
) -> Result<(Vec<PathBuf>, Option<PathBuf>), ReportError> {
    let dir = out.join(job.preset);
    // One figure for both files (its theory overlay is a harmonic balance per abscissa on a
    // rate table), and the plan's validation for the summary's warnings.
    let plot = sweep_figure(&job.cfg, r, job.title);
    let figure_path = figure_name(job.preset).map(|name| out.join(format!("{name}.png")));
    let write_run = |copies: &[&Path]| {
        write_run_with(&dir, &job.cfg, Ok(job.warnings.clone()), r, &plot, copies)
    };
    let (run, figure) = match (&figure_path, paper_i_series(r)) {
        // The figure is the run's own plot: drawn and encoded once, written under both names.
        (Some(path), None) => (write_run(&[path]), Ok(figure_path.clone())),
        // In parallel: the last experiment to finish has the pool to itself.
        (Some(path), Some(paper)) => rayon::join(
            || write_run(&[]),
            || -> Result<_, ReportError> {
                render_png(&plot.clone().with(paper), path)?;
                Ok(figure_path.clone())
            },
        ),
        (None, _) => (write_run(&[]), Ok(None)),
    };
    let mut files = run?;
    files.extend(swept.dump_files.iter().cloned());
    files.extend(swept.dump_made.iter().cloned());
    Ok((files, figure?))
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

/// The index of a preset's job (every plan has the five).
fn job_index(jobs: &[Job], name: &str) -> usize {
    jobs.iter().position(|j| j.preset == name).unwrap_or(0)
}

/// Fig. 6: the Coriolis phase against the rotation rate, and the rotating-excitation phase
/// against the excitation rate divided by lambda: the two coincide. Each series has its best
/// linear fit, drawn as in the sweep figures ([`fit_series`]): the rotating sweep's fit against
/// Omega, redrawn against Omega / lambda (slope times lambda; intercept and R^2 unchanged), so
/// its slope is the self-calibrated Coriolis slope beside the rate table's.
pub fn fig6(cfg: &Config, cor: &SweepResult, rot: &SweepResult) -> Figure {
    let lambda = cfg.device.angular_gain;
    let cor_x: Vec<f64> = cor.points.iter().map(|p| p.rate_dps).collect();
    let rot_x: Vec<f64> = rot.points.iter().map(|p| p.rate_dps / lambda).collect();
    let all_x: Vec<f64> = cor_x.iter().chain(&rot_x).copied().collect();
    let span = line_span(&all_x);
    let (cor_y, rot_y) = (phases(cor, 0), phases(rot, 0));
    let rot_fit = LineFit {
        slope: rot.fit[0].slope * lambda,
        slope_std_err: rot.fit[0].slope_std_err * lambda,
        ..rot.fit[0]
    };
    let fits = [
        fit_series("Coriolis mode 1", &cor.fit[0], &cor_x, &cor_y, span),
        fit_series("rotating mode 1", &rot_fit, &rot_x, &rot_y, span),
    ];
    let mut fig = Figure::new(
        "Fig. 6: Coriolis and rotating excitation coincide (excitation axis / lambda)",
        "Rotation rate, or excitation rate / lambda (deg/s)",
        "Phase (deg)",
    )
    .with(Series {
        name: "Coriolis, mode 1".into(),
        style: SeriesStyle::Points,
        xs: cor_x,
        ys: cor_y,
    })
    .with(Series {
        name: format!("rotating excitation, mode 1 (Omega / {lambda})"),
        style: SeriesStyle::OpenPoints,
        xs: rot_x,
        ys: rot_y,
    })
    .with(theory_series(
        cfg,
        &theory_abscissae(span.0, span.1, &all_x, 100),
        0,
        1.0,
        "exact theory (eq. 3)",
    ));
    for s in fits.into_iter().flatten() {
        fig = fig.with(s);
    }
    fig
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_full_plan_splits_fig9_and_counts_the_bandwidth_sweep() {
        let full = plan_reproduce(false).unwrap();
        let w = full.work();
        // The five presets' 37 points and the bandwidth sweep's 9.
        assert_eq!(w.points, 37 + 9);
        // Fig. 9's points are 500.6 s of signal (0.71 s of settling and up to 499.9 s of
        // averaging); split into eight segments, its longest lane runs 63.2 s.
        assert!((w.longest_s - 500.6).abs() < 0.05, "{}", w.longest_s);
        let rot = &full.jobs[job_index(&full.jobs, "m2tfg-rotating")].cfg;
        let whole = gyroemu_experiment::sweep_work(rot).longest_samples;
        let split = job_work(rot).longest_samples;
        let segment_s = split as f64 / rot.fs_hz();
        assert!((segment_s - 63.2).abs() < 0.05, "{segment_s} s");
        assert!(split < whole / 7, "{split} of {whole}");
        // --quick's 15 s is too short to split.
        let quick = plan_reproduce(true).unwrap();
        let rot = &quick.jobs[job_index(&quick.jobs, "m2tfg-rotating")].cfg;
        assert_eq!(
            job_work(rot).longest_samples,
            gyroemu_experiment::sweep_work(rot).longest_samples
        );
        // The bandwidth sweep's longest lane is a refilled one running two of its 4 s points
        // back to back (16.26 s each with the settling, the second from the refill grain's
        // block: 32.515 s), not the 0.05 Hz point's 52.25 s; its points and point-samples are
        // the same.
        let lane_s = |samples: u64| samples as f64 / 240_000.0;
        let split = tables_work(&quick.bandwidth, true).unwrap();
        let whole = tables_work(&quick.bandwidth, false).unwrap();
        assert!(
            (lane_s(split.longest_samples) - 32.515).abs() < 0.001,
            "{split:?}"
        );
        assert!(
            (lane_s(whole.longest_samples) - 52.25).abs() < 0.01,
            "{whole:?}"
        );
        assert_eq!(
            (split.points, split.point_samples),
            (whole.points, whole.point_samples)
        );
        assert_eq!(split.longest_s, whole.longest_s);
    }

    /// The plan validated in parallel holds what a validation one config after the other
    /// gives: the same configs, the bandwidth sweep's in frequency order, and the same
    /// warnings in the same order.
    #[test]
    fn the_parallel_plan_equals_a_sequential_one() {
        let plan = plan_reproduce(false).unwrap();
        let mut warnings = Vec::new();
        for job in &plan.jobs {
            let cfg = preset(job.preset).unwrap();
            assert_eq!(job.cfg, cfg, "{}", job.preset);
            let name = job.preset;
            let own = cfg.validate().unwrap();
            // Each job keeps its own, which its `summary.json` gives.
            assert_eq!(job.warnings, own, "{name}");
            warnings.extend(own.into_iter().map(|w| format!("{name}: {w}")));
        }
        assert_eq!(plan.warnings, warnings);
        let rt = preset("m2tfg-ratetable").unwrap();
        let one_by_one: Vec<Config> = gyroemu_analysis::bandwidth::BANDWIDTH_FREQS_HZ
            .iter()
            .map(|&f| gyroemu_analysis::bandwidth::bandwidth_config(&rt, f).unwrap())
            .collect();
        assert_eq!(plan.bandwidth, one_by_one);
        // The time estimate measures Fig. 9's chain, 0.84e9 of the run's 1.3e9 point-samples.
        assert_eq!(*plan.heaviest_config(), preset("m2tfg-rotating").unwrap());
    }
}
