//! A production lot's devices against `selfcal` on each device's own config (bit for bit:
//! the lot adds no arithmetic of its own but the nominal-lambda prediction), and its physics:
//! a lot spread only in the drive-gain ratio has the mode-1 error F1/F2 - 1 (the Coriolis
//! phase of mode 1 scales with F2/F1, the rotating phase does not: THEORY.md eqs. 2-3 and 6),
//! one spread only in lambda has the error lambda_nominal / lambda - 1 (the calibration
//! predicts with the nominal lambda), one only in the Q mismatch has Q1/Q2 - 1 (the phasors
//! of THEORY.md section 3 with damping w0/Q_k per mode give the small-angle Coriolis phase of
//! mode 1 as 2 lambda Omega Q2 F2 / (F1 w0), while its rotating phase goes as 2 Q1 Omega / w0),
//! each to the ideal device's own error; the two-mode (combined) error cancels the drive-gain
//! ratio and the Q mismatch.

use gyroemu::analysis::montecarlo::{
    device_config, draw_device, run_device, validate_lot, DeviceResult, HEADLINE,
};
use gyroemu::analysis::run_selfcal;
use gyroemu::config::presets::preset;
use gyroemu::config::Config;
use gyroemu::experiment::Quiet;

/// The lot preset made small: Q = 200 (16 time constants in 68 ms), three rates whose half
/// periods divide the 0.2 s average, 0.1 s settling.
fn tiny() -> Config {
    let mut c = preset("m2tfg-montecarlo").unwrap();
    c.device.q = 200.0;
    c.experiment.rates_dps = vec![900.0, 1800.0, 2700.0];
    c.experiment.average_s = 0.2;
    c.experiment.settle_s = Some(0.1);
    c
}

fn device(cfg: &Config, i: u64) -> DeviceResult {
    run_device(cfg, i, None, &|_| {}).unwrap().unwrap()
}

#[test]
fn a_lot_ignores_what_selfcal_ignores() {
    // Rate 0 beside the preset's rotating `kind` and a `[dump]` at a rate not listed: `run`
    // refuses both, a lot (selfcal on each device) reads neither.
    let clean = tiny();
    assert_eq!(
        clean.experiment.kind,
        gyroemu::config::ExperimentKind::Rotating
    );
    let mut c = clean.clone();
    c.experiment.rates_dps.insert(0, 0.0);
    c.dump = Some(gyroemu::config::DumpConfig {
        rate_dps: Some(60.0),
        start_s: None,
        duration_s: None,
        nodes: None,
    });
    assert!(c.validate().is_err());
    assert_eq!(
        validate_lot(&c, &[0, 1]).unwrap(),
        validate_lot(&clean, &[0, 1]).unwrap()
    );
}

#[test]
fn each_device_equals_selfcal_on_its_own_config_bit_for_bit() {
    let cfg = tiny();
    let devices = [0u64, 5, 17];
    validate_lot(&cfg, &devices).unwrap();
    let mc = cfg.montecarlo.clone().unwrap();
    for i in devices {
        let d = device(&cfg, i);
        let own = device_config(&cfg, &draw_device(&mc, i));
        let r = run_selfcal(&own, &Quiet).unwrap().core;
        let v = |name: &str| d.value(name).unwrap().to_bits();
        for k in 0..2 {
            let m = &r.modes[k];
            let sfx = format!("mode{}", k + 1);
            assert_eq!(
                v(&format!("board_relative_error_{sfx}")),
                m.relative_error.to_bits(),
                "device {i} {sfx}"
            );
            assert_eq!(
                v(&format!("rotating_slope_{sfx}_deg_per_dps")),
                m.rotating.slope_deg_per_dps.to_bits()
            );
            assert_eq!(
                v(&format!("coriolis_slope_{sfx}_deg_per_dps")),
                m.coriolis.slope_deg_per_dps.to_bits()
            );
            // The lot's error: the same prediction with the nominal lambda.
            let nominal = cfg.device.angular_gain * m.rotating.slope_deg_per_dps
                / m.coriolis.slope_deg_per_dps
                - 1.0;
            assert_eq!(v(&format!("relative_error_{sfx}")), nominal.to_bits());
        }
        let c = &r.combined;
        assert_eq!(
            v("board_combined_relative_error"),
            c.relative_error.to_bits()
        );
        let nominal = cfg.device.angular_gain * c.rotating.slope_deg_per_dps
            / c.coriolis.slope_deg_per_dps
            - 1.0;
        assert_eq!(v("combined_relative_error"), nominal.to_bits());
        assert_eq!(v("q"), own.device.q.to_bits());
        assert_eq!(v("angular_gain"), own.device.angular_gain.to_bits());
        assert!(d.problems.is_empty(), "{:?}", d.problems);
    }
    // Without a lambda spread the lot's error is selfcal's, bit for bit.
    let mut flat = cfg.clone();
    flat.montecarlo.as_mut().unwrap().lambda_sigma_rel = 0.0;
    let d = device(&flat, 5);
    assert_eq!(
        d.value(HEADLINE).unwrap().to_bits(),
        d.value("board_relative_error_mode1").unwrap().to_bits()
    );
}

