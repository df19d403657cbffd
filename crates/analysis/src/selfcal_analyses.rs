//! The analyses of `gyroemu selfcal`, each a sample-by-sample emulation of the same board:
//! the Allan deviation of the zero-rate phase output, the self-calibration error against the
//! averaging time (one long rotating run read at checkpoints), and a temperature drift.

use crate::allan::{
    fit::NoiseModelFit, noise_readings_settled, overlapping_adev, AllanPoint, NoiseReadings,
};
pub use crate::selfcal::drift_pll_design;
use crate::selfcal::{drifted, run_selfcal_core, sweep_configs};
use crate::selfcal_combined::{combined_slope, CombinedSlope};
use crate::slope_fit::{linearised_slope, SlopeFit};
use gyroemu_board::{lane_groups, max_lanes_for, GroupBoard, LaneResult, Point, RunOptions};
use gyroemu_config::{Config, WindowKind};
use gyroemu_experiment::post_process;
use gyroemu_experiment::sweep::{add_group_progress, group_samples};
use gyroemu_experiment::{lock_config_carrier, resolve_lock, Progress, SweepError};
use gyroemu_lpf::Window;
use gyroemu_mixer::wrap_pi;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicU64, Ordering};

/// Noise streams of the analyses start here, apart from the sweep points' streams (0..).
pub const ANALYSIS_STREAM_BASE: u64 = 1 << 32;

/// The Allan record's streams (points at zero rate, one lane group).
const ALLAN_STREAMS: usize = 4;

/// Allan deviation of the zero-rate output, from four independent records (one per lane).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AllanResult {
    /// Sample interval of the analysed series (block means of the decimated output), s.
    pub tau0_s: f64,
    pub record_s: f64,
    /// Of the mode-1 phase output, degrees (records pooled: RMS over the four).
    pub phase_deg: Vec<AllanPoint>,
    /// Of the rate-equivalent output (phase over the measured scale factor), deg/s.
    pub rate_dps: Vec<AllanPoint>,
    pub readings: Option<NoiseReadings>,
    /// The scale factor used, deg of phase per deg/s.
    pub scale_deg_per_dps: f64,
    /// Its relative 95 % half-width (the rate-table slope's), counted in every interval of
    /// `readings.model_fit`: the rate-equivalent terms are the phase's over the measured
    /// scale, which a noisy sweep misses by more than the fit's own intervals allowed.
    pub scale_rel_ci95: f64,
    /// Why the noise-model fit's terms may not be the device's, if a configured source has a
    /// term the model lacks (the carrier's phase flicker).
    pub model_warning: Option<String>,
}

/// The carrier's phase flicker turns the drives and the demodulation alike, so it cancels
/// below the envelope corner and leaves a high-passed 1/f phase, whose Allan variance falls
/// as ln(tau)/tau^2: IEEE Std 952's model has no such term, and its fit took it as angle random
/// walk (3.3 to 3.8 deg/sqrt(h) with tight intervals for a source with none) and quantisation.
const FLICKER_ANGLE_WARNING: &str = "the carrier's flicker cancels below the envelope corner f0/(2Q) and leaves a term whose Allan variance falls as ln(tau)/tau^2, which IEEE Std 952's model has not; the fit takes it as angle random walk and quantisation, so allan.model_fit can read N and Q (with intervals) where the device has neither, or too large";

impl AllanResult {
    /// Why a reading is absent, only a bound, or unreliable: one line each, for the run's
    /// warnings (a null in `selfcal.json` alone is easy to miss).
    pub fn warnings(&self) -> Vec<String> {
        let Some(r) = self.readings else {
            return vec!["Allan deviation: too few points for any reading".into()];
        };
        let mut w: Vec<String> = self
            .model_warning
            .iter()
            .map(|m| format!("Allan deviation: {m}"))
            .collect();
        if let Some(why) = r.arw_warning {
            w.push(format!(
                "Allan deviation: angle random walk not read: {why}"
            ));
        }
        // Beside the refusal, the noise-model fit's number and its method.
        if r.arw_deg_per_rt_h.is_nan() && r.model_fit.arw_deg_per_rt_h.is_finite() {
            if let Some(s) = r.model_fit.summary() {
                w.push(format!(
                    "Allan deviation: the noise-model fit (IEEE Std 952 Annex C, allan.model_fit) reads {s}"
                ));
            }
        }
        if let Some(why) = r.bias_instability_warning {
            w.push(format!("Allan deviation: bias instability: {why}"));
        }
        w
    }
}

