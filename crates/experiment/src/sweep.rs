//! A sweep over operating points: plans the settling and averaging windows, runs the board
//! sample by sample (four points per SIMD lane group, groups in parallel), then turns the
//! averages into phases with the estimators of THEORY.md section 6, compensates the readout
//! chain terms, and puts the exact theory beside each result.

use crate::board::{
    decimator_mode, resonator_params, tia_params, Board, LaneResult, NonFinite, Point, PointWindow,
    MAX_LANES,
};
use crate::config::{Config, ExperimentKind, RateTable, WindowKind};
use crate::fit::{fit_line, LineFit};
use crate::probe::Probe;
use crate::theory;
use gyroemu_am::Dac;
use gyroemu_core::{f64x4, Complex64, ParamError, Response};
use gyroemu_lpf::Decimator;
use gyroemu_mixer::{paper_i_channel_psi_rad, phase_lag_rad, sideband_estimate, Mode};
use gyroemu_resonator::continuous_steady_state;
use gyroemu_tia::Tia;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

const DEG: f64 = core::f64::consts::PI / 180.0;

/// One operating point's result. Phases in degrees, lag positive.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PointResult {
    /// Rate (rotation, excitation, or rate-table amplitude), deg/s.
    pub rate_dps: f64,
    /// Measured phase per mode: Coriolis shift against zero rate, compensated psi (rotating),
    /// or the phase amplitude at the table frequency (rate table).
    pub phase_deg: [f64; 2],
    /// Exact theory for the same quantity.
    pub theory_deg: [f64; 2],
    /// Rotating: the paper-style real-I-channel estimate, with the same compensation.
    pub paper_i_deg: Option<[f64; 2]>,
    /// Rotating: psi before compensation of the chain terms.
    pub raw_psi_deg: Option<[f64; 2]>,
    /// Rotating: the carrier phase alpha of each mode.
    pub alpha_deg: Option<[f64; 2]>,
    /// Coriolis: the paper's single real mixer DC reading (mixing with the mode's own drive), V.
    pub single_mixer_dc_v: Option<[f64; 2]>,
    /// Rate table: lag of the phase response behind the table, degrees (theory beside).
    pub table_lag_deg: Option<[f64; 2]>,
    /// Rate table: theory of that lag.
    pub table_lag_theory_deg: Option<f64>,
    /// Averaging time actually used, s.
    pub averaged_s: f64,
}

/// What the rotating readout compensated at one point, millidegrees (added to psi by the chain).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Compensation {
    pub rate_dps: f64,
    /// TIA: (arg H(f0 - fm) - arg H(f0 + fm))/2, removed from psi.
    pub tia_mdeg: f64,
    /// DAC zero-order hold (about Omega Ts / 2), removed from psi.
    pub dac_hold_mdeg: f64,
    /// Stage-1 low-pass, -arg L(fm): it delays the envelope but not the Omega references
    /// (taken at the decimated instants), so it is removed from psi from the filter's exact
    /// discrete response.
    pub lowpass_mdeg: f64,
    /// Pipeline delay between drive and reference, samples (0: both use the same sample).
    pub pipeline_delay_samples: u64,
}

/// A whole sweep's results and how they were obtained.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepResult {
    pub kind: ExperimentKind,
    pub rate_table: RateTable,
    pub points: Vec<PointResult>,
    pub compensation: Vec<Compensation>,
    /// Fit of the measured phase against the listed rates, per mode.
    pub fit: [LineFit; 2],
    /// Small-angle theory slope per mode, degrees per deg/s.
    pub theory_slope_deg_per_dps: [f64; 2],
    pub settle_s: f64,
    pub fs_hz: f64,
    pub fs_out_hz: f64,
    /// Input samples emulated in all (per lane group).
    pub samples: u64,
    /// Operating-point samples emulated (samples times the points each group carries).
    pub point_samples: u64,
}

impl SweepResult {
    /// Largest |measured - theory| of one mode over the points, millidegrees.
    pub fn max_abs_error_mdeg(&self, mode: usize) -> f64 {
        self.points
            .iter()
            .map(|p| ((p.phase_deg[mode] - p.theory_deg[mode]) * 1e3).abs())
            .fold(0.0, f64::max)
    }
}

