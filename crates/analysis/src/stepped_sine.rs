//! The stepped-sine measurement of `gyroemu sweep`, as a network analyser makes it, emulated
//! sample by sample on the board: at each frequency f and for each mode, the board drives that
//! mode alone at carrier f (the other drive 0) with the device at rest, settles from rest,
//! averages the stage-1 phasors of both modes, and the response is read from them.
//!
//! What is divided out of the averaged phasor `z_k` (mode k read, mode m driven) to give the
//! velocity of mode k per unit force (per unit mass) on mode m, in s:
//! the drive phasor (`F1` on mode 1; `F2 e^{-j (90 + e) deg}` on mode 2, `e` the shifter
//! error), the transduction `device.transduction_a_s_per_m`, the TIA's response `H_TIA(f)`,
//! the stage-1 low-pass's DC gain `L(0)`, and the DAC's zero-order hold at f,
//! `sinc(f Ts) e^{-j pi f Ts}`. What stays is the plant's velocity at the sampling instants
//! under the held drive over the hold's fundamental: the continuous-time response plus the
//! hold's images, which add about `(f Ts)^2 / (1 - (f Ts)^2)` of the off-resonance response
//! (a few 1e-6 of the peak over Q at 16 samples per period).

use gyroemu_board::{Board, ChainResponse, Health, RunOptions, Shape};
use gyroemu_config::Config;
use gyroemu_core::Complex64;
use gyroemu_experiment::{Progress, SweepError, Work};
use gyroemu_nco::Nco;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// One frequency of the sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResponsePoint {
    /// The carrier frequency as the board's oscillator realises it, Hz.
    pub freq_hz: f64,
    /// `response[m][k]`: velocity of mode `k + 1` per unit force on mode `m + 1`, s (the chain
    /// divided out as the module says). `[m][m]` is the driven response, `[m][1 - m]` the
    /// cross-coupling.
    pub response: [[Complex64; 2]; 2],
    /// The averaged stage-1 phasors as the board gave them, `z[m][k]` (V).
    pub z: [[Complex64; 2]; 2],
    /// What was divided out of `z[m][k]` to give `response[m][k]` (the same for both k).
    pub chain: [Complex64; 2],
    /// The converters' and rails' counts of the run driving each mode.
    pub health: [Health; 2],
}

/// The measured frequency response.
#[derive(Clone, Debug, PartialEq)]
pub struct SteppedSine {
    /// The frequencies, ascending.
    pub points: Vec<ResponsePoint>,
    /// Settling at each frequency, s (whole output periods).
    pub settle_s: f64,
    /// Averaging at each frequency, s (whole output periods).
    pub average_s: f64,
    /// Operating-point samples emulated (two runs per frequency).
    pub point_samples: u64,
    /// Readings no signal supports, or that are not finite: each leaves NaN in its place and
    /// makes the command exit non-zero.
    pub problems: Vec<String>,
    /// Clipping and other conditions worth a look.
    pub warnings: Vec<String>,
}

/// Input samples of one run (one frequency, one driven mode).
fn run_samples(cfg: &Config) -> u64 {
    let (settle, point) = cfg.sweep_point();
    (settle + point.window.samples()) * cfg.decimation() as u64
}

/// What `gyroemu sweep` on `cfg` will emulate: two single-lane runs per frequency.
pub fn stepped_sine_work(cfg: &Config) -> Work {
    let n = cfg.sweep_frequencies_hz().len();
    let per_run = run_samples(cfg);
    Work {
        points: 2 * n,
        point_samples: 2 * n as u64 * per_run,
        longest_s: per_run as f64 / cfg.fs_hz(),
        longest_samples: per_run,
        // One point per run: a group of four lanes.
        widest_lanes: 4,
        // The stepped sine runs open loop: a [pll] is not used.
        lock_samples: 0,
    }
}

/// The board of one run: the config's board at rest, its carrier at `f_hz`, only mode `m`
/// driven.
fn run_board(cfg: &Config, f_hz: f64, m: usize) -> gyroemu_board::BoardParams {
    let mut p = cfg.board_params();
    p.shape = Shape::Coriolis;
    p.carrier_hz = f_hz;
    p.drive[1 - m] = 0.0;
    p
}

/// The drive phasor of mode `m` (its force per unit mass, against the carrier's cos).
fn drive_phasor(cfg: &Config, m: usize) -> Complex64 {
    match m {
        0 => Complex64::new(cfg.drive.f1, 0.0),
        _ => Complex64::from_polar(
            cfg.f2(),
            -(90.0 + cfg.board.phase_shifter_error_deg).to_radians(),
        ),
    }
}

