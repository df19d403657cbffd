//! A rotating window too short to part the two sidebands f_c +- Omega: refused before any
//! sample where the emulated read-out has no phase (a Hann window of one output sample was
//! accepted, then read NaN blaming an overflow), and warned, with the factor the sideband
//! solve multiplies other errors by, where it is merely ill-conditioned.

mod common;

use common::finished;
use gyroemu_board::unleak_sidebands;
use gyroemu_config::{presets::preset, Config, WindowKind};
use gyroemu_core::Complex64;

/// The rotating preset read at 1 output sample per second behind a 0.49 Hz low-pass, a
/// Hann window of `average_s`, at 175 deg/s (Omega / 2 pi = 0.486 Hz).
fn slow(average_s: f64) -> Config {
    let mut c = preset("m2tfg-rotating").unwrap();
    c.board.lpf_cutoff_hz = Some(0.49);
    c.board.decimation = Some(240_000);
    c.experiment.window = WindowKind::Hann;
    c.experiment.average_s = average_s;
    c.experiment.rates_dps = vec![175.0];
    c
}

#[test]
fn a_one_sample_hann_window_is_refused_where_the_emulation_reads_nothing() {
    let cfg = slow(1.03);
    let err = cfg.validate().unwrap_err().to_string();
    assert!(
        err.contains("experiment.average_s") && err.contains("cannot be told apart"),
        "{err}"
    );
    // Past the rule, the emulation has no phase to give for either mode.
    let res = finished(&cfg);
    assert!(
        res.points[0].phase_deg.iter().all(|p| p.is_nan()),
        "{:?}",
        res.points[0]
    );
}

/// The largest singular value of the read-out's sideband solve (`unleak_sidebands`, a linear
/// map of the two averages), from its action on the unit inputs: how much it multiplies an
/// error of the averages.
fn solve_gain(w: Complex64) -> f64 {
    let (one, zero) = (Complex64::new(1.0, 0.0), Complex64::new(0.0, 0.0));
    let (c0, s0) = unleak_sidebands(one, zero, w);
    let (c1, s1) = unleak_sidebands(zero, one, w);
    // M = [[c0, c1], [s0, s1]]: sigma_max^2 is the larger eigenvalue of M^H M.
    let a = c0.norm_sqr() + s0.norm_sqr();
    let d = c1.norm_sqr() + s1.norm_sqr();
    let b = c0.conj() * c1 + s0.conj() * s1;
    (0.5 * (a + d) + (0.25 * (a - d) * (a - d) + b.norm_sqr()).sqrt()).sqrt()
}

#[test]
fn a_two_sample_hann_window_is_warned_with_the_solves_gain() {
    // Two output samples of equal weight (sin^2 of pi/4 and 3 pi/4): the window keeps
    // (1 + e^{-j 2 pi x}) / 2 of the 2 Omega term, x = 2 Omega / (2 pi fs_out) cycles per
    // sample; the solve's gain is measured on the read-out's own solve.
    let cfg = slow(2.0);
    let warnings = cfg.validate().unwrap();
    let x = 2.0 * 175.0 / 360.0 / cfg.fs_out_hz();
    let (s, c) = (std::f64::consts::TAU * x).sin_cos();
    let gain = solve_gain(Complex64::new(0.5 * (1.0 + c), -0.5 * s));
    assert!(gain > 100.0, "{gain}");
    let w: Vec<_> = warnings.iter().filter(|w| w.contains("2 Omega")).collect();
    assert_eq!(w.len(), 1, "{warnings:?}");
    assert!(
        w[0].contains(&format!("= {gain:.3e}")),
        "{} (gain {gain:.3e})",
        w[0]
    );
    // Long enough, nothing is said.
    assert!(!slow(20.0)
        .validate()
        .unwrap()
        .iter()
        .any(|w| w.contains("2 Omega")));
}