/// Progress callback: (input samples done, total).
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// The rates emulated: the listed ones, plus 0 for a constant-rate Coriolis run when it is
/// not listed (the reference the shifts are measured against).
pub fn emulated_rates_dps(cfg: &Config) -> Vec<f64> {
    let mut r = cfg.experiment.rates_dps.clone();
    let constant_coriolis = cfg.experiment.kind == ExperimentKind::Coriolis
        && cfg.experiment.rate_table == RateTable::Constant;
    if constant_coriolis && !r.contains(&0.0) {
        r.push(0.0);
    }
    r
}

/// The averaging window of a point, in decimated samples after settling.
pub fn plan_point(cfg: &Config, rate_dps: f64) -> Point {
    let e = &cfg.experiment;
    let fs_out = cfg.fs_out_hz();
    let rate_rad_s = rate_dps * DEG;
    if e.window == WindowKind::Hann {
        return Point {
            rate_rad_s,
            n_avg: (e.average_s * fs_out).floor().max(1.0) as u64,
            window: PointWindow::Hann,
        };
    }
    // The period whose whole multiples make the boxcar exact.
    let period_s = match (e.kind, e.rate_table) {
        (ExperimentKind::Rotating, _) if rate_dps != 0.0 => Some(180.0 / rate_dps.abs()),
        (ExperimentKind::Coriolis, RateTable::Sinusoid) => e.table_freq_hz.map(|f| 1.0 / f),
        _ => None,
    };
    let span_s = match period_s {
        Some(p) => (e.average_s / p).floor().max(1.0) * p,
        None => e.average_s,
    };
    let x = span_s * fs_out;
    Point {
        rate_rad_s,
        n_avg: x.floor() as u64,
        window: PointWindow::Boxcar {
            frac: if period_s.is_some() {
                x - x.floor()
            } else {
                0.0
            },
        },
    }
}

/// Runs the sweep. `dump_dir` receives the probe's files when the config asks for a dump.
pub fn run_sweep(
    cfg: &Config,
    progress: Progress,
    dump_dir: Option<&std::path::Path>,
) -> Result<SweepResult, SweepError> {
    let run = run_sweep_with(cfg, progress, dump_dir, SweepOptions::default())?;
    finish_sweep(cfg, &run.lanes)
}

/// Called from the worker threads with each finished lane group's points, `(index in
/// emulated_rates_dps, lane result)`, after the group's dump (if any) is written. An error
/// stops the sweep (groups not started are skipped) and is returned.
pub type OnGroup<'a> = &'a (dyn Fn(&[(usize, LaneResult)]) -> Result<(), String> + Sync);

/// What [`run_sweep_with`] runs and what it does with the points it finishes.
#[derive(Default)]
pub struct SweepOptions<'a> {
    /// Points already computed (by index): not run again (a resumed sweep).
    pub done: BTreeMap<usize, LaneResult>,
    /// The point indices this run is responsible for (a shard); `None`: all.
    pub only: Option<Vec<usize>>,
    /// Raised (Ctrl-C): groups not started are skipped, running ones stop within about
    /// 65 536 samples, and the points of every group that did not finish are left out.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Receives each finished group (e.g. to write its point files).
    pub on_group: Option<OnGroup<'a>>,
}

/// The points a [`run_sweep_with`] call has, and whether it was cancelled.
#[derive(Clone, Debug, Default)]
pub struct SweepRun {
    /// Every point available: the given `done` plus those computed now, by index.
    pub lanes: BTreeMap<usize, LaneResult>,
    /// Indices computed by this call, ascending.
    pub computed: Vec<usize>,
    /// The cancel flag stopped the run before every point it was given finished.
    pub cancelled: bool,
    /// Operating-point samples emulated by the groups that finished.
    pub point_samples: u64,
}

/// The canonical lane grouping of a sweep (all points in index order, four per group) and
/// its work: (input samples per lane group summed, operating-point samples). Reported in the
/// results, so they are the same whichever subset, order or shard actually ran the points.
pub(crate) fn canonical_work(cfg: &Config, points: &[Point]) -> (u64, u64) {
    let n_settle = cfg.n_settle_out();
    let m = cfg.board.decimation as u64;
    let group_samples =
        |g: &[Point]| (n_settle + g.iter().map(|p| p.n_avg + 1).max().unwrap_or(1)) * m;
    points.chunks(MAX_LANES).fold((0, 0), |(s, ps), g| {
        let n = group_samples(g);
        (s + n, ps + n * g.len() as u64)
    })
}

