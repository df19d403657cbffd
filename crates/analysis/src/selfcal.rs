//! Self-calibration (the point of the method): the Coriolis scale factor predicted from the
//! rotating excitation alone (phase slope times lambda), checked, as a lab would, against the
//! virtual rate table on the same emulated board. Both sweeps run sample by sample through
//! `run_sweep`; the analyses (averaging time, Allan deviation, drift) are in `selfcal_analyses`.

use crate::selfcal_combined::{combined_selfcal, CombinedSelfcal};
pub use crate::slope_fit::{linearised_slope, SlopeFit};
use gyroemu_config::{Config, ConfigError, ExperimentKind, PllConfig, RateTable};
use gyroemu_experiment::fit::{fit_line, t95};
use gyroemu_experiment::{
    finish_sweep, fit_readings, run_sweep_with, Progress, SweepError, SweepOptions, SweepResult,
};
use serde::Serialize;

/// Self-calibration of one mode.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ModeSelfcal {
    /// Rotating-excitation slope (I/Q major-axis estimator), deg per deg/s.
    pub rotating: SlopeFit,
    /// The same from the paper's single real I channel.
    pub rotating_paper_i: SlopeFit,
    /// Coriolis slope measured on the virtual rate table.
    pub coriolis: SlopeFit,
    /// Predicted Coriolis slope: lambda times the rotating slope.
    pub predicted_deg_per_dps: f64,
    /// Predicted over measured, minus one.
    pub relative_error: f64,
    /// Half-width of the 95 % confidence interval of `relative_error`.
    pub relative_error_ci95: f64,
    /// The same estimator applied to the exact continuous-time theory of both sweeps at the
    /// same rates (what the imperfections alone leave, without noise or board effects).
    pub relative_error_theory: f64,
    /// The same prediction from the paper's single channel, and its error.
    pub predicted_paper_i_deg_per_dps: f64,
    pub relative_error_paper_i: f64,
    /// Small-angle theory of the Coriolis slope for an ideal device: 2 Q lambda / w0 times
    /// the drive ratio of the other mode over this one.
    pub theory_coriolis_deg_per_dps: f64,
}

fn rates_of(r: &SweepResult) -> Vec<f64> {
    r.points.iter().map(|p| p.rate_dps).collect()
}

/// Combines the rotating and Coriolis sweeps of one mode.
pub fn mode_selfcal(cfg: &Config, rot: &SweepResult, cor: &SweepResult, k: usize) -> ModeSelfcal {
    let lambda = cfg.device.angular_gain;
    let rates = rates_of(rot);
    let rot_phase: Vec<f64> = rot.points.iter().map(|p| p.phase_deg[k]).collect();
    let paper: Vec<f64> = rot
        .points
        .iter()
        .map(|p| p.paper_i_deg.map_or(f64::NAN, |v| v[k]))
        .collect();
    let cor_rates = rates_of(cor);
    let cor_phase: Vec<f64> = cor.points.iter().map(|p| p.phase_deg[k]).collect();
    let mut rotating = linearised_slope(&rates, &rot_phase);
    let mut rotating_paper_i = linearised_slope(&rates, &paper);
    let mut coriolis = linearised_slope(&cor_rates, &cor_phase);
    // The plain line's R² on the readings' own branch, as a sweep's summary fits them.
    let (rot_cfg, cor_cfg) = sweep_configs(cfg);
    let on_branch = |c: &Config, xs: &[f64], ys: &[f64]| fit_line(xs, &fit_readings(c, xs, ys, k));
    rotating.plain_fit = on_branch(&rot_cfg, &rates, &rot_phase);
    rotating_paper_i.plain_fit = on_branch(&rot_cfg, &rates, &paper);
    // A Coriolis phase is known within a whole turn: a step of more than a quarter turn
    // between rates had been moved a half turn (slope -0.0044 for +0.0092).
    coriolis.plain_fit = on_branch(&cor_cfg, &cor_rates, &cor_phase);
    let theory = |r: &SweepResult| {
        let ph: Vec<f64> = r.points.iter().map(|p| p.theory_deg[k]).collect();
        linearised_slope(&rates_of(r), &ph).slope_deg_per_dps
    };
    let relative_error_theory = lambda * theory(rot) / theory(cor) - 1.0;
    let predicted = lambda * rotating.slope_deg_per_dps;
    let measured = coriolis.slope_deg_per_dps;
    let ratio = predicted / measured;
    let ci = t95(rotating.dof.min(coriolis.dof))
        * ratio
        * rotating.rel_std_err().hypot(coriolis.rel_std_err());
    let predicted_paper = lambda * rotating_paper_i.slope_deg_per_dps;
    let d = &cfg.device;
    let q2 = d.q_mode2.unwrap_or(d.q);
    // A mode's Coriolis phase is driven by the other mode's response: 2 lambda Omega Q_other
    // F_other / (F_own w0) at small angles (docs/selfcal.md).
    let (own, other, q_other) = if k == 0 {
        (cfg.drive.f1, cfg.f2(), q2)
    } else {
        (cfg.f2(), cfg.drive.f1, d.q)
    };
    let w0 = core::f64::consts::TAU * d.f0_hz;
    ModeSelfcal {
        rotating,
        rotating_paper_i,
        coriolis,
        predicted_deg_per_dps: predicted,
        relative_error: ratio - 1.0,
        relative_error_ci95: ci.abs(),
        relative_error_theory,
        predicted_paper_i_deg_per_dps: predicted_paper,
        relative_error_paper_i: predicted_paper / measured - 1.0,
        theory_coriolis_deg_per_dps: 2.0 * q_other * d.angular_gain / w0 * other / own,
    }
}