#[test]
fn a_devices_work_is_the_canonical_count_whatever_grouping_ran() {
    // Five rates of unequal windows (half periods 0.19, 0.16, 0.14, 0.12 and 0.11 s against a
    // 0.2 s average): eight lanes run them as one group, four as two packed by length, the
    // canonical count as groups of four in index order. The record must not depend on which
    // ran (it once differed between --threads 1 and 2, and between --lanes 4 and 8).
    let mut cfg = tiny();
    cfg.experiment.rates_dps = vec![950.0, 1100.0, 1300.0, 1500.0, 1700.0];
    validate_lot(&cfg, &[3]).unwrap();
    let d = device(&cfg, 3);
    let own = device_config(&cfg, &draw_device(cfg.montecarlo.as_ref().unwrap(), 3));
    let r = run_selfcal(&own, &Quiet).unwrap().core;
    assert_eq!(
        d.point_samples,
        r.rotating.point_samples + r.coriolis.point_samples
    );
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| device(&cfg, 3));
    assert_eq!(one_thread.point_samples, d.point_samples);
}

/// The tiny lot noiseless, with only `set`'s spread.
fn one_spread(set: impl Fn(&mut gyroemu::config::MonteCarloConfig)) -> Config {
    let mut c = tiny();
    c.noise = None;
    c.board.dac_bits = None;
    c.board.adc_bits = None;
    let m = c.montecarlo.as_mut().unwrap();
    m.mode_split_sigma_hz = 0.0;
    m.q_sigma_rel = 0.0;
    m.q_mismatch_sigma_rel = 0.0;
    m.drive_gain_sigma_rel = 0.0;
    m.phase_shifter_sigma_deg = 0.0;
    m.lambda_sigma_rel = 0.0;
    set(m);
    c
}

#[test]
fn drive_gain_lambda_and_q_mismatch_spreads_give_their_closed_form_errors() {
    // The ideal device's own error sets the tolerance.
    let ideal = device(&one_spread(|_| {}), 0);
    let floor = ideal.value(HEADLINE).unwrap();
    assert!(floor.abs() < 1e-5, "ideal device: {floor:e}");
    let combined_floor = ideal.value("combined_relative_error").unwrap();
    assert!(
        combined_floor.abs() < 1e-5,
        "ideal device: {combined_floor:e}"
    );
    let gain = one_spread(|m| m.drive_gain_sigma_rel = 0.01);
    let lambda = one_spread(|m| m.lambda_sigma_rel = 0.01);
    let q_mismatch = one_spread(|m| m.q_mismatch_sigma_rel = 0.01);
    for i in 0..4 {
        let d = device(&gain, i);
        let want = 1.0 / d.value("f2_over_f1").unwrap() - 1.0;
        let got = d.value(HEADLINE).unwrap();
        assert!(
            (got - want - floor).abs() < 2e-6,
            "drive gain, device {i}: {got:e} vs F1/F2 - 1 = {want:e} (+ {floor:e})"
        );
        // Mode 2 sees the inverse ratio.
        let got2 = d.value("relative_error_mode2").unwrap();
        let want2 = d.value("f2_over_f1").unwrap() - 1.0;
        assert!((got2 - want2 - floor).abs() < 2e-6, "mode 2, device {i}");
        let d = device(&lambda, i);
        let want = 1.0 / d.value("angular_gain").unwrap() - 1.0;
        let got = d.value(HEADLINE).unwrap();
        assert!(
            (got - want - floor).abs() < 2e-6,
            "lambda, device {i}: {got:e} vs lambda_nominal / lambda - 1 = {want:e} (+ {floor:e})"
        );
        // The board itself is unaffected by the lambda spread: its own error is the floor.
        let board = d.value("board_relative_error_mode1").unwrap();
        assert!((board - floor).abs() < 2e-6, "device {i}: board {board:e}");
        let d = device(&q_mismatch, i);
        let want = d.value("q").unwrap() / d.value("q_mode2").unwrap() - 1.0;
        let got = d.value(HEADLINE).unwrap();
        assert!(
            (got - want - floor).abs() < 2e-6,
            "Q mismatch, device {i}: {got:e} vs Q1/Q2 - 1 = {want:e} (+ {floor:e})"
        );
        // The two modes together: the Q mismatch and the drive-gain ratio cancel.
        for (what, d) in [("Q mismatch", d), ("drive gain", device(&gain, i))] {
            let c = d.value("combined_relative_error").unwrap();
            assert!(
                (c - combined_floor).abs() < 2e-6,
                "{what}, device {i}: combined {c:e} vs the ideal device's {combined_floor:e}"
            );
        }
    }
}
