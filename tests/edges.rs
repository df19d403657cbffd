//! Issue 11, correctness at the edges: a dead channel, a clipped converter, an overflowing or
//! underflowing chain never read out as a clean phase. Each refused phase is NaN (null in
//! JSON), named with its stage and the setting to change; clipping is counted and warned.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use gyroemu::config::Config;
use std::f64::consts::PI;

/// The M^2-TFG Coriolis board with an 8-bit ADC whose full scale puts the TIA output (about
/// 20 mV) at `lsbs` LSBs.
fn with_adc(lsbs: f64) -> Config {
    let mut c = config("coriolis", 15e3, 2000.0, 1.0, 1.0, &[25.0, 100.0], 0.1);
    let tia = 1e-6 * 1e6 * 2000.0 / (2.0 * PI * 15e3) / (1.0 + 0.25f64.powi(2)).sqrt();
    c.board.adc_bits = Some(8);
    c.board.adc_full_scale_v = tia / lsbs * 128.0;
    c
}

#[test]
fn an_adc_that_reads_only_zeros_gives_no_phase_and_names_the_setting() {
    // 0.3 LSB: validation warns (below half an LSB), every sample then rounds to 0.
    let c = with_adc(0.3);
    let w = c.validate().expect("a warning, not a refusal");
    assert!(w.iter().any(|w| w.contains("below half an LSB")), "{w:?}");
    let r = run(&c);
    assert_eq!(r.problems.len(), 4, "{:?}", r.problems);
    for p in &r.problems {
        assert!(
            p.contains("ADC") && p.contains("board.adc_full_scale_v"),
            "{p}"
        );
    }
    for p in &r.points {
        assert!(p.phase_deg.iter().all(|v| v.is_nan()), "{p:?}");
    }
    assert!(r.max_abs_error_mdeg(0).is_nan() && r.max_abs_error_mdeg(1).is_nan());
    // Every sample of both channels was 0: counted over the whole run of every point.
    let h = r.health;
    assert!(h.samples > 0 && h.adc_zero == [h.samples; 2], "{h:?}");
}

#[test]
fn a_working_adc_counts_no_dead_sample_and_clipping_is_counted_and_warned() {
    // 40 LSBs: a working channel, phases within the quantisation's reach of theory.
    let r = run(&with_adc(40.0));
    assert!(r.problems.is_empty() && r.warnings.is_empty(), "{r:?}");
    assert!(r.health.adc_zero[0] < r.health.samples / 10);
    for p in &r.points {
        assert!(p.phase_deg.iter().all(|v| v.is_finite()));
    }
    // 300 LSBs of amplitude on a 128-code half range: the ADC clips, and says how often.
    let c = with_adc(300.0);
    assert!(c.validate().unwrap().iter().any(|w| w.contains("clip")));
    let r = run(&c);
    let h = r.health;
    assert!(h.adc_clipped[0] > 0 && h.adc_clipped[1] > 0, "{h:?}");
    assert!(
        r.warnings.iter().any(|w| w.contains("the ADC clipped")
            && w.contains("board.adc_full_scale_v")
            && w.contains(&format!("of {} samples", h.samples))),
        "{:?}",
        r.warnings
    );
    // A symmetric clip keeps the fundamental's phase of a pure carrier: still a number.
    assert!(r.problems.is_empty());
}

#[test]
fn an_undithered_adc_states_how_far_its_rounding_can_move_the_phase_and_stays_within() {
    // Without noise the ADC's error is a sawtooth of a carrier of 16 samples per period: it
    // repeats every period, so no averaging removes it (at 2.6 LSBs the phase froze on a
    // staircase with no warning). The bound is asin(LSB / A): twice the half-LSB bias over
    // the smallest amplitude of the run, computed here from the board's values: at 100 deg/s
    // the velocity falls by cos theta (THEORY.md section 3), and the chain is the hold's sinc
    // and the TIA recursion's |H| = (1 - a)/|1 - a e^{-j w Ts}| (a = e^{-2 pi 60 kHz Ts}).
    let ts = 1.0 / 240e3;
    let w = 2.0 * PI * 15e3;
    let a = (-2.0 * PI * 60e3 * ts).exp();
    let tia = (1.0 - a)
        / num_complex::Complex64::new(1.0 - a * (w * ts).cos(), a * (w * ts).sin()).norm();
    let hold = (w * ts / 2.0).sin() / (w * ts / 2.0);
    let theta = common::theta_deg(15e3, 2000.0, 1.0, 1.0, 1.0, 100.0)[0].to_radians();
    let smallest = 1e-6 * 1e6 * 2000.0 / w * theta.cos() * tia * hold;
    let resonance = 1e-6 * 1e6 * 2000.0 / w / (1.0 + 0.25f64.powi(2)).sqrt();
    for lsbs in [2.6, 40.0, 120.0] {
        let c = with_adc(lsbs);
        let lsb = resonance / lsbs;
        let bound_mdeg = (lsb / smallest).min(1.0).asin().to_degrees() * 1e3;
        let w = c.validate().expect("a warning, not a refusal");
        let said: Vec<&String> = w.iter().filter(|w| w.contains("rounding error")).collect();
        assert_eq!(said.len(), 2, "{lsbs} LSBs: {w:?}");
        assert!(
            said.iter()
                .all(|w| w.contains(&format!("{bound_mdeg:.3e} mdeg")) && w.contains("adc_bits")),
            "{said:?} against {bound_mdeg:.3e}"
        );
        let r = run(&c);
        for p in &r.points {
            for k in 0..2 {
                let e = ((p.phase_deg[k] - p.theory_deg[k]) * 1e3).abs();
                assert!(
                    e <= bound_mdeg,
                    "{lsbs} LSBs, mode {k}: {e} > {bound_mdeg} mdeg"
                );
            }
        }
    }
    // 2^31 LSBs of amplitude: the bound (3e-5 mdeg) is below the 0.01 mdeg stated.
    let mut c = with_adc(1.0);
    c.board.adc_bits = Some(32);
    assert!(!c
        .validate()
        .unwrap()
        .iter()
        .any(|w| w.contains("rounding error")));
}