/// A lane group reports the input samples it has done (`n`, its own count): adds the increase
/// since its previous report (`last`) to the count shared by all groups (`done`) and reports
/// that against `total`.
pub(crate) fn add_group_progress(
    done: &AtomicU64,
    last: &AtomicU64,
    n: u64,
    total: u64,
    progress: Progress,
) {
    let prev = last.swap(n, Ordering::Relaxed);
    let all = done.fetch_add(n - prev, Ordering::Relaxed) + n - prev;
    progress(all, total);
}

/// Runs the points of a sweep that `opts` assigns and that are not done yet, four per lane
/// group in index order, groups in parallel. Each point draws the noise stream of its index,
/// and lanes do not interact, so any subset or grouping gives every point the same bits.
pub fn run_sweep_with(
    cfg: &Config,
    progress: Progress,
    dump_dir: Option<&std::path::Path>,
    opts: SweepOptions,
) -> Result<SweepRun, SweepError> {
    let rates = emulated_rates_dps(cfg);
    let todo: Vec<usize> = match &opts.only {
        Some(only) => {
            let mut v: Vec<usize> = only.iter().copied().filter(|&i| i < rates.len()).collect();
            v.sort_unstable();
            v.dedup();
            v
        }
        None => (0..rates.len()).collect(),
    }
    .into_iter()
    .filter(|i| !opts.done.contains_key(i))
    .collect();
    let plan = |i: usize| plan_point(cfg, rates[i]);
    let n_settle = cfg.n_settle_out();
    let m = cfg.board.decimation as u64;
    let groups: Vec<&[usize]> = todo.chunks(MAX_LANES).collect();
    let group_samples =
        |g: &[usize]| (n_settle + g.iter().map(|&i| plan(i).n_avg + 1).max().unwrap_or(1)) * m;
    let total: u64 = groups.iter().map(|g| group_samples(g)).sum();
    let done = AtomicU64::new(0);
    let dump = cfg.dump.as_ref().map(|d| {
        let idx = rates.iter().position(|&r| r == d.rate_dps).unwrap_or(0);
        (idx, d)
    });
    // Raised by the caller's flag (copied at each progress report) or by a failed group.
    let stop = Arc::new(AtomicBool::new(false));
    let user_cancel = || {
        opts.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    };
    // Build every board first, so a bad parameter fails before any sample is computed.
    let mut boards = Vec::with_capacity(groups.len());
    for g in &groups {
        let r: Vec<f64> = g.iter().map(|&i| plan(i).rate_rad_s).collect();
        // Each point draws the noise stream of its index in the emulated rates.
        let streams: Vec<u64> = g.iter().map(|&i| i as u64).collect();
        let mut board = Board::<f64x4>::with_streams(cfg, &r, &streams)?;
        board.set_cancel(stop.clone());
        boards.push(board);
    }
    type Outcome = Option<Result<(Vec<(usize, LaneResult)>, u64), SweepError>>;
    let outcomes: Vec<Outcome> = boards
        .into_par_iter()
        .zip(groups.par_iter())
        .map(|(mut board, g)| {
            if user_cancel() {
                stop.store(true, Ordering::Relaxed);
            }
            if stop.load(Ordering::Relaxed) {
                return None;
            }
            let points: Vec<Point> = g.iter().map(|&i| plan(i)).collect();
            let mut probe = dump.and_then(|(idx, d)| {
                g.iter().position(|&i| i == idx).map(|lane| {
                    Probe::new(
                        &d.nodes,
                        cfg.board.fs_hz,
                        cfg.board.decimation,
                        d.start_s,
                        d.duration_s,
                        lane,
                    )
                })
            });
            let last = AtomicU64::new(0);
            let report = |n: u64| {
                add_group_progress(&done, &last, n, total, progress);
                if user_cancel() {
                    stop.store(true, Ordering::Relaxed);
                }
            };
            let res = board.run(n_settle, &points, probe.as_mut(), &report);
            // A raised flag may have cut the run short: its averages are not the point's.
            if stop.load(Ordering::Relaxed) {
                return None;
            }
            let finished = (|| {
                let lanes = res?;
                if let (Some(p), Some(dir)) = (probe, dump_dir) {
                    p.write(dir, "dump")
                        .map_err(|e| SweepError::Output(e.to_string()))?;
                }
                let pts: Vec<(usize, LaneResult)> = g.iter().copied().zip(lanes).collect();
                if let Some(f) = opts.on_group {
                    f(&pts).map_err(SweepError::Output)?;
                }
                Ok((pts, group_samples(g) * g.len() as u64))
            })();
            if finished.is_err() {
                stop.store(true, Ordering::Relaxed);
            }
            Some(finished)
        })
        .collect();
    let mut run = SweepRun {
        lanes: opts.done,
        computed: Vec::new(),
        cancelled: false,
        point_samples: 0,
    };
    let mut first_err = None;
    for o in outcomes {
        match o {
            None => run.cancelled = true,
            Some(Err(e)) => {
                first_err.get_or_insert(e);
            }
            Some(Ok((pts, work))) => {
                run.point_samples += work;
                for (i, lane) in pts {
                    run.computed.push(i);
                    run.lanes.insert(i, lane);
                }
            }
        }
    }
    if let Some(e) = first_err {
        return Err(e);
    }
    run.computed.sort_unstable();
    Ok(run)
}