/// Runs `record_s` of the board at zero rate (Coriolis drive) on four streams and reads the
/// Allan deviation of the mode-1 phase. `scale_deg_per_dps` converts phase to rate; its
/// relative 95 % half-width `scale_rel_ci95` widens every interval of the noise-model fit.
pub fn allan_analysis(
    cfg: &Config,
    record_s: f64,
    scale_deg_per_dps: f64,
    scale_rel_ci95: f64,
    progress: Progress,
) -> Result<AllanResult, SweepError> {
    let (_, cor) = sweep_configs(cfg);
    let fs_out = cor.fs_out_hz();
    let block = ((0.01 * fs_out).round() as u64).max(1);
    let tau0 = block as f64 / fs_out;
    let n_avg = (record_s * fs_out).floor() as u64;
    let point = Point {
        rate_rad_s: 0.0,
        window: Window::Boxcar {
            n: n_avg,
            frac: 0.0,
        },
    };
    let streams: [u64; ALLAN_STREAMS] = core::array::from_fn(|i| ANALYSIS_STREAM_BASE + i as u64);
    let mut board = GroupBoard::new(&cor.board_params(), &[0.0; ALLAN_STREAMS], &streams)?;
    let n_settle = cor.n_settle_out();
    let total = (n_settle + n_avg + 1) * cor.decimation() as u64;
    let opts = RunOptions {
        series_block: block,
        ..Default::default()
    };
    let out = board.run(n_settle, &[point; ALLAN_STREAMS], opts, &|d| {
        progress(d, total)
    })?;
    // Phase lag of mode 1, degrees, unwrapped (the record never wraps at zero rate, but a
    // noisy low-amplitude device could).
    let curves: Vec<Vec<AllanPoint>> = out
        .series
        .iter()
        .map(|rows| {
            let mut prev = 0.0f64;
            let mut acc = 0.0f64;
            let ph: Vec<f64> = rows
                .iter()
                .enumerate()
                .map(|(i, r)| {
                    let p = -r[1].atan2(r[0]);
                    if i > 0 {
                        acc += wrap_pi(p - prev);
                    } else {
                        acc = p;
                    }
                    prev = p;
                    acc.to_degrees()
                })
                .collect();
            overlapping_adev(&ph, tau0, 8)
        })
        .collect();
    let phase: Vec<AllanPoint> = (0..curves[0].len())
        .map(|j| {
            let ms =
                curves.iter().map(|c| c[j].adev * c[j].adev).sum::<f64>() / curves.len() as f64;
            AllanPoint {
                tau_s: curves[0][j].tau_s,
                adev: ms.sqrt(),
                n_terms: curves.iter().map(|c| c[j].n_terms).sum(),
            }
        })
        .collect();
    let rate: Vec<AllanPoint> = phase
        .iter()
        .map(|p| AllanPoint {
            adev: p.adev / scale_deg_per_dps.abs(),
            ..*p
        })
        .collect();
    // Below ten mechanical time constants the resonator still rolls the curve off.
    let mut readings = noise_readings_settled(&rate, 10.0 * cor.slowest_tau_s());
    if let Some(r) = &mut readings {
        widen_by_scale(&mut r.model_fit, scale_rel_ci95);
    }
    let flicker = cfg
        .noise
        .as_ref()
        .map(|n| n.carrier_phase_flicker_rad_per_rthz)
        .filter(|&x| x > 0.0);
    Ok(AllanResult {
        tau0_s: tau0,
        record_s: n_avg as f64 / fs_out,
        readings,
        phase_deg: phase,
        rate_dps: rate,
        scale_deg_per_dps,
        scale_rel_ci95,
        model_warning: flicker.map(|x| {
            format!("noise.carrier_phase_flicker_rad_per_rthz = {x}: {FLICKER_ANGLE_WARNING}")
        }),
    })
}