#[test]
fn a_dead_drive_refuses_both_modes_naming_the_dac_setting() {
    // Validation refuses a drive below half a DAC LSB; a library user who skips it still gets
    // no phase: the run counts the all-zero drive and refuses both modes.
    let mut c = config("rotating", 15e3, 2000.0, 1.0, 1.0, &[50.0, 100.0], 3.6);
    c.board.dac_bits = Some(8);
    c.drive.f1 = 1e-3;
    let e = c.validate().unwrap_err();
    assert_eq!(e.key.as_deref(), Some("drive.f1"));
    let r = run(&c);
    assert_eq!(r.problems.len(), 4, "{:?}", r.problems);
    assert!(r.problems.iter().all(|p| p.contains("drive.f1")));
    assert!(r
        .points
        .iter()
        .all(|p| p.phase_deg[0].is_nan() && p.phase_deg[1].is_nan()));
    assert!(r.points.iter().all(|p| p.paper_i_deg.unwrap()[0].is_nan()));
}

#[test]
fn a_dead_coriolis_channel_has_no_single_mixer_reading_either() {
    // The same dead drive in a Coriolis run: the single-mixer DC of a refused channel was
    // written as a clean 0 (read by Python as 0.0) beside the NaN phases.
    let mut c = config("coriolis", 15e3, 2000.0, 1.0, 1.0, &[50.0, 100.0], 0.2);
    c.board.dac_bits = Some(8);
    c.drive.f1 = 1e-3;
    c.drive.f2 = Some(1e-3);
    let r = run(&c);
    assert!(!r.problems.is_empty());
    for p in &r.points {
        assert!(p.phase_deg.iter().all(|x| x.is_nan()), "{p:?}");
        assert!(
            p.single_mixer_dc_v.unwrap().iter().all(|x| x.is_nan()),
            "{p:?}"
        );
    }
}

#[test]
fn an_underflowing_chain_gives_no_phase_instead_of_zero() {
    // Far below the refused range the products of the read-out underflow to exact zeros, and
    // atan2(0, 0) would read as a clean 0 degrees.
    let mut c = config("coriolis", 15e3, 2000.0, 1.0, 1.0, &[25.0, 100.0], 0.1);
    c.drive.f1 = 1e-300;
    c.drive.f2 = Some(1e-300);
    assert!(c.validate().is_err());
    let r = run(&c);
    assert!(!r.problems.is_empty());
    assert!(
        r.points.iter().all(|p| p.phase_deg[0].is_nan()),
        "{:?}",
        r.points
    );
}

#[test]
fn a_decimation_that_folds_the_mixer_product_onto_dc_is_stated_and_bounded() {
    // Order 1 at 1 kHz leaves |L(2 f_c)| of the 30 kHz product; M = 8 makes the output rate
    // 30 kHz, which aliases it exactly onto the averaged DC (a 6 % scale-factor error with no
    // warning before). The bound: asin |L(2 f_c)| of the bilinear one-pole, prewarped at the
    // cutoff, H(z) = k (1 + 1/z) / (1 + a/z), k = t / (1 + t), a = (t - 1)/(t + 1).
    let board = "fs_hz = 240000.0\ntia_pole_hz = 60000.0\nlpf_order = 1\nlpf_cutoff_hz = 1000.0";
    let rates = [25.0, 175.0];
    let mut c = config_with_board("coriolis", 15e3, 2000.0, 1.0, 1.0, &rates, 0.5, board);
    let derived = c.validate().unwrap();
    assert!(
        !derived.iter().any(|w| w.contains("2 f_c product")),
        "the derived decimation avoids the fold: {derived:?}"
    );
    c.board.decimation = Some(8);
    let t = (PI * 1000.0 / 240e3).tan();
    let (k, a) = (t / (1.0 + t), (t - 1.0) / (t + 1.0));
    let z = num_complex::Complex64::from_polar(1.0, -2.0 * PI * 30e3 / 240e3);
    let leak = (k * (1.0 + z) / (1.0 + a * z)).norm();
    // Each phasor's bound, twice: the point's and the zero-rate reference's it is read against.
    let bound_mdeg = 2.0 * leak.asin().to_degrees() * 1e3;
    let w = c.validate().unwrap();
    assert!(
        w.iter()
            .any(|w| w.contains("board.decimation = 8")
                && w.contains(&format!("{bound_mdeg:.3e} mdeg"))),
        "{w:?} against {bound_mdeg:.3e}"
    );
    let r = run(&c);
    let errs: Vec<f64> = r
        .points
        .iter()
        .flat_map(|p| (0..2).map(|k| ((p.phase_deg[k] - p.theory_deg[k]) * 1e3).abs()))
        .collect();
    assert!(
        errs.iter().all(|&e| e <= bound_mdeg),
        "{errs:?} > {bound_mdeg}"
    );
    // The fold is real: the worst point moves by a sizeable share of one phasor's bound.
    assert!(errs.iter().any(|&e| e >= 0.05 * bound_mdeg), "{errs:?}");
}

