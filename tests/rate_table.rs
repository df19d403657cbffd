//! A sinusoidal rate table: the phase follows Omega through a first-order low-pass with time
//! constant tau = 2Q/w0 and DC gain 2 Q lambda / w0 (THEORY.md section 3). At a small
//! amplitude the emulated phase amplitude and lag match that model.
#![allow(clippy::needless_range_loop)] // mode indices address parallel arrays

mod common;
use common::*;
use gyroemu::config::parse_config;
use std::f64::consts::PI;

#[test]
fn phase_amplitude_and_lag_follow_the_mechanical_low_pass() {
    let (f0, q, table_hz, amp_dps) = (15e3, 36_000.0, 0.5, 1.0);
    let text = format!(
        r#"
[device]
f0_hz = {f0}
q = {q}
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
[board]
fs_hz = 240000.0
tia_pole_hz = 60000.0
lpf_cutoff_hz = 200.0
decimation = 100
[experiment]
kind = "coriolis"
rate_table = "sinusoid"
table_freq_hz = {table_hz}
rates_dps = [{amp_dps}]
average_s = 4.0
"#
    );
    let cfg = parse_config(&text).unwrap();
    cfg.validate().unwrap();
    let p = &run(&cfg).points[0];
    let w0 = 2.0 * PI * f0;
    let tau = 2.0 * q / w0;
    let wt = 2.0 * PI * table_hz * tau;
    let expect_deg = (2.0 * q / w0) * amp_dps / (1.0 + wt * wt).sqrt();
    let lag = p.table_lag_deg.unwrap();
    for k in 0..2 {
        let rel = p.phase_deg[k] / expect_deg - 1.0;
        // The first-order envelope model neglects terms of order 1/Q and theta^2/3.
        assert!(
            rel.abs() < 2e-3,
            "mode {}: {} vs {expect_deg} deg",
            k + 1,
            p.phase_deg[k]
        );
        assert!(
            (lag[k] - wt.atan().to_degrees()).abs() < 0.05,
            "lag {} vs {}",
            lag[k],
            wt.atan().to_degrees()
        );
    }
    // Far above the corner the phase is much smaller than a constant rate would give.
    let constant = theta_deg(f0, q, 1.0, 1.0, 1.0, amp_dps)[0];
    assert!(p.phase_deg[0] < 0.5 * constant);
}

/// At Q = 5, 3e5 deg/s and 2 Hz the time-varying plant step's second-order expansion in the
/// rate shows (it was 5.8 mdeg with the validation quoting 2.5e-5): the hold rule's exact figure
/// of the board's own recursion, which includes the step, states what the run reads, and both
/// fall as fs^-2 (the step's error is third order in Ts per step over tau/Ts steps).
#[test]
fn a_fast_rate_table_states_its_plant_steps_error_which_falls_as_fs_squared() {
    let mut errs = Vec::new();
    for fs in [240_000.0, 960_000.0] {
        let text = format!(
            r#"
[device]
f0_hz = 15000.0
q = 5.0
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
[board]
fs_hz = {fs}
tia_pole_hz = 60000.0
lpf_cutoff_hz = 200.0
decimation = 100
[experiment]
kind = "coriolis"
rate_table = "sinusoid"
table_freq_hz = 2.0
rates_dps = [300000.0]
average_s = 1.0
"#
        );
        let cfg = parse_config(&text).unwrap();
        let w = cfg.validate().unwrap();
        let hold = w
            .iter()
            .find(|w| w.contains("zero-order hold"))
            .unwrap_or_else(|| panic!("{w:?}"));
        let stated: f64 = {
            let rest = &hold[hold.find("by up to ").unwrap() + "by up to ".len()..];
            rest[..rest.find(" mdeg").unwrap()].parse().unwrap()
        };
        let p = &run(&cfg).points[0];
        let e = ((p.phase_deg[0] - p.theory_deg[0]) * 1e3).abs();
        assert!(
            (e - stated).abs() <= 1e-3 * e + 1e-4,
            "{e} mdeg read against {stated} stated"
        );
        errs.push(e);
    }
    let ratio = errs[0] / errs[1];
    assert!((12.0..20.0).contains(&ratio), "{errs:?}");
}
