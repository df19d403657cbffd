//! The two-mode (combined) self-calibration: the geometric mean of the two modes' slopes.
//! Truths: the closed forms of THEORY.md eqs. 2-3 and section 4 for a device whose only
//! imperfections are the drive-gain ratio and the Q mismatch (each mode's prediction off by
//! Q_k / (r^{+-1} Q_other), the combined one exact); the exact continuous-time theory of the
//! imperfect plant (`DrivenDevice`) read by an estimator written out again here; and the
//! first-order law docs/selfcal.md gives for what the combination cannot cancel.

use gyroemu::analysis::selfcal::run_selfcal_core;
use gyroemu::analysis::selfcal_combined::combined_slope;
use gyroemu::config::presets::preset;
use gyroemu::config::Config;
use std::f64::consts::PI;

const DEG: f64 = PI / 180.0;
const RATES: [f64; 7] = [25.0, 50.0, 75.0, 100.0, 125.0, 150.0, 175.0];

fn quiet(_: u64, _: u64) {}

/// A noiseless, short self-calibration config: the m2tfg-selfcal device and board without
/// noise, converters or analyses, averaged over one half period of the slowest rate.
fn short(mut c: Config) -> Config {
    c.experiment.rates_dps = RATES.to_vec();
    c.experiment.average_s = 7.2;
    c.experiment.settle_s = Some(0.8);
    c.noise = None;
    c.selfcal = None;
    c.board.dac_bits = None;
    c.board.adc_bits = None;
    c.validate().expect("test config validates");
    c
}

/// An otherwise ideal device with drive-gain ratio `r` and Q2 = `q_ratio` Q1.
fn gain_and_q(r: f64, q_ratio: f64) -> Config {
    let mut c = preset("m2tfg-selfcal").unwrap();
    c.device.mode2_f0_offset_hz = 0.0;
    c.device.quadrature_coupling_rad2_s2 = 0.0;
    c.board.phase_shifter_error_deg = 0.0;
    c.device.q_mode2 = Some(q_ratio * c.device.q);
    c.drive.f2 = Some(r);
    c
}