/// Each interval of `fit` as wide as the scale's error makes it: a rate-equivalent term is
/// the phase's over the scale (the tau^-2 coefficient over its square), and the true scale
/// lies within `1 +- rel` of the one used (95 %), so the term within `[lo, hi]` times
/// `[1/(1 + rel), 1/(1 - rel)]` (to every positive value once `rel` reaches 1).
fn widen_by_scale(fit: &mut NoiseModelFit, rel: f64) {
    if rel.is_nan() || rel <= 0.0 {
        return;
    }
    let span = |power: i32| {
        let hi = if rel < 1.0 {
            (1.0 - rel).powi(-power)
        } else {
            f64::INFINITY
        };
        ((1.0 + rel).powi(-power), hi)
    };
    let widen = |ci: &mut [f64; 2], power: i32| {
        let (a, b) = span(power);
        // 0 stays 0 when b is infinite; a NaN end (an undetermined term) stays NaN.
        let times = |x: f64, f: f64| if x == 0.0 { 0.0 } else { x * f };
        let [lo, hi] = *ci;
        // Either end times a factor in [a, b] (a bound may be negative): the extremes.
        *ci = [
            times(lo, a).min(times(lo, b)),
            times(hi, a).max(times(hi, b)),
        ];
    };
    widen(&mut fit.arw_deg_per_rt_h_ci95, 1);
    widen(&mut fit.bias_instability_deg_per_h_ci95, 1);
    widen(&mut fit.rate_random_walk_deg_per_h_per_rt_h_ci95, 1);
    widen(&mut fit.quantisation_deg_ci95, 1);
    widen(&mut fit.tau_minus2_coefficient_dps2_s2_ci95, 2);
}

/// The self-calibration at one averaging time.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TauPoint {
    /// Averaging time asked, s.
    pub tau_s: f64,
    /// Averaging time used by the slowest rate (whole half periods once tau allows), s.
    pub averaged_s: f64,
    pub predicted_deg_per_dps: f64,
    /// Predicted over the measured Coriolis slope, minus one.
    pub relative_error: f64,
    pub relative_error_ci95: f64,
    /// Predicted over lambda times the slope of the rotating sweep's exact theory phases,
    /// minus one: the rotating reading's noise and truncation only, without the rate table.
    pub relative_error_vs_theory: f64,
    /// Both modes together: lambda times the geometric mean of their rotating slopes.
    pub combined_predicted_deg_per_dps: f64,
    /// That over the combined Coriolis slope measured by the sweep, minus one.
    pub combined_relative_error: f64,
    pub combined_relative_error_ci95: f64,
}

/// The averaging times read: 1, 2, 5 per decade up to `tau_max_s`, plus the config's
/// averaging time and 500 s (the paper's) when in range.
pub fn tau_grid(tau_max_s: f64, average_s: f64) -> Vec<f64> {
    let mut g: Vec<f64> = (0..8)
        .flat_map(|d| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(d)))
        .filter(|&t| t <= tau_max_s)
        .collect();
    for t in [average_s, 500.0, tau_max_s] {
        if t >= 1.0 && t <= tau_max_s && !g.contains(&t) {
            g.push(t);
        }
    }
    g.sort_by(f64::total_cmp);
    g
}

