//! `selfcal` as one call: the two sweeps, then the analyses the config's `[selfcal]` section
//! asks for, each reported as its own task.

use crate::selfcal::{sweep_configs, SelfcalCore};
use crate::selfcal_analyses::{
    allan_analysis, drift_analysis_held, drift_tracking_design, tau_analysis, AllanResult,
    DriftPoint, TauPoint,
};
use gyroemu_config::Config;
use gyroemu_experiment::{
    lock_work, resolve_lock, run_sweep, sweep_work, CarrierLock, Reporter, SweepError, Work,
};

/// Everything `selfcal` measured.
#[derive(Clone, Debug)]
pub struct SelfcalReport {
    /// The two sweeps and their comparison.
    pub core: SelfcalCore,
    /// Allan deviation of the zero-rate output (`selfcal.allan_record_s`).
    pub allan: Option<AllanResult>,
    /// Error against averaging time (`selfcal.tau_max_s`).
    pub taus: Option<Vec<TauPoint>>,
    /// Drift scenario (`selfcal.drift_delta_t_k`).
    pub drift: Option<Vec<DriftPoint>>,
    /// How the carrier PLL locked, with a `[pll]`.
    pub lock: Option<CarrierLock>,
}

impl SelfcalReport {
    /// The run's warnings: both sweeps', the Allan record's readings', then each drift
    /// temperature whose tracking lock did not hold.
    pub fn warnings(&self) -> Vec<String> {
        let allan = self.allan.iter().flat_map(|a| a.warnings());
        let drift = self
            .drift
            .iter()
            .flatten()
            .filter_map(|p| p.pll_warning.clone());
        self.core
            .rotating
            .warnings
            .iter()
            .chain(&self.core.coriolis.warnings)
            .cloned()
            .chain(self.core.combined_warning())
            .chain(allan)
            .chain(drift)
            .collect()
    }
}

/// What one analysis gives: its result, or `None` when the config does not ask for it.
type Done<T> = Result<Option<T>, SweepError>;

/// Runs the rotating sweep and the rate-table sweep of `cfg` (validated, e.g. by
/// `validate_selfcal`), compares them, then runs each analysis the config asks for.
pub fn run_selfcal(cfg: &Config, reporter: &dyn Reporter) -> Result<SelfcalReport, SweepError> {
    // With a [pll], both sweeps run at the carrier it locks (the drift scenario locks again at
    // each temperature).
    let (held, lock) = resolve_lock(cfg)?;
    if let Some(l) = &lock {
        reporter.note(&l.note());
    }
    let (rot_cfg, cor_cfg) = sweep_configs(&held);
    let p = reporter.task("rotating sweep");
    let rotating = run_sweep(&rot_cfg, &|d, t| p.update(d, t), None)?;
    p.finish(Some(rotating.point_samples));
    let p = reporter.task("rate-table sweep");
    let coriolis = run_sweep(&cor_cfg, &|d, t| p.update(d, t), None)?;
    p.finish(Some(coriolis.point_samples));
    let core = SelfcalCore::from_sweeps(&held, rotating, coriolis);
    let m = core.modes[0];
    let sc = cfg.selfcal.clone().unwrap_or_default();
    // The analyses run side by side in one pool: the averaging-time run's two long lane
    // groups, the Allan record's one group and the drift scenario's many short sweeps, so no
    // thread waits for another analysis to end (each result has the bits it has alone). Their
    // lane groups are sized for a third of the threads each (reproduce does the same for its
    // experiments): as wide as the CPU runs, the most points per CPU-second.
    let share = Some((rayon::current_num_threads() / 3).max(1));
    let allan = || -> Done<AllanResult> {
        let Some(t) = sc.allan_record_s else {
            return Ok(None);
        };
        let p = reporter.task("allan record");
        // The rate-table slope's own 95 % error, relative, in every interval of the fit.
        let c = &m.coriolis;
        let rel =
            gyroemu_experiment::fit::t95(c.dof) * c.std_err_deg_per_dps / c.slope_deg_per_dps.abs();
        let a = allan_analysis(&held, t, c.slope_deg_per_dps, rel, &|d, n| p.update(d, n))?;
        p.finish(None);
        Ok(Some(a))
    };
    let taus = || -> Done<Vec<TauPoint>> {
        let Some(t) = sc.tau_max_s else {
            return Ok(None);
        };
        let p = reporter.task("averaging-time run");
        let r = tau_analysis(
            &held,
            t,
            &m.coriolis,
            &core.combined.coriolis,
            share,
            &|d, n| p.update(d, n),
        )?;
        p.finish(None);
        Ok(Some(r))
    };
    let drift = || -> Done<Vec<DriftPoint>> {
        if sc.drift_delta_t_k.is_empty() {
            return Ok(None);
        }
        let p = reporter.task("drift scenario");
        let d = drift_analysis_held(
            cfg,
            &held,
            &sc.drift_delta_t_k,
            m.coriolis.slope_deg_per_dps,
            share,
            &|d, n| p.update(d, n),
        )?;
        p.finish(None);
        Ok(Some(d))
    };
    let (taus, (allan, drift)) = rayon::join(taus, || rayon::join(allan, drift));
    let (allan, taus, drift) = (allan?, taus?, drift?);
    Ok(SelfcalReport {
        core,
        allan,
        taus,
        drift,
        lock,
    })
}

/// What `selfcal` on `cfg` will emulate: both sweeps, then the Allan record (four streams),
/// the averaging-time run and, per drift temperature, both sweeps open loop and, when the
/// drift loop fits the board, both again PLL-tracked (the same windows at another carrier;
/// the tracking loop's own lock runs, of a few of its time constants, are not counted). A
/// `[pll]`'s lock runs first, and once more for the drift scenario.
pub fn selfcal_work(cfg: &Config) -> Work {
    let (rot, cor) = sweep_configs(cfg);
    let mut w = lock_work(cfg).plus(sweep_work(&rot)).plus(sweep_work(&cor));
    let sc = cfg.selfcal.clone().unwrap_or_default();
    if let Some(t) = sc.allan_record_s {
        let mut a = cor.clone();
        a.experiment.rates_dps = vec![0.0; 4];
        a.experiment.average_s = t;
        let m = sweep_work(&a);
        // Four lanes of one group (the zero rate is listed, so no reference is added).
        w = w.plus(Work { points: 4, ..m });
    }
    if let Some(t) = sc.tau_max_s {
        let mut r = rot.clone();
        r.experiment.average_s = t;
        w = w.plus(sweep_work(&r));
    }
    // The drift scenario runs on the carrier locked above; where its tracking loop fits,
    // each temperature locks that loop first (the design's `lock_s`, on the same board
    // rates), then runs its sweeps at the open-loop carrier and at the locked one.
    let design = drift_tracking_design(cfg);
    let cases = if design.is_some() { 2 } else { 1 };
    for &dt in &sc.drift_delta_t_k {
        let (r, c) = sweep_configs(&crate::selfcal::drifted(cfg, dt));
        let pair = sweep_work(&r).plus(sweep_work(&c));
        for _ in 0..cases {
            w = w.plus(pair);
        }
        if let Some(d) = &design {
            w = w.plus(lock_work(d));
        }
    }
    w
}