#[test]
fn a_clipping_warning_names_the_points_that_clipped_and_only_those() {
    // Coriolis with F1 = F2: each mode's velocity is F Q / w0 cos(theta) (THEORY.md section 3:
    // the amplitude falls as cos theta), held by the DAC (the fundamental of a held sine at
    // fs = 16 f0 is sinc(1/16) = sin(pi/16) / (pi/16) of it) and seen through the TIA's pole.
    // Rails at 0.9 of the zero-rate output catch rates up to 175 deg/s (cos theta >= 0.99) but
    // not 1000 and 2000 deg/s (0.80 and 0.56, and a start-up overshoot of at most
    // e^(-pi / (lambda Omega tau)) = 1.4 % and 12 %). The warning had summed all points.
    let (f0, q) = (15e3, 2000.0);
    let mut c = config(
        "coriolis",
        f0,
        q,
        1.0,
        1.0,
        &[25.0, 175.0, 1000.0, 2000.0],
        0.5,
    );
    let w0 = 2.0 * std::f64::consts::PI * f0;
    let x = std::f64::consts::PI / 16.0;
    let out = c.board.tia_gain_ohm * c.device.transduction_a_s_per_m * q / w0 * x.sin()
        / x
        / (1.0 + (f0 / c.board.tia_pole_hz.unwrap()).powi(2)).sqrt();
    c.board.tia_rail_v = Some(0.9 * out);
    let r = run(&c);
    let rails: Vec<&String> = r.warnings.iter().filter(|w| w.contains("rails")).collect();
    assert_eq!(rails.len(), 2, "{:?}", r.warnings);
    for w in rails {
        for railed in ["the zero-rate reference", " 25 deg/s", " 175 deg/s"] {
            assert!(w.contains(railed), "{railed}: {w}");
        }
        for clean in ["1000 deg/s", "2000 deg/s"] {
            assert!(!w.contains(clean), "{clean}: {w}");
        }
        // The reference clipped, and every phase is read against it.
        assert!(w.contains("phase of this run can be trusted"), "{w}");
    }
    // Against the same board without rails: every phase moved by the reference's shift (the
    // clipped tone's harmonics alias onto the carrier at fs = 16 f0), and the clipped points'
    // by their own clipping besides.
    c.board.tia_rail_v = None;
    let free = run(&c);
    let moved: Vec<f64> = r
        .points
        .iter()
        .zip(&free.points)
        .map(|(p, q)| p.phase_deg[0] - q.phase_deg[0])
        .collect();
    let reference_shift = moved[2];
    assert!(reference_shift.abs() > 1e-2, "{moved:?}");
    assert!((moved[3] - reference_shift).abs() < 1e-9, "{moved:?}");
    assert!(
        moved[..2]
            .iter()
            .all(|m| (m - reference_shift).abs() > 1e-2),
        "{moved:?}"
    );
}

#[test]
fn a_clipped_drive_in_a_coriolis_run_spoils_every_phase_and_the_warning_says_so() {
    // Only drive 1 clips (F2 = 0.4 F1): its fundamental shrinks, the drives' ratio moves, and
    // with it every point's phase of both modes, though only drive 1's counts show it.
    let mut c = config("coriolis", 15e3, 2000.0, 1.0, 0.4, &[25.0, 2000.0], 0.5);
    let free = run(&c);
    c.board.dac_bits = Some(16);
    c.board.dac_full_scale = 0.6;
    let r = run(&c);
    let dac: Vec<&String> = r
        .warnings
        .iter()
        .filter(|w| w.contains("DAC clipped"))
        .collect();
    assert_eq!(dac.len(), 1, "{:?}", r.warnings);
    assert!(
        dac[0].contains("of mode 1") && dac[0].contains("no phase of this run"),
        "{}",
        dac[0]
    );
    for (p, q) in r.points.iter().zip(&free.points) {
        let moved = (p.phase_deg[1] - q.phase_deg[1]).abs();
        assert!(
            moved > 1e-2,
            "{} deg/s: mode 2 moved {moved} deg",
            p.rate_dps
        );
    }
}