/// Least-squares slope of tan(phase) against the rate (the scale-factor definition), written
/// out again: rad per rad/s.
fn tan_slope(rates_rad_s: &[f64], phase_rad: &[f64]) -> f64 {
    let n = rates_rad_s.len() as f64;
    let mx = rates_rad_s.iter().sum::<f64>() / n;
    let t: Vec<f64> = phase_rad.iter().map(|p| p.tan()).collect();
    let my = t.iter().sum::<f64>() / n;
    let sxy: f64 = rates_rad_s
        .iter()
        .zip(&t)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum();
    let sxx: f64 = rates_rad_s.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// What the exact continuous-time theory gives for the per-mode and the combined errors of
/// `cfg`'s device at `rates_dps`.
fn theory_errors(cfg: &Config, rates_dps: &[f64]) -> ([f64; 2], f64) {
    let dev = cfg.driven_device();
    let lambda = cfg.device.angular_gain;
    let w: Vec<f64> = rates_dps.iter().map(|r| r * DEG).collect();
    let cor: Vec<[f64; 2]> = w.iter().map(|&o| dev.coriolis_phase_rad(o)).collect();
    let rot: Vec<[f64; 2]> = w.iter().map(|&o| dev.rotating_psi_rad(o)).collect();
    let slope = |s: &[[f64; 2]], k: usize| {
        let p: Vec<f64> = s.iter().map(|x| x[k]).collect();
        tan_slope(&w, &p)
    };
    let sc = [slope(&cor, 0), slope(&cor, 1)];
    let sr = [slope(&rot, 0), slope(&rot, 1)];
    let per_mode = [0, 1].map(|k| lambda * sr[k] / sc[k] - 1.0);
    let combined = lambda * (sr[0] * sr[1]).sqrt() / (sc[0] * sc[1]).sqrt() - 1.0;
    (per_mode, combined)
}

#[test]
fn drive_gain_and_q_mismatch_errors_are_equal_and_opposite_and_the_combination_cancels_them() {
    // (F2/F1, Q2/Q1): the F2/F1 = 1.2 on an ideal device, and both together.
    for (r, qr) in [(1.2, 1.0), (0.8, 1.25)] {
        let c = short(gain_and_q(r, qr));
        let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
        // Closed forms: rotating slope 2 Q_k / w0, Coriolis slope 2 lambda Q_other r^{+-1} / w0.
        let expected = [1.0 / (r * qr) - 1.0, r * qr - 1.0];
        for (k, (m, x)) in core.modes.iter().zip(expected).enumerate() {
            let e = m.relative_error;
            assert!(
                (e - x).abs() < 1e-6,
                "r {r}, Q2/Q1 {qr}, mode {}: {e:e} vs {x:e}",
                k + 1
            );
        }
        let comb = core.combined;
        assert!(
            comb.relative_error.abs() < 1e-7,
            "r {r}, Q2/Q1 {qr}: combined {:e}",
            comb.relative_error
        );
        // The combined Coriolis slope is 2 lambda sqrt(Q1 Q2) / w0 whatever F2/F1 is.
        let w0 = 2.0 * PI * c.device.f0_hz;
        let truth = 2.0 * c.device.angular_gain * c.device.q * qr.sqrt() / w0;
        assert!((comb.coriolis.slope_deg_per_dps / truth - 1.0).abs() < 1e-6);
        assert!((comb.theory_coriolis_deg_per_dps / truth - 1.0).abs() < 1e-12);
        // Noiseless: the interval is only the fits' residual (the rotating psi's curvature).
        assert!(comb.relative_error_ci95 < 1e-6, "{comb:?}");
    }
}

#[test]
fn combined_error_on_an_imperfect_device_is_the_exact_theory_of_the_same_estimator() {
    // The m2tfg-selfcal device (mode split, Q mismatch, F2/F1, phase-shifter error), and the
    // same with quadrature coupling and larger mismatches.
    let mut worse = preset("m2tfg-selfcal").unwrap();
    worse.device.quadrature_coupling_rad2_s2 = 3e4;
    worse.device.mode2_f0_offset_hz = 0.05;
    worse.board.phase_shifter_error_deg = 0.5;
    worse.drive.f2 = Some(0.9);
    for c in [short(preset("m2tfg-selfcal").unwrap()), short(worse)] {
        let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
        let (per_mode, combined) = theory_errors(&c, &RATES);
        let got = core.combined.relative_error;
        // The emulated phases sit within micro-degrees of the continuous theory (hold, TIA and
        // low-pass compensated): a few 1e-7 on each mode's error, much less on the combined.
        assert!(
            (got - combined).abs() < 5e-8,
            "emulated {got:e}, theory {combined:e}"
        );
        assert!((core.combined.relative_error_theory - combined).abs() < 1e-12);
        for (m, x) in core.modes.iter().zip(per_mode) {
            assert!((m.relative_error - x).abs() < 1e-6);
            assert!((m.relative_error_theory - x).abs() < 1e-12);
        }
        // The combination removes the large equal-and-opposite part.
        assert!(combined.abs() < 0.1 * per_mode[0].abs().min(per_mode[1].abs()));
    }
}

/// The m2tfg-selfcal device with the given imperfections (Q2 in units of Q1).
fn device(r: f64, q_ratio: f64, split_hz: f64, eps_deg: f64, k12: f64) -> Config {
    let mut c = gain_and_q(r, q_ratio);
    c.device.mode2_f0_offset_hz = split_hz;
    c.board.phase_shifter_error_deg = eps_deg;
    c.device.quadrature_coupling_rad2_s2 = k12;
    c
}

/// A small deterministic pseudo-random sequence in [0, 1) (the property test's cases).
fn unit(i: u64) -> f64 {
    let x = (i + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
    (x >> 11) as f64 / (1u64 << 53) as f64
}

#[test]
fn property_the_combination_cancels_any_drive_gain_ratio_and_q_mismatch_exactly() {
    // On the exact theory, for F2/F1 and Q2/Q1 each drawn over [1/2, 2]: per-mode errors are
    // Q_k / (r^{+-1} Q_other) - 1 and the combined error only the rotating psi's
    // O((Omega / w0)^2) departure from atan(2 Q Omega / w0) (6e-10 here).
    for i in 0..64 {
        let r = 2f64.powf(2.0 * unit(2 * i) - 1.0);
        let qr = 2f64.powf(2.0 * unit(2 * i + 1) - 1.0);
        let c = device(r, qr, 0.0, 0.0, 0.0);
        let (per_mode, combined) = theory_errors(&c, &RATES);
        assert!((per_mode[0] - (1.0 / (r * qr) - 1.0)).abs() < 1e-8);
        assert!((per_mode[1] - (r * qr - 1.0)).abs() < 1e-8);
        assert!(combined.abs() < 1e-8, "r {r}, Q2/Q1 {qr}: {combined:e}");
    }
}

#[test]
fn what_the_combination_cannot_cancel_follows_the_documented_first_order_law() {
    // Mode split d = 2 Q2 df / f0 and phase-shifter error eps enter as curvature of tan(phase)
    // against the rate, which the straight-line fit reads as slope. To first order in d and
    // eps (docs/selfcal.md): tan theta1 = S1 W (1 - (d - eps) S1 W + d S2 W), tan theta2 =
    // S2 W (1 - eps S2 W + d S1 W), tan psi2 = R2 W + eps (1 + (R2 W)^2), with the small-angle
    // slopes S1 = 2 lambda r Q2 / w0, S2 = 2 lambda Q1 / (r w0), R2 = 2 Q2 / w0; a line fit
    // reads u (1 + c u) as slope times 1 + c cov(u, u^2) / var(u). So the combined error is
    // (K / 2) (eps (R2 - S1 + S2) - d S2), K = cov(W, W^2) / var(W) (twice the mean rate for
    // evenly spread rates).
    let w: Vec<f64> = RATES.iter().map(|r| r * DEG).collect();
    let n = w.len() as f64;
    let m1 = w.iter().sum::<f64>() / n;
    let m2 = w.iter().map(|x| x * x).sum::<f64>() / n;
    let m3 = w.iter().map(|x| x * x * x).sum::<f64>() / n;
    let k = (m3 - m1 * m2) / (m2 - m1 * m1);
    for i in 0..24 {
        let r = 2f64.powf(0.6 * unit(100 + 4 * i) - 0.3);
        let qr = 2f64.powf(0.2 * unit(101 + 4 * i) - 0.1);
        let split_hz = 0.04 * unit(102 + 4 * i) - 0.02;
        let eps_deg = 0.4 * unit(103 + 4 * i) - 0.2;
        let mut c = device(r, qr, split_hz, eps_deg, 0.0);
        c.device.angular_gain = if i % 2 == 0 { 1.0 } else { 0.6 };
        let (q1, lambda) = (c.device.q, c.device.angular_gain);
        let q2 = qr * q1;
        let w0 = 2.0 * PI * c.device.f0_hz;
        let (s1, s2, r2) = (
            2.0 * lambda * r * q2 / w0,
            2.0 * lambda * q1 / (r * w0),
            2.0 * q2 / w0,
        );
        let d = 2.0 * q2 * split_hz / c.device.f0_hz;
        let law = 0.5 * k * (eps_deg * DEG * (r2 - s1 + s2) - d * s2);
        let (_, combined) = theory_errors(&c, &RATES);
        // Second-order terms (d^2, eps^2, d eps, times powers of the phase) stay below 2e-5
        // here, against laws of up to 7e-4.
        assert!(
            (combined - law).abs() < 3e-5,
            "r {r}, Q2/Q1 {qr}, split {split_hz} Hz, eps {eps_deg} deg, lambda {lambda}: \
             {combined:e} vs law {law:e}"
        );
    }
    // Quadrature coupling cancels to first order: doubling k12 doubles each mode's error but
    // quadruples the combined one.
    let err = |k12: f64| theory_errors(&device(1.0, 1.0, 0.0, 0.0, k12), &RATES);
    let (p1, c1) = err(1e4);
    let (p2, c2) = err(2e4);
    for m in 0..2 {
        assert!((p2[m] / p1[m] - 2.0).abs() < 0.05, "{p1:?} {p2:?}");
    }
    assert!((c2 / c1 - 4.0).abs() < 0.2, "{c1:e} {c2:e}");
    assert!(c1.abs() < 0.02 * p1[0].abs());
}

#[test]
fn combined_slope_is_the_geometric_mean_and_its_error_counts_correlated_noise_once() {
    // Two modes of slopes 0.02 and 0.08 rad per rad/s (geometric mean 0.04). A relative
    // residual common to both modes moves each relative slope alike, so the combined relative
    // error is that of either mode; on one mode only, it is half of that mode's.
    let rates = [25.0, 50.0, 75.0, 100.0, 125.0];
    let wobble = [0.0, 1e-4, -2e-4, 1e-4, 0.0];
    let ph = |s: f64, e: &[f64]| -> Vec<f64> {
        rates
            .iter()
            .zip(e)
            .map(|(r, e)| (s * r * DEG * (1.0 + e)).atan() / DEG)
            .collect()
    };
    let fit = gyroemu::analysis::selfcal::linearised_slope;
    let (a, b) = (ph(0.02, &wobble), ph(0.08, &wobble));
    let c = combined_slope(&rates, [&a, &b]);
    let (fa, fb) = (fit(&rates, &a), fit(&rates, &b));
    let g = (fa.slope_deg_per_dps * fb.slope_deg_per_dps).sqrt();
    assert!((c.slope_deg_per_dps / g - 1.0).abs() < 1e-15);
    assert!((c.slope_deg_per_dps / 0.04 - 1.0).abs() < 1e-3);
    let rel = fa.std_err_deg_per_dps / fa.slope_deg_per_dps;
    assert!(rel > 0.0);
    assert!((c.rel_std_err / rel - 1.0).abs() < 1e-9, "{c:?} vs {rel:e}");
    let clean = ph(0.08, &[0.0; 5]);
    let half = combined_slope(&rates, [&a, &clean]);
    assert!(
        (half.rel_std_err / (0.5 * rel) - 1.0).abs() < 1e-9,
        "{half:?}"
    );
    // Opposite signs: no common scale factor.
    let neg: Vec<f64> = a.iter().map(|p| -p).collect();
    assert!(combined_slope(&rates, [&neg, &b])
        .slope_deg_per_dps
        .is_nan());
}