/// Turns the lane results of every point of a sweep (by index in `emulated_rates_dps`) into
/// the sweep's result, the same bits whichever runs computed them.
pub fn finish_sweep(
    cfg: &Config,
    lanes: &BTreeMap<usize, LaneResult>,
) -> Result<SweepResult, SweepError> {
    let rates = emulated_rates_dps(cfg);
    let missing: Vec<usize> = (0..rates.len())
        .filter(|i| !lanes.contains_key(i))
        .collect();
    if !missing.is_empty() {
        return Err(SweepError::Missing(missing));
    }
    let points: Vec<Point> = rates.iter().map(|&r| plan_point(cfg, r)).collect();
    let lane_results: Vec<LaneResult> = (0..rates.len()).map(|i| lanes[&i]).collect();
    let (samples, point_samples) = canonical_work(cfg, &points);
    let res = post_process(cfg, &rates, &points, &lane_results)?;
    Ok(SweepResult {
        settle_s: cfg.settle_s(),
        fs_hz: cfg.board.fs_hz,
        fs_out_hz: cfg.fs_out_hz(),
        samples,
        point_samples,
        ..res
    })
}

/// Why a sweep failed after validation.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error(transparent)]
    Param(#[from] ParamError),
    #[error("writing the signal dump failed: {0}")]
    Output(String),
    #[error(transparent)]
    NonFinite(#[from] NonFinite),
    /// Points without a result (indices in `emulated_rates_dps`).
    #[error("the sweep is missing the results of points {0:?}")]
    Missing(Vec<usize>),
}

fn is_ideal(cfg: &Config) -> bool {
    let d = &cfg.device;
    d.mode2_f0_offset_hz == 0.0
        && d.q_mode2.is_none_or(|q2| q2 == d.q)
        && d.quadrature_coupling_rad2_s2 == 0.0
        && cfg.board.phase_shifter_error_deg == 0.0
}

/// Exact Coriolis theory: the closed form for an ideal device, else the continuous-time
/// steady state of the imperfect plant (velocity phase against zero rate).
fn coriolis_theory_rad(cfg: &Config, omega: f64) -> [f64; 2] {
    let d = &cfg.device;
    if is_ideal(cfg) {
        return theory::coriolis_theta_rad(
            d.f0_hz,
            d.q,
            d.angular_gain,
            cfg.drive.f1,
            cfg.drive.f2,
            omega,
        );
    }
    let p = resonator_params(cfg);
    let shift = (90.0 + cfg.board.phase_shifter_error_deg) * DEG;
    let force = [
        Complex64::new(cfg.drive.f1, 0.0),
        Complex64::from_polar(cfg.drive.f2, -shift),
    ];
    let v = |w: f64| continuous_steady_state(&p, w, d.f0_hz, force);
    let (x0, x) = (v(0.0), v(omega));
    [phase_lag_rad(x[2], x0[2]), phase_lag_rad(x[3], x0[3])]
}

/// Exact rotating-excitation psi per mode: the closed form for an ideal device; otherwise the
/// major-axis estimator applied to the continuous-time velocity phasors of the imperfect plant
/// at the two sidebands w0 +- Omega (drive sidebands F1/2, F1/2 on mode 1 and -j F2/2, +j F2/2
/// on mode 2), psi_k = (arg(V_k(-)/M-) - arg(V_k(+)/M+))/2 as in THEORY.md section 6. A
/// phase-shifter error eps makes the mode-2 modulation sin(Omega t - eps), which turns its
/// sidebands by e^{-+j eps}.
fn rotating_theory_rad(cfg: &Config, omega: f64) -> [f64; 2] {
    let d = &cfg.device;
    if is_ideal(cfg) || omega == 0.0 {
        return [theory::rotating_psi_rad(d.f0_hz, d.q, omega); 2];
    }
    let p = resonator_params(cfg);
    let fm = omega / core::f64::consts::TAU;
    let (f1, f2) = (cfg.drive.f1, cfg.drive.f2);
    let j = Complex64::new(0.0, 1.0);
    let eps = cfg.board.phase_shifter_error_deg * DEG;
    let v = |sign: f64| {
        let turn = Complex64::from_polar(1.0, -sign * eps);
        let force = [Complex64::new(0.5 * f1, 0.0), -j * sign * 0.5 * f2 * turn];
        continuous_steady_state(&p, 0.0, d.f0_hz + sign * fm, force)
    };
    let (vp, vm) = (v(1.0), v(-1.0));
    let m = [
        (Complex64::new(1.0, 0.0), Complex64::new(1.0, 0.0)),
        (-j, j),
    ];
    [0, 1].map(|k| {
        let (mp, mm) = m[k];
        0.5 * ((vm[2 + k] / mm).arg() - (vp[2 + k] / mp).arg())
    })
}

/// Small-signal phase amplitude per unit rate-table amplitude, per mode (rad per rad/s).
fn rate_table_gains(cfg: &Config) -> [f64; 2] {
    let d = &cfg.device;
    let (f1, f2) = (cfg.drive.f1, cfg.drive.f2);
    let ft = cfg.experiment.table_freq_hz.unwrap_or(0.0);
    let g = |a: f64, b: f64| theory::rate_table_gain(d.f0_hz, d.q, d.angular_gain, a, b, ft).0;
    [g(f1, f2), g(f2, f1)]
}

/// The exact theory of the quantity a sweep measures at `rate_dps`, per mode, degrees (the
/// rate-table case is the small-signal first-order model of THEORY.md section 3).
pub fn theory_deg(cfg: &Config, rate_dps: f64) -> [f64; 2] {
    let omega = rate_dps * DEG;
    let rad = match (cfg.experiment.kind, cfg.experiment.rate_table) {
        (ExperimentKind::Coriolis, RateTable::Constant) => coriolis_theory_rad(cfg, omega),
        (ExperimentKind::Coriolis, RateTable::Sinusoid) => rate_table_gains(cfg).map(|g| g * omega),
        (ExperimentKind::Rotating, _) => rotating_theory_rad(cfg, omega),
    };
    rad.map(|r| r / DEG)
}

/// Turns each emulated point's lane averages into phases, compensation, theory and fits (the
/// `samples` and rate fields of the result are left for the caller).
#[allow(clippy::needless_range_loop)] // mode indices address parallel arrays
pub fn post_process(
    cfg: &Config,
    rates: &[f64],
    points: &[Point],
    lanes: &[LaneResult],
) -> Result<SweepResult, ParamError> {
    let d = &cfg.device;
    let (f1, f2) = (cfg.drive.f1, cfg.drive.f2);
    let fs_out = cfg.fs_out_hz();
    let e = &cfg.experiment;
    let tia = Tia::<f64>::new(&tia_params(cfg))?;
    let dac = Dac::<f64>::new(cfg.board.fs_hz, None)?;
    let lp = Decimator::<f64>::new(decimator_mode(cfg), cfg.board.decimation, cfg.board.fs_hz)?;
    let w0 = 2.0 * core::f64::consts::PI * d.f0_hz;
    let mut out = Vec::new();
    let mut comp = Vec::new();
    let zero = rates.iter().position(|&r| r == 0.0);
    let averaged = |p: &Point| p.span_samples() / fs_out;
    for (i, &rate) in rates.iter().enumerate() {
        if !e.rates_dps.contains(&rate) {
            continue; // the implicit zero-rate reference
        }
        let lr = &lanes[i];
        let omega = rate * DEG;
        let mut r = PointResult {
            rate_dps: rate,
            phase_deg: [0.0; 2],
            theory_deg: [0.0; 2],
            paper_i_deg: None,
            raw_psi_deg: None,
            alpha_deg: None,
            single_mixer_dc_v: None,
            table_lag_deg: None,
            table_lag_theory_deg: None,
            averaged_s: averaged(&points[i]),
        };
        r.theory_deg = theory_deg(cfg, rate);
        match (e.kind, e.rate_table) {
            (ExperimentKind::Coriolis, RateTable::Constant) => {
                let z0 = lanes[zero.expect("zero rate is always emulated")].z;
                for k in 0..2 {
                    r.phase_deg[k] = phase_lag_rad(lr.z[k], z0[k]) / DEG;
                }
                // Mixing with the mode's own drive: cos w0t (mode 1), sin w0t (mode 2).
                r.single_mixer_dc_v = Some([0.5 * lr.z[0].re, -0.5 * lr.z[1].im]);
            }
            (ExperimentKind::Coriolis, RateTable::Sinusoid) => {
                let ft = e.table_freq_hz.unwrap_or(0.0);
                let l = lp.response(ft);
                let mut lag = [0.0; 2];
                for k in 0..2 {
                    // The phase passed through the stage-1 low-pass: divide its response out.
                    let x = lr.table_phase[k] / l;
                    r.phase_deg[k] = x.norm().to_degrees();
                    // Response to A sin(wt) has complex amplitude -j A e^{-j lag}.
                    lag[k] = -(x * Complex64::new(0.0, 1.0)).arg().to_degrees();
                    let (_, ph) =
                        theory::rate_table_gain(d.f0_hz, d.q, d.angular_gain, 1.0, 1.0, ft);
                    r.table_lag_theory_deg = Some(ph.to_degrees());
                }
                r.table_lag_deg = Some(lag);
            }
            (ExperimentKind::Rotating, _) => {
                let fm = omega.abs() / core::f64::consts::TAU;
                let term = |h: &dyn Fn(f64) -> Complex64| {
                    0.5 * (h(d.f0_hz - fm).arg() - h(d.f0_hz + fm).arg())
                };
                let sgn = omega.signum();
                let tia_t = sgn * term(&|f| tia.response(f));
                let hold_t = sgn * term(&|f| dac.response(f));
                // A real low-pass multiplies the baseband sidebands by L(fm) and conj L(fm).
                let lp_t = -sgn * lp.response(fm).arg();
                let chain = tia_t + hold_t + lp_t;
                comp.push(Compensation {
                    rate_dps: rate,
                    tia_mdeg: tia_t / DEG * 1e3,
                    dac_hold_mdeg: hold_t / DEG * 1e3,
                    lowpass_mdeg: lp_t / DEG * 1e3,
                    pipeline_delay_samples: 0,
                });
                let mut raw = [0.0; 2];
                let mut paper = [0.0; 2];
                let mut alpha = [0.0; 2];
                for (k, mode) in [Mode::One, Mode::Two].into_iter().enumerate() {
                    let est = sideband_estimate(lr.c[k], lr.s[k], mode);
                    raw[k] = est.psi_rad / DEG;
                    alpha[k] = est.alpha_rad / DEG;
                    r.phase_deg[k] = (est.psi_rad - chain) / DEG;
                    // A real channel cannot tell the sign of the carrier (an inverting TIA
                    // flips it): fold the paper-style reading into (-90, 90] degrees.
                    let p = paper_i_channel_psi_rad(lr.c[k], lr.s[k], mode) - chain;
                    paper[k] =
                        (p - core::f64::consts::PI * (p / core::f64::consts::PI).round()) / DEG;
                }
                r.raw_psi_deg = Some(raw);
                r.paper_i_deg = Some(paper);
                r.alpha_deg = Some(alpha);
            }
        }
        out.push(r);
    }
    let xs: Vec<f64> = out.iter().map(|p| p.rate_dps).collect();
    let fit =
        [0, 1].map(|k| fit_line(&xs, &out.iter().map(|p| p.phase_deg[k]).collect::<Vec<_>>()));
    let slope = match (e.kind, e.rate_table) {
        (ExperimentKind::Coriolis, RateTable::Constant) => {
            let g = 2.0 * d.q * d.angular_gain / w0;
            [g * f2 / f1, g * f1 / f2]
        }
        (ExperimentKind::Coriolis, RateTable::Sinusoid) => rate_table_gains(cfg),
        (ExperimentKind::Rotating, _) => [2.0 * d.q / w0; 2],
    };
    Ok(SweepResult {
        kind: e.kind,
        rate_table: e.rate_table,
        points: out,
        compensation: comp,
        fit,
        theory_slope_deg_per_dps: slope,
        settle_s: 0.0,
        fs_hz: 0.0,
        fs_out_hz: 0.0,
        samples: 0,
        point_samples: 0,
    })
}

#[cfg(test)]
mod resume_tests {
    use super::*;
    use std::sync::Mutex;

    fn small() -> Config {
        let mut cfg = crate::presets::preset("m2tfg-coriolis").unwrap();
        cfg.experiment.average_s = 0.1;
        cfg.experiment.settle_s = Some(0.02);
        cfg.experiment.rates_dps = vec![25.0, 50.0, 75.0, 100.0, 125.0, 150.0];
        cfg
    }

    #[test]
    fn subsets_in_any_grouping_give_the_whole_sweeps_bits() {
        let cfg = small();
        let whole = run_sweep(&cfg, &|_, _| {}, None).unwrap();
        let n = emulated_rates_dps(&cfg).len();
        // Odd points first (other lane groups than the whole run's), then the rest resumed.
        let seen = Mutex::new(Vec::new());
        let on_group = |pts: &[(usize, LaneResult)]| {
            seen.lock().unwrap().extend(pts.iter().map(|p| p.0));
            Ok(())
        };
        let odd = run_sweep_with(
            &cfg,
            &|_, _| {},
            None,
            SweepOptions {
                only: Some((1..n).step_by(2).collect()),
                on_group: Some(&on_group),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(!odd.cancelled);
        assert_eq!(odd.computed, (1..n).step_by(2).collect::<Vec<_>>());
        assert!(matches!(
            finish_sweep(&cfg, &odd.lanes),
            Err(SweepError::Missing(_))
        ));
        let rest = run_sweep_with(
            &cfg,
            &|_, _| {},
            None,
            SweepOptions {
                done: odd.lanes,
                on_group: Some(&on_group),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(rest.computed, (0..n).step_by(2).collect::<Vec<_>>());
        let mut s = seen.into_inner().unwrap();
        s.sort_unstable();
        assert_eq!(s, (0..n).collect::<Vec<_>>());
        assert_eq!(finish_sweep(&cfg, &rest.lanes).unwrap(), whole);
    }

    #[test]
    fn a_raised_cancel_flag_runs_nothing() {
        let cfg = small();
        let run = run_sweep_with(
            &cfg,
            &|_, _| {},
            None,
            SweepOptions {
                cancel: Some(Arc::new(AtomicBool::new(true))),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(run.cancelled && run.lanes.is_empty() && run.computed.is_empty());
    }

    #[test]
    fn a_failing_point_writer_stops_the_sweep_with_its_error() {
        let cfg = small();
        let fail = |_: &[(usize, LaneResult)]| Err("disk full".to_string());
        let r = run_sweep_with(
            &cfg,
            &|_, _| {},
            None,
            SweepOptions {
                on_group: Some(&fail),
                ..Default::default()
            },
        );
        assert!(matches!(r, Err(SweepError::Output(e)) if e == "disk full"));
    }
}