/// One rotating run of `tau_max_s`, read at every averaging time of [`tau_grid`] (each point
/// averaged over whole half periods once tau spans one, as the sweep does), compared with
/// the measured Coriolis slope of mode 1 (`coriolis`), and the two modes' combined prediction
/// with their combined measured slope (`combined_coriolis`, a NaN slope leaves it out). Each
/// interval counts both slopes' errors, as the main self-calibration's does: the rate-table
/// slope is measured once, and its error is in every reading.
pub fn tau_analysis(
    cfg: &Config,
    tau_max_s: f64,
    coriolis: &SlopeFit,
    combined_coriolis: &CombinedSlope,
    group_threads: Option<usize>,
    progress: Progress,
) -> Result<Vec<TauPoint>, SweepError> {
    let measured_deg_per_dps = coriolis.slope_deg_per_dps;
    let combined_measured_deg_per_dps = combined_coriolis.slope_deg_per_dps;
    let (mut rot, _) = sweep_configs(cfg);
    // Every reading is an early read of one run, and an early read is a prefix of the run's
    // window: only a boxcar has one. With the config's Hann window the readings had taken
    // Hann leaks that were never applied (+27.75 at 1 s on a noiseless ideal device).
    rot.experiment.window = WindowKind::Boxcar;
    let grid = tau_grid(tau_max_s, cfg.experiment.average_s);
    rot.experiment.average_s = tau_max_s;
    let rates = rot.emulated_rates_dps();
    let points: Vec<Point> = rates.iter().map(|&r| rot.plan_point(r)).collect();
    // Window of each point at each tau: plan_point's rule (whole half periods) once tau spans
    // half a modulation period; below that, exactly tau (the truncated window a user who
    // stops early gets, so its leakage shows).
    let fs_out = rot.fs_out_hz();
    let windows: Vec<Vec<Point>> = grid
        .iter()
        .map(|&t| {
            let mut c = rot.clone();
            c.experiment.average_s = t;
            rates
                .iter()
                .map(|&r| {
                    let half_period_s = 180.0 / r.abs().max(1e-300);
                    if t < half_period_s {
                        Point {
                            rate_rad_s: r.to_radians(),
                            window: Window::Boxcar {
                                n: ((t * fs_out).floor() as u64).max(1),
                                frac: 0.0,
                            },
                        }
                    } else {
                        c.plan_point(r)
                    }
                })
                .collect()
        })
        .collect();
    let n_settle = rot.n_settle_out();
    let mut groups: Vec<(usize, &[Point])> = Vec::new();
    let mut first = 0;
    let threads = group_threads.unwrap_or_else(rayon::current_num_threads);
    let params = rot.board_params();
    for size in lane_groups(points.len(), threads, max_lanes_for(&params)) {
        groups.push((first, &points[first..first + size]));
        first += size;
    }
    // Progress counts the groups that run (one of eight where the CPU has AVX-512), not the
    // canonical four-lane grouping the results report, so it ends at 100 %.
    let total: u64 = groups.iter().map(|(_, g)| group_samples(&rot, g)).sum();
    let done = AtomicU64::new(0);
    let mut boards = Vec::new();
    for (first, g) in &groups {
        let r: Vec<f64> = g.iter().map(|p| p.rate_rad_s).collect();
        let s: Vec<u64> = (0..g.len()).map(|i| (first + i) as u64).collect();
        boards.push(GroupBoard::new(&params, &r, &s)?);
    }
    let results: Vec<Result<Vec<Vec<LaneResult>>, SweepError>> = boards
        .into_par_iter()
        .zip(groups.par_iter())
        .with_max_len(1)
        .map(|(mut board, (first, g))| {
            let early_reads = (0..g.len())
                .map(|i| {
                    windows
                        .iter()
                        .map(|w| match w[first + i].window {
                            Window::Boxcar { n, frac } => (n, frac),
                            Window::Hann { n } => (n, 0.0),
                        })
                        .collect()
                })
                .collect();
            let opts = RunOptions {
                early_reads,
                ..Default::default()
            };
            let last = AtomicU64::new(0);
            let report = |n: u64| add_group_progress(&done, &last, n, total, progress);
            Ok(board.run(n_settle, g, opts, &report)?.early_reads)
        })
        .collect();
    let mut per_point: Vec<Vec<LaneResult>> = Vec::new();
    for r in results {
        per_point.extend(r?);
    }
    let lambda = cfg.device.angular_gain;
    grid.iter()
        .enumerate()
        .map(|(ti, &tau)| {
            let lanes: Vec<LaneResult> = per_point.iter().map(|cks| cks[ti]).collect();
            let mut c = rot.clone();
            c.experiment.average_s = tau;
            let res = post_process(&c, &rates, &windows[ti], &lanes)?;
            let xs: Vec<f64> = res.points.iter().map(|p| p.rate_dps).collect();
            let [ys, ys2]: [Vec<f64>; 2] =
                [0, 1].map(|k| res.points.iter().map(|p| p.phase_deg[k]).collect());
            let s = linearised_slope(&xs, &ys);
            let comb = combined_slope(&xs, [&ys, &ys2]);
            let t95 = gyroemu_experiment::fit::t95;
            let comb_predicted = lambda * comb.slope_deg_per_dps;
            let comb_ratio = comb_predicted / combined_measured_deg_per_dps;
            let comb_ci = t95(comb.dof.min(combined_coriolis.dof))
                * comb_ratio
                * comb.rel_std_err.hypot(combined_coriolis.rel_std_err);
            let predicted = lambda * s.slope_deg_per_dps;
            let ratio = predicted / measured_deg_per_dps;
            let ci = t95(s.dof.min(coriolis.dof))
                * ratio
                * s.rel_std_err().hypot(coriolis.rel_std_err());
            // The rotating sweep's own exact theory, read the same way: what a noiseless,
            // untruncated reading gives.
            let theory: Vec<f64> = res.points.iter().map(|p| p.theory_deg[0]).collect();
            let theory_deg_per_dps = lambda * linearised_slope(&xs, &theory).slope_deg_per_dps;
            Ok(TauPoint {
                tau_s: tau,
                averaged_s: res.points.iter().map(|p| p.averaged_s).fold(0.0, f64::max),
                predicted_deg_per_dps: predicted,
                relative_error: ratio - 1.0,
                relative_error_ci95: ci.abs(),
                relative_error_vs_theory: predicted / theory_deg_per_dps - 1.0,
                combined_predicted_deg_per_dps: comb_predicted,
                combined_relative_error: comb_ratio - 1.0,
                combined_relative_error_ci95: comb_ci.abs(),
            })
        })
        .collect()
}