/// The two sweeps' configs derived from the user's: the same board and rates, one rotating
/// and one on a constant-rate table; dumps off.
pub fn sweep_configs(cfg: &Config) -> (Config, Config) {
    let mut rot = cfg.clone();
    rot.experiment.kind = ExperimentKind::Rotating;
    rot.experiment.rate_table = RateTable::Constant;
    rot.experiment.table_freq_hz = None;
    rot.dump = None;
    let mut cor = rot.clone();
    cor.experiment.kind = ExperimentKind::Coriolis;
    // Rate 0 has no sidebands to read: the rotating sweep leaves it out (the Coriolis sweep
    // keeps it; its zero-rate reference is emulated anyway).
    rot.experiment.rates_dps.retain(|&r| r != 0.0);
    (rot, cor)
}

/// The device at a temperature offset: f0 (and the mode-2 offset) and Q scaled by their
/// temperature coefficients.
pub fn drifted(cfg: &Config, delta_t_k: f64) -> Config {
    let s = cfg.selfcal.clone().unwrap_or_default();
    let f_scale = 1.0 + s.f0_tc_ppm_per_k * 1e-6 * delta_t_k;
    let q_scale = 1.0 + s.q_tc_ppm_per_k * 1e-6 * delta_t_k;
    let mut c = cfg.clone();
    c.device.f0_hz *= f_scale;
    c.device.mode2_f0_offset_hz *= f_scale;
    c.device.q *= q_scale;
    c.device.q_mode2 = c.device.q_mode2.map(|q| q * q_scale);
    // The board does not drift: its carrier stays where it was set (open loop); a PLL can
    // lock it onto the drifted resonance (`drift_analysis`).
    c.drive.carrier_hz = Some(cfg.carrier_hz());
    c
}

/// The config whose `[pll]` designs the drift scenario's loop: the user's, or the default
/// loop (derived natural frequency and lock time) on the nominal device; as selfcal reads
/// the config ([`as_read`]), so that whether the loop fits is not judged on what selfcal
/// ignores (a rotating config's rate 0 had dropped the tracked half).
pub fn drift_pll_design(cfg: &Config) -> Config {
    let mut d = as_read(cfg);
    if d.pll.is_none() {
        d.pll = Some(PllConfig {
            natural_hz: None,
            damping: core::f64::consts::FRAC_1_SQRT_2,
            lock_s: None,
            mode: 1,
        });
        d.resolve();
    }
    d
}

/// `cfg` as `selfcal` (and a lot's device) reads it: what it ignores left out (`[dump]`, the
/// rate table's form and frequency) and, for a rotating config, rate 0, which its rotating
/// sweep leaves out. So an unused part never refuses it (a `[dump]` naming a rate the config
/// no longer lists did), while a rule of the kind the config names keeps its plain wording;
/// the other kind's sweep is judged as such.
pub fn as_read(cfg: &Config) -> Config {
    let (rot, cor) = sweep_configs(cfg);
    match cfg.experiment.kind {
        ExperimentKind::Rotating => rot,
        ExperimentKind::Coriolis => cor,
    }
}

/// `e`'s problems, of a config whose rates are `cfg`'s without rate 0 (the rotating sweep's,
/// or a rotating config as selfcal reads it), keyed by the index in `cfg`'s own list: a
/// refusal of `rates_dps = [0.0, 25.0, 50.0, 1e5]` named `experiment.rates_dps[2]` (50 in
/// the file) for the 1e5 at index 3.
fn at_users_rate(cfg: &Config, e: ConfigError) -> ConfigError {
    let users: Vec<usize> = (0..cfg.experiment.rates_dps.len())
        .filter(|&i| cfg.experiment.rates_dps[i] != 0.0)
        .collect();
    let list: Vec<ConfigError> = e
        .problems()
        .into_iter()
        .map(|mut p| {
            let index = p
                .key
                .as_deref()
                .and_then(|k| k.strip_prefix("experiment.rates_dps["))
                .and_then(|k| k.strip_suffix(']'))
                .and_then(|j| j.parse::<usize>().ok());
            if let Some(&i) = index.and_then(|j| users.get(j)) {
                p.key = Some(format!("experiment.rates_dps[{i}]"));
            }
            p
        })
        .collect();
    ConfigError::from_problems(list).unwrap_or(e)
}