/// Runs the stepped-sine measurement of `cfg` (validated with `validate_sweep`): every
/// frequency and driven mode is its own board run, in parallel; run `(i, m)` draws noise
/// stream `2 i + m`, so the results do not depend on the thread count.
pub fn run_stepped_sine(cfg: &Config, progress: Progress) -> Result<SteppedSine, SweepError> {
    let freqs = cfg.sweep_frequencies_hz();
    let (n_settle, point) = cfg.sweep_point();
    let per_run = run_samples(cfg);
    let total = 2 * freqs.len() as u64 * per_run;
    let done = AtomicU64::new(0);
    let fs = cfg.fs_hz();
    let jobs: Vec<(usize, usize)> = (0..freqs.len()).flat_map(|i| [(i, 0), (i, 1)]).collect();
    let runs: Vec<(Complex64, [Complex64; 2], Health, f64)> = jobs
        .par_iter()
        .with_max_len(1)
        .map(|&(i, m)| {
            let f = Nco::new(freqs[i], fs, 0.0)?.f_hz();
            let p = run_board(cfg, f, m);
            let mut board = Board::<f64>::new(&p, &[0.0], &[(2 * i + m) as u64])?;
            let last = AtomicU64::new(0);
            let report = |n: u64| {
                let prev = last.swap(n, Ordering::Relaxed);
                let all = done.fetch_add(n - prev, Ordering::Relaxed) + n - prev;
                progress(all, total);
            };
            let out = board.run(n_settle, &[point], RunOptions::default(), &report)?;
            report(per_run);
            let chain = ChainResponse::new(&p)?;
            let divide = drive_phasor(cfg, m)
                * cfg.device.transduction_a_s_per_m
                * chain.tia(f)
                * chain.lowpass(0.0)
                * chain.dac_hold(f);
            let lane = out.lanes[0];
            Ok((divide, lane.z, lane.health, f))
        })
        .collect::<Result<_, SweepError>>()?;
    let mut points: Vec<ResponsePoint> = runs
        .chunks(2)
        .map(|r| {
            let z = [r[0].1, r[1].1];
            let chain = [r[0].0, r[1].0];
            ResponsePoint {
                freq_hz: r[0].3,
                response: core::array::from_fn(|m| z[m].map(|v| v / chain[m])),
                z,
                chain,
                health: [r[0].2, r[1].2],
            }
        })
        .collect();
    let (problems, warnings) = check_points(cfg, &mut points);
    let fs_out = cfg.fs_out_hz();
    Ok(SteppedSine {
        points,
        settle_s: n_settle as f64 / fs_out,
        average_s: point.window.span() / fs_out,
        point_samples: total,
        problems,
        warnings,
    })
}

/// Refuses what no signal supports (a dead DAC or ADC on the driven mode, a driven phasor of
/// exactly 0, a value that is not finite): its response becomes NaN and a problem is listed.
/// A cross-coupling of exactly 0 is kept (an uncoupled device at rest has none), unless the
/// ADC of the mode read put out only zeros: then it is below the ADC's resolution, NaN, and a
/// warning says so. Clipping is a warning.
fn check_points(cfg: &Config, points: &mut [ResponsePoint]) -> (Vec<String>, Vec<String>) {
    let mut problems = Vec::new();
    let mut total = Health::default();
    let mut unresolved = [[0usize; 2]; 2];
    let b = &cfg.board;
    let zero = Complex64::new(0.0, 0.0);
    let nan = Complex64::new(f64::NAN, f64::NAN);
    for p in points.iter_mut() {
        for m in 0..2 {
            let h = p.health[m];
            total.add(&h);
            let all = |n: u64| h.samples > 0 && n == h.samples;
            let adc_dead = |k: usize| b.adc_bits.is_some() && all(h.adc_zero[k]);
            let dac = (b.dac_bits.is_some() && all(h.dac_zero[m])).then(|| {
                let key = ["drive.f1", "drive.f2"][m];
                format!(
                    "the DAC put out every sample of drive {} as 0 ({key} is below half an LSB \
                     of board.dac_full_scale / 2^(board.dac_bits - 1))",
                    m + 1
                )
            });
            // Why the driven response has no signal, if it has none.
            let driven = if let Some(d) = &dac {
                Some(d.clone())
            } else if adc_dead(m) {
                Some(format!(
                    "the ADC put out every sample of mode {} as 0 (the TIA output is below half \
                     an LSB)",
                    m + 1
                ))
            } else if p.z[m][m] == zero {
                Some(format!(
                    "mode {}'s read-out averaged to exactly 0 (no signal reached the mixer)",
                    m + 1
                ))
            } else {
                None
            };
            for (k, r) in p.response[m].iter_mut().enumerate() {
                let why = if k == m {
                    driven.clone()
                } else {
                    if dac.is_none() && adc_dead(k) {
                        unresolved[m][k] += 1;
                        *r = nan;
                    }
                    dac.clone()
                };
                // A cross reading below the ADC's resolution is already NaN (a warning).
                let fine = (r.re.is_finite() && r.im.is_finite()) || (k != m && adc_dead(k));
                let why = why.or_else(|| {
                    (!fine).then(|| {
                        format!(
                            "the response is not a finite number ({r}): the chain's values \
                             overflowed or underflowed"
                        )
                    })
                });
                if let Some(w) = why {
                    problems.push(format!(
                        "{} Hz, mode {} driven, mode {} read: no response: {w}",
                        p.freq_hz,
                        m + 1,
                        k + 1
                    ));
                    *r = nan;
                }
            }
        }
    }
    let mut warnings = Vec::new();
    for (m, row) in unresolved.iter().enumerate() {
        for (k, &n) in row.iter().enumerate() {
            if n > 0 {
                warnings.push(format!(
                    "at {n} frequencies the ADC put out every sample of mode {} as 0 while mode {} was driven: the cross-coupling is below the ADC's resolution and is written as NaN",
                    k + 1,
                    m + 1
                ));
            }
        }
    }
    let pct = |n: u64| 100.0 * n as f64 / total.samples.max(1) as f64;
    for (what, counts, setting) in [
        ("the DAC clipped", total.dac_clipped, "board.dac_full_scale"),
        (
            "the TIA sat on its rails for",
            total.tia_railed,
            "board.tia_rail_v",
        ),
        (
            "the ADC clipped",
            total.adc_clipped,
            "board.adc_full_scale_v",
        ),
    ] {
        for (k, &n) in counts.iter().enumerate() {
            if n > 0 {
                warnings.push(format!(
                    "{what} {n} of {} samples ({:.3} %) of mode {} over the sweep: raise {setting} (clipping distorts the response)",
                    total.samples,
                    pct(n),
                    k + 1
                ));
            }
        }
    }
    (problems, warnings)
}