/// The self-calibration at one temperature offset with one way of driving the carrier.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DriftCase {
    /// The carrier the sweeps ran at, Hz.
    pub carrier_hz: f64,
    /// Coriolis slope measured on the rate table at this temperature, deg per deg/s.
    pub measured_deg_per_dps: f64,
    /// Self-calibrated at this temperature.
    pub selfcal_deg_per_dps: f64,
    /// Self-calibration error at this temperature.
    pub selfcal_relative_error: f64,
    /// Its 95 % half-width, as the main result's: off resonance the slope is 6 to 25 times
    /// smaller while the phase noise is not, so this error scatters that much more.
    pub selfcal_relative_error_ci95: f64,
    /// Error of keeping the nominal-temperature calibration instead.
    pub stale_relative_error: f64,
    /// Self-calibration error of both modes together at this temperature.
    pub combined_selfcal_relative_error: f64,
    /// Its 95 % half-width.
    pub combined_selfcal_relative_error_ci95: f64,
}

/// The self-calibration at one temperature offset: the drive open loop at the nominal
/// carrier, and the carrier locked onto the drifted resonance by the PLL.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DriftPoint {
    pub delta_t_k: f64,
    pub f0_hz: f64,
    pub q: f64,
    /// The carrier left where it was at the nominal temperature.
    pub open_loop: DriftCase,
    /// The carrier locked by the PLL at this temperature (held for the sweeps); `None` when
    /// no loop fits the board (validation warns).
    pub pll: Option<DriftCase>,
    /// When the PLL's lock indicator came on for good, s.
    pub pll_lock_time_s: Option<f64>,
    /// Why `pll` is `None` at this temperature though a loop fits: its lock did not hold
    /// (the drifted resonance beyond what the loop pulls in within its lock run).
    pub pll_warning: Option<String>,
}

/// [`drift_pll_design`] when its loop fits the board: the drift scenario then runs its
/// PLL-tracked half too (else that half is left out, and validation says so).
pub fn drift_tracking_design(cfg: &Config) -> Option<Config> {
    let d = drift_pll_design(cfg);
    d.validate().is_ok().then_some(d)
}

/// Re-runs both sweeps on the drifted device at each temperature offset, twice: with the
/// carrier open loop at the nominal one (`cfg`'s, or where a `[pll]` locked it at the
/// nominal temperature), and with the carrier locked by the PLL at that temperature (the
/// loop of [`drift_pll_design`], designed for the nominal device). `nominal_deg_per_dps` is
/// the calibration taken at the nominal temperature (what a device without
/// self-calibration keeps using).
pub fn drift_analysis(
    cfg: &Config,
    deltas_k: &[f64],
    nominal_deg_per_dps: f64,
    group_threads: Option<usize>,
    progress: Progress,
) -> Result<Vec<DriftPoint>, SweepError> {
    let (held, _) = resolve_lock(cfg)?;
    drift_analysis_held(
        cfg,
        &held,
        deltas_k,
        nominal_deg_per_dps,
        group_threads,
        progress,
    )
}

