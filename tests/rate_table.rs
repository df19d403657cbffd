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