/// Validates every config `selfcal` will run (the config as it reads it, [`as_read`], both
/// sweeps, and each drifted device) before any sample is computed; returns the config's
/// warnings, then those the runs it derives add, or every problem in one error (the sweeps'
/// under keys the config's own problems do not name; the analyses' configs only once the
/// config is valid).
pub fn validate_selfcal(cfg: &Config) -> Result<Vec<String>, ConfigError> {
    // Every config with the rotating sweep's rates (rate 0 left out) has its problems keyed
    // by the index in the user's list.
    let users = |r: Result<Vec<String>, ConfigError>| r.map_err(|e| at_users_rate(cfg, e));
    // A config as selfcal reads it has the rotating sweep's rates only when it is rotating.
    let read = |c: &Config| match cfg.experiment.kind {
        ExperimentKind::Rotating => users(c.validate()),
        ExperimentKind::Coriolis => c.validate(),
    };
    let base = read(&as_read(cfg));
    // A slope needs two distinct rates besides zero, and its 95 % interval a third (the
    // residual scatter has points - 2 degrees of freedom).
    let mut distinct: Vec<f64> = Vec::new();
    for &r in &cfg.experiment.rates_dps {
        if r != 0.0 && !distinct.contains(&r) {
            distinct.push(r);
        }
    }
    let rates = (distinct.len() < 3).then(|| {
        ConfigError::key(
            "experiment.rates_dps",
            format!("{:?}", cfg.experiment.rates_dps),
            format!(
                "selfcal needs at least 3 distinct non-zero rates (here {}): 2 for the slope of each sweep and a third for its 95 % confidence interval",
                distinct.len()
            ),
        )
    });
    let base = match (base, rates) {
        (Ok(w), None) => w,
        // Its own problems first; the rates rule only if it names another key's problem; then
        // those of the two sweeps under keys not named yet, so that every problem is in one
        // message (fixing the low-pass used to reveal the sweeps' refusal only afterwards).
        (base, rates) => {
            let mut list = base.err().map(|e| e.problems()).unwrap_or_default();
            if !list
                .iter()
                .any(|p| p.key.as_deref() == Some("experiment.rates_dps"))
            {
                list.extend(rates);
            }
            let (rot, cor) = sweep_configs(cfg);
            for (what, r) in [
                ("rotating sweep", users(rot.validate())),
                ("rate-table sweep", cor.validate()),
            ] {
                for p in r.err().map(|e| e.problems()).unwrap_or_default() {
                    if !list.iter().any(|q| q.key == p.key) {
                        list.push(p.map_details(|d| format!("{d} (in the {what} of selfcal)")));
                    }
                }
            }
            return Err(ConfigError::from_problems(list).expect("a problem was found"));
        }
    };
    // Each added warning with the runs it holds for: the same rule states different sizes
    // on different runs, and an unnamed list of them reads as one warning said four times.
    let mut warnings: Vec<(String, Vec<String>)> = Vec::new();
    let mut problems = Vec::new();
    let (rot, cor) = sweep_configs(cfg);
    let mut add = |what: &str, r: Result<Vec<String>, ConfigError>| match r {
        Ok(w) => {
            for x in w {
                if base.contains(&x) {
                    continue;
                }
                match warnings.iter_mut().find(|(t, _)| *t == x) {
                    Some((_, runs)) if !runs.iter().any(|r| r == what) => runs.push(what.into()),
                    Some(_) => {}
                    None => warnings.push((x, vec![what.into()])),
                }
            }
        }
        Err(e) => problems.push(e.map_details(|d| format!("{d} (in the {what} of selfcal)"))),
    };
    add("rotating sweep", users(rot.validate()));
    add("rate-table sweep", cor.validate());
    if let Some(s) = &cfg.selfcal {
        if !s.drift_delta_t_k.is_empty() && cfg.pll.is_none() {
            // The PLL-tracked half of the drift scenario locks with the default loop; where
            // none fits the board, that half is left out (null), and said so.
            if let Err(e) = read(&drift_pll_design(cfg)) {
                add("drift scenario", Ok(vec![format!(
                    "selfcal.drift_delta_t_k: the drift scenario's PLL-tracked half is left out (null): the default carrier PLL does not fit this board ({}); add a [pll] section that fits to get it",
                    e.problems().iter().map(|p| p.to_string()).collect::<Vec<_>>().join("; ")
                )]));
            }
        }
        for &dt in &s.drift_delta_t_k {
            let (r, c) = sweep_configs(&drifted(cfg, dt));
            let what = format!("drift scenario at dT = {dt:+} K");
            add(&what, users(r.validate()));
            add(&what, c.validate());
        }
        if let Some(t) = s.tau_max_s {
            let mut r = rot.clone();
            r.experiment.average_s = t;
            // That run's averaging time is selfcal.tau_max_s: its refusal names the key set.
            let v = users(r.validate()).map_err(|e| {
                let list = e
                    .problems()
                    .into_iter()
                    .map(|mut p| {
                        if p.key.as_deref() == Some("experiment.average_s") {
                            p.key = Some("selfcal.tau_max_s".into());
                        }
                        p
                    })
                    .collect();
                ConfigError::from_problems(list).unwrap_or(e)
            });
            add("averaging-time analysis", v);
        }
    }
    match ConfigError::from_problems(problems) {
        Some(e) => Err(e),
        None => Ok(base
            .into_iter()
            .chain(
                warnings
                    .into_iter()
                    .map(|(w, runs)| format!("{w} (in the {} of selfcal)", runs.join(", the "))),
            )
            .collect()),
    }
}

