//! Shared helpers of the accuracy tests: the closed forms of THEORY.md written out again here,
//! independently of `gyroemu::experiment::theory`, and small config builders.
#![allow(dead_code)]

use gyroemu::board::{Board, Point, Probe, RunOptions};
use gyroemu::config::{parse_config, Config};
use gyroemu::experiment::{run_sweep, SweepResult};
use gyroemu::lpf::Window;
use std::f64::consts::PI;

pub const DEG: f64 = PI / 180.0;

/// THEORY.md eqs. 2-3, in degrees.
pub fn theta_deg(f0: f64, q: f64, lambda: f64, f1: f64, f2: f64, rate_dps: f64) -> [f64; 2] {
    let x = 2.0 * q * lambda * rate_dps * DEG / (2.0 * PI * f0);
    [(x * f2 / f1).atan() / DEG, (x * f1 / f2).atan() / DEG]
}

/// THEORY.md section 4, exact plant psi (major-axis estimator), degrees.
pub fn psi_deg(f0: f64, q: f64, rate_dps: f64) -> f64 {
    let w0 = 2.0 * PI * f0;
    let w = rate_dps * DEG;
    let dp = (q * w * (2.0 * w0 + w) / (w0 * (w0 + w))).atan();
    let dm = (q * w * (2.0 * w0 - w) / (w0 * (w0 - w))).atan();
    0.5 * (dp + dm) / DEG
}

/// A config for the M^2-TFG-like board with the given device and sweep.
#[allow(clippy::too_many_arguments)]
pub fn config(
    kind: &str,
    f0: f64,
    q: f64,
    lambda: f64,
    f2_over_f1: f64,
    rates: &[f64],
    average_s: f64,
) -> Config {
    let (fs, pole, cutoff, dec) = if f0 > 1e6 {
        (16.0 * f0, 4.0 * f0, 2000.0, 2000)
    } else {
        (16.0 * f0, 4.0 * f0, 200.0, 100)
    };
    let board =
        format!("fs_hz = {fs}\ntia_pole_hz = {pole}\nlpf_cutoff_hz = {cutoff}\ndecimation = {dec}");
    config_with_board(kind, f0, q, lambda, f2_over_f1, rates, average_s, &board)
}

/// A config with the given device and sweep and `board` as the body of its `[board]` section
/// (keys left out take their derived defaults).
#[allow(clippy::too_many_arguments)]
pub fn config_with_board(
    kind: &str,
    f0: f64,
    q: f64,
    lambda: f64,
    f2_over_f1: f64,
    rates: &[f64],
    average_s: f64,
    board: &str,
) -> Config {
    let text = format!(
        r#"
[device]
f0_hz = {f0}
q = {q}
angular_gain = {lambda}
[drive]
f1 = 1.0
f2 = {f2_over_f1}
[board]
{board}
[experiment]
kind = "{kind}"
rates_dps = {rates:?}
average_s = {average_s}
"#
    );
    let cfg = parse_config(&text).expect("test config parses");
    cfg.validate().expect("test config validates");
    cfg
}

/// Runs a sweep with no progress output.
pub fn run(cfg: &Config) -> SweepResult {
    run_sweep(cfg, &|_, _| {}, None).expect("sweep runs")
}

/// The full-rate dump of `nodes` over `dur_s` from `start_s`, recorded by a one-point zero-rate
/// board run just past the window, written and read back as a user would.
pub fn full_rate_dump(c: &Config, nodes: &[&str], start_s: f64, dur_s: f64) -> gyroemu_io::Dump {
    let nodes: Vec<String> = nodes.iter().map(|n| n.to_string()).collect();
    let mut probe = Probe::new(&nodes, c.fs_hz(), c.decimation(), start_s, dur_s, 0);
    let n_out = ((start_s + dur_s) * c.fs_out_hz()).ceil() as u64 + 2;
    let point = Point {
        rate_rad_s: 0.0,
        window: Window::Boxcar {
            n: n_out,
            frac: 0.0,
        },
    };
    Board::<f64>::new(&c.board_params(), &[0.0], &[0])
        .unwrap()
        .run(
            0,
            &[point],
            RunOptions {
                probe: Some(&mut probe),
                ..Default::default()
            },
            &|_| {},
        )
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    probe.write(dir.path(), "d").unwrap();
    gyroemu_io::read_dump(&dir.path().join("d_fullrate")).unwrap()
}