/// [`drift_analysis`] on `held`, `cfg` with its nominal carrier already locked and held
/// ([`resolve_lock`]): `selfcal` has locked it for its sweeps, and the lock is
/// deterministic, so locking it again would only repeat the same run.
pub fn drift_analysis_held(
    cfg: &Config,
    held: &Config,
    deltas_k: &[f64],
    nominal_deg_per_dps: f64,
    group_threads: Option<usize>,
    progress: Progress,
) -> Result<Vec<DriftPoint>, SweepError> {
    let design = drift_tracking_design(cfg);
    let tracked_too = design.is_some();
    // Progress in thousandths of each offset (two self-calibrations of two sweeps, a quarter
    // each; the tracked half only when a loop fits), summed over the offsets and quarters,
    // which all run side by side.
    let total = deltas_k.len() as u64 * if tracked_too { 1000 } else { 500 };
    // A quarter's reports can arrive out of order (its lane groups run side by side): each
    // quarter only moves up, and only its increase is added to the shared count, so the count
    // never passes the total and exactly one report gives it.
    let parts: Vec<[AtomicU64; 4]> = deltas_k.iter().map(|_| Default::default()).collect();
    let done = AtomicU64::new(0);
    let one = |(i, &dt): (usize, &f64)| -> Result<DriftPoint, SweepError> {
        let open = drifted(held, dt);
        let at = |quarter: usize, d: u64, t: u64| {
            let v = d.min(t) * 250 / t.max(1);
            let prev = parts[i][quarter].fetch_max(v, Ordering::Relaxed);
            if v > prev {
                progress(
                    done.fetch_add(v - prev, Ordering::Relaxed) + v - prev,
                    total,
                )
            }
        };
        let case = |c: &Config, q0: usize| -> Result<DriftCase, SweepError> {
            let core = run_selfcal_core(
                c,
                &|d, t| at(q0, d, t),
                &|d, t| at(q0 + 1, d, t),
                group_threads,
            )?;
            let m = core.modes[0];
            Ok(DriftCase {
                carrier_hz: c.carrier_hz(),
                measured_deg_per_dps: m.coriolis.slope_deg_per_dps,
                selfcal_deg_per_dps: m.predicted_deg_per_dps,
                selfcal_relative_error: m.relative_error,
                selfcal_relative_error_ci95: m.relative_error_ci95,
                stale_relative_error: nominal_deg_per_dps / m.coriolis.slope_deg_per_dps - 1.0,
                combined_selfcal_relative_error: core.combined.relative_error,
                combined_selfcal_relative_error_ci95: core.combined.relative_error_ci95,
            })
        };
        // The tracked case needs the lock, not the open-loop case: the two run side by side
        // (when one fails the other still runs to its end; the open-loop error comes first).
        type Tracked = (Option<DriftCase>, Option<f64>, Option<String>);
        let tracked = || -> Result<Tracked, SweepError> {
            let Some(design) = &design else {
                return Ok((None, None, None));
            };
            // A lock that does not hold at one temperature leaves that temperature's tracked
            // half out, said, rather than failing the whole selfcal after its sweeps (whose
            // advice, pll.lock_s, named a key the drift loop does not read).
            let lock = match lock_config_carrier(&open, design) {
                Ok(lock) => lock.expect("the design has a [pll]"),
                Err(SweepError::NotLocked { cause, .. }) => {
                    at(2, 1, 1);
                    at(3, 1, 1);
                    // The lock's own cause (noise, or too far or too slow a loop for the
                    // drifted device), with the drift: the loop is designed for the nominal
                    // device, so a drifted Q makes it slow as well as the offset far.
                    return Ok((None, None, Some(format!(
                        "selfcal.drift_delta_t_k: at dT = {dt:+} K the drift scenario's tracking PLL (designed for the nominal device, Q {}) did not lock: the resonance moved to {} Hz with Q {}, {:+.3} Hz from the carrier it starts at ({} Hz); {cause}; this temperature's PLL-tracked half is null",
                        cfg.device.q,
                        open.device.f0_hz,
                        open.device.q,
                        open.device.f0_hz - open.carrier_hz(),
                        open.carrier_hz()
                    ))));
                }
                Err(e) => return Err(e),
            };
            let mut tracked = open.clone();
            tracked.drive.carrier_hz = Some(lock.carrier_hz);
            Ok((Some(case(&tracked, 2)?), lock.lock_time_s, None))
        };
        let (open_loop, tracked) = rayon::join(|| case(&open, 0), tracked);
        let open_loop = open_loop?;
        let (pll, pll_lock_time_s, pll_warning) = tracked?;
        Ok(DriftPoint {
            delta_t_k: dt,
            f0_hz: open.device.f0_hz,
            q: open.device.q,
            open_loop,
            pll,
            pll_lock_time_s,
            pll_warning,
        })
    };
    // Each offset's sweeps are lane groups of a few seconds: run side by side they fill the
    // threads the longer analyses leave ([`crate::selfcal_run`]). One offset per task: rayon
    // would otherwise hand a thread busy since the start several offsets as one task, which
    // the other thread, once free, cannot take from it. Results keep the offsets' order and
    // bits (a point's bits do not depend on its group or thread).
    deltas_k
        .par_iter()
        .with_max_len(1)
        .enumerate()
        .map(one)
        .collect()
}