/// Both sweeps and their comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct SelfcalCore {
    pub angular_gain: f64,
    /// Per mode (mode 1 is the headline).
    pub modes: [ModeSelfcal; 2],
    /// Both modes together (their geometric mean), free of the drive-gain ratio and the Q
    /// mismatch.
    pub combined: CombinedSelfcal,
    pub rotating: SweepResult,
    pub coriolis: SweepResult,
}

impl SelfcalCore {
    /// Why the two-mode estimate is null, when it is: a sweep whose two modes' slopes differ
    /// in sign (or one is not finite) has no common scale factor. It was null with no word
    /// (noise burying the rate table's slopes read -0.061 and +0.04).
    pub fn combined_warning(&self) -> Option<String> {
        let sweeps = [
            (
                "rotating",
                &self.combined.rotating,
                self.modes.map(|m| m.rotating),
            ),
            (
                "rate-table",
                &self.combined.coriolis,
                self.modes.map(|m| m.coriolis),
            ),
        ];
        let null: Vec<String> = sweeps
            .iter()
            .filter(|(_, c, _)| c.slope_deg_per_dps.is_nan())
            .map(|(what, _, m)| {
                format!(
                    "the {what} sweep's (mode 1 {:.6e}, mode 2 {:.6e} deg per deg/s)",
                    m[0].slope_deg_per_dps, m[1].slope_deg_per_dps
                )
            })
            .collect();
        (!null.is_empty()).then(|| {
            format!(
                "the two-mode estimate (combined_relative_error and the combined slopes) is null: the two modes' slopes of {} differ in sign or are not finite, so they share no scale factor; read each mode's own",
                null.join(" and of ")
            )
        })
    }
}

/// Runs the rotating sweep and the rate-table sweep of `cfg` and compares them, their lane
/// groups sized for `group_threads` ([`SweepOptions::group_threads`]).
pub fn run_selfcal_core(
    cfg: &Config,
    rot_progress: Progress,
    cor_progress: Progress,
    group_threads: Option<usize>,
) -> Result<SelfcalCore, SweepError> {
    let (rot_cfg, cor_cfg) = sweep_configs(cfg);
    let sweep = |c: &Config, progress: Progress| {
        let opts = SweepOptions {
            group_threads,
            ..Default::default()
        };
        finish_sweep(c, &run_sweep_with(c, progress, None, opts)?.lanes)
    };
    // Side by side: each sweep may be a single lane group (one thread), and neither needs
    // the other. When one fails the other still runs to its end; a rotating failure is the
    // one reported, as in sequence.
    let (rotating, coriolis) = rayon::join(
        || sweep(&rot_cfg, rot_progress),
        || sweep(&cor_cfg, cor_progress),
    );
    Ok(SelfcalCore::from_sweeps(cfg, rotating?, coriolis?))
}

impl SelfcalCore {
    /// Compares the rotating and the rate-table sweeps of `cfg` (from [`sweep_configs`]).
    pub fn from_sweeps(cfg: &Config, rotating: SweepResult, coriolis: SweepResult) -> Self {
        Self {
            angular_gain: cfg.device.angular_gain,
            modes: [0, 1].map(|k| mode_selfcal(cfg, &rotating, &coriolis, k)),
            combined: combined_selfcal(cfg, &rotating, &coriolis),
            rotating,
            coriolis,
        }
    }
}
