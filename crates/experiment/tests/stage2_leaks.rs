//! Stage-2 leaks computed before the read-out: the same results, taken only for the very point
//! (window, settling, chain rates) they were computed for.

use gyroemu_board::ChainResponse;
use gyroemu_config::{presets::preset, Config, ExperimentKind};
use gyroemu_core::Complex64;
use gyroemu_experiment::{
    finish_sweep, finish_sweep_with, run_sweep_with, Stage2Leaks, SweepOptions,
};

const RATES: [f64; 4] = [200.0, 250.0, 300.0, 350.0];

/// Four rotating points, windows of about a second (a fractional end sample each, so every
/// leak is non-zero).
fn rotating() -> Config {
    let mut cfg = preset("m2tfg-rotating").unwrap();
    cfg.experiment.kind = ExperimentKind::Rotating;
    cfg.experiment.rates_dps = RATES.to_vec();
    cfg.experiment.average_s = 1.1;
    cfg.experiment.settle_s = Some(0.02);
    cfg
}

fn chain(cfg: &Config) -> ChainResponse {
    ChainResponse::new(&cfg.board_params()).unwrap()
}

#[test]
fn kept_leaks_give_the_read_outs_bits() {
    let cfg = rotating();
    let run = run_sweep_with(&cfg, &|_, _| {}, None, SweepOptions::default()).unwrap();
    let plain = finish_sweep(&cfg, &run.lanes).unwrap();
    let leaks = Stage2Leaks::of_sweep(&cfg).unwrap();
    assert_eq!(leaks.len(), RATES.len());
    let ch = chain(&cfg);
    for r in RATES {
        let kept = leaks.get(&ch, &cfg.plan_point(r), cfg.n_settle_out());
        let direct = ch
            .stage2_leak(&cfg.plan_point(r), cfg.n_settle_out())
            .unwrap();
        assert_eq!(kept, Some(direct), "{r} deg/s");
        assert!(direct.norm() > 0.0, "{r} deg/s: the window should leak");
    }
    assert_eq!(finish_sweep_with(&cfg, &run.lanes, &leaks).unwrap(), plain);
}

#[test]
fn a_kept_leak_is_taken_for_its_point_and_no_other() {
    let cfg = rotating();
    let run = run_sweep_with(&cfg, &|_, _| {}, None, SweepOptions::default()).unwrap();
    let plain = finish_sweep(&cfg, &run.lanes).unwrap();
    // A leak far from the true one (|W| is about 1e-3 here): the point reads differently.
    let bogus = Stage2Leaks::default().with_entry(
        &chain(&cfg),
        cfg.plan_point(250.0),
        cfg.n_settle_out(),
        Complex64::new(0.3, 0.2),
    );
    let r = finish_sweep_with(&cfg, &run.lanes, &bogus).unwrap();
    for (a, b) in r.points.iter().zip(&plain.points) {
        if a.rate_dps == 250.0 {
            assert_ne!(a.phase_deg, b.phase_deg);
        } else {
            assert_eq!(a, b);
        }
    }
}

#[test]
fn leaks_of_another_window_settling_or_rate_are_not_taken() {
    let cfg = rotating();
    let ch = chain(&cfg);
    let n_settle = cfg.n_settle_out();
    let mut longer = cfg.clone();
    longer.experiment.average_s = 2.5;
    let mut settled = cfg.clone();
    settled.experiment.settle_s = Some(0.05);
    for other in [&longer, &settled] {
        let leaks = Stage2Leaks::of_sweep(other).unwrap();
        assert_eq!(leaks.len(), RATES.len());
        for r in RATES {
            assert_eq!(leaks.get(&ch, &cfg.plan_point(r), n_settle), None, "{r}");
        }
    }
    // And the read-out then computes its own.
    let run = run_sweep_with(&cfg, &|_, _| {}, None, SweepOptions::default()).unwrap();
    let foreign = Stage2Leaks::of_sweep(&longer).unwrap();
    assert_eq!(
        finish_sweep_with(&cfg, &run.lanes, &foreign).unwrap(),
        finish_sweep(&cfg, &run.lanes).unwrap()
    );
}

#[test]
fn a_leak_of_another_chains_rates_is_not_taken() {
    // The same point and settling on a chain of another sample rate or decimation.
    let cfg = rotating();
    let (point, n_settle) = (cfg.plan_point(250.0), cfg.n_settle_out());
    let mut decimated = cfg.clone();
    decimated.board.decimation = Some(cfg.decimation() * 2);
    let mut faster = cfg.clone();
    faster.board.fs_hz = Some(cfg.fs_hz() * 2.0);
    for other in [&decimated, &faster] {
        let leak = Complex64::new(0.3, 0.2);
        let leaks = Stage2Leaks::default().with_entry(&chain(other), point, n_settle, leak);
        assert_eq!(leaks.get(&chain(other), &point, n_settle), Some(leak));
        assert_eq!(leaks.get(&chain(&cfg), &point, n_settle), None);
    }
}

#[test]
fn sweeps_without_stage_2_keep_no_leak() {
    for name in ["m2tfg-coriolis", "m2tfg-ratetable"] {
        let leaks = Stage2Leaks::of_sweep(&preset(name).unwrap()).unwrap();
        assert!(leaks.is_empty(), "{name}");
    }
}
