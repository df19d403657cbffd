//! `gyroemu sweep`'s measurement and fits, on small emulated boards (Q = 2000 at 15 kHz,
//! fs = 16 f0): the emulated response is the plant's exact held-drive steady state, the fits
//! give back the configured device (its hold bias stated), quadrature coupling moves the
//! fitted modes as the coupled plant's eigenvalues say, and the results do not depend on the
//! thread count.

use gyroemu_analysis::freq_response::{
    coupled_modes, frequency_response_from, held_response, FrequencyResponse,
};
use gyroemu_analysis::stepped_sine::{run_stepped_sine, SteppedSine};
use gyroemu_config::presets::preset_text;
use gyroemu_config::{parse_config, Config};
use gyroemu_resonator::Resonator;
use std::f64::consts::PI;

/// The Coriolis preset's board with this device and `[sweep] points`.
fn config(offset_hz: f64, q2: f64, k12: f64, points: usize, extra: &str) -> Config {
    let text = preset_text("m2tfg-coriolis")
        .unwrap()
        .replace(
            "mode2_f0_offset_hz = 0.0",
            &format!("mode2_f0_offset_hz = {offset_hz:?}\nq_mode2 = {q2:?}"),
        )
        .replace(
            "quadrature_coupling_rad2_s2 = 0.0",
            &format!("quadrature_coupling_rad2_s2 = {k12:?}"),
        )
        + &format!("\n[sweep]\npoints = {points}\n{extra}");
    let c = parse_config(&text).unwrap();
    c.validate_sweep().unwrap();
    c
}

fn measure(c: &Config) -> SteppedSine {
    let m = run_stepped_sine(c, &|_, _| {}).unwrap();
    assert!(m.problems.is_empty() && m.warnings.is_empty(), "{m:?}");
    m
}

/// The peak velocity per force of mode 1, Q / w0.
fn peak(c: &Config) -> f64 {
    c.device.q / (2.0 * PI * c.device.f0_hz)
}

#[test]
fn the_emulated_response_is_the_exact_held_steady_state() {
    let c = config(2.0, 1500.0, 2e5, 21, "");
    let m = measure(&c);
    // An independently built plant's exact steady state under the held drive, over the hold.
    let plant = Resonator::<f64>::new(&c.resonator_params(), 0.0).unwrap();
    let p = peak(&c);
    let (mut worst, mut cross_max, mut recip) = (0.0f64, 0.0f64, 0.0f64);
    for pt in &m.points {
        for drive in 0..2 {
            let want = held_response(&plant, pt.freq_hz, drive);
            for (got, want) in pt.response[drive].iter().zip(want) {
                worst = worst.max((got - want).norm() / p);
            }
        }
        cross_max = cross_max.max(pt.response[0][1].norm());
        // Reciprocity: a symmetric stiffness and damping give a symmetric response matrix.
        recip = recip.max((pt.response[0][1] - pt.response[1][0]).norm());
    }
    // What is left of the start-up transient after 16 time constants is e^-16 = 1e-7 of the
    // response; the low-pass leaves less than 1e-9 of the 2 f product.
    assert!(worst < 1e-6, "{worst:e}");
    assert!(cross_max > 1e-2 * p, "the coupling shows: {cross_max:e}");
    assert!(recip < 1e-6 * cross_max, "{recip:e} of {cross_max:e}");
}

#[test]
fn the_fits_give_back_the_configured_device() {
    let c = config(2.0, 1500.0, 0.0, 41, "");
    let r = frequency_response_from(&c, measure(&c));
    for (k, (f0, q)) in [(15000.0, 2000.0), (15002.0, 1500.0)]
        .into_iter()
        .enumerate()
    {
        let mode = r.modes[k];
        let fit = mode.fit.unwrap();
        let hb = f0 / (2.0 * q);
        assert_eq!((mode.configured_f0_hz, mode.configured_q), (f0, q));
        // Without coupling the coupled plant's modes are the configured ones.
        assert!(
            (mode.coupled_f0_hz - f0).abs() < 1e-9 * hb && (mode.coupled_q / q - 1.0).abs() < 1e-9
        );
        // The hold's images add a nearly constant -0.0105 j / w0 to the velocity per force at
        // 16 samples per period (5e-6 of the peak at Q = 2000): the fit reads f0 about 1e-5
        // half-bandwidths high and Q 1e-6 low. Bounded ten times above.
        assert!((fit.f0_hz - f0).abs() < 1e-4 * hb, "mode {k}: {fit:?}");
        assert!((fit.q / q - 1.0).abs() < 1e-5, "mode {k}: {fit:?}");
        assert!(
            (fit.gain_re - 1.0).abs() < 1e-4 && fit.gain_im.abs() < 1e-4,
            "{fit:?}"
        );
        assert!(fit.f0_sigma_hz < 1e-4 * hb, "{fit:?}");
        // The emulation against the exact expectation (the same fit of the held steady state).
        let exp = mode.expected.unwrap();
        assert!((fit.f0_hz - exp.f0_hz).abs() < 1e-7 * hb, "{fit:?} {exp:?}");
        assert!((fit.q / exp.q - 1.0).abs() < 1e-7, "{fit:?} {exp:?}");
    }
    let (split, sigma) = r.mode_split_hz();
    assert!(
        (split - 2.0).abs() < 1e-4 * 3.75 && sigma < 1e-3,
        "{split} {sigma}"
    );
    // The matrix identification: the same modes, no coupling.
    let mx = r.matrix.unwrap();
    assert!(
        (mx.f0_hz[0] - 15000.0).abs() < 1e-4 && (mx.f0_hz[1] - 15002.0).abs() < 1e-4,
        "{mx:?}"
    );
    assert!(
        (mx.q[0] / 2000.0 - 1.0).abs() < 1e-5 && (mx.q[1] / 1500.0 - 1.0).abs() < 1e-5,
        "{mx:?}"
    );
    assert!(
        mx.coupling_rad2_s2 == 0.0 && mx.damping_coupling_rad_s == 0.0,
        "{mx:?}"
    );
}

/// The coupled modes of `c` from the stiffness matrix `[[w1^2, k], [k, w2^2]]` alone (its
/// eigenvalues in closed form), Hz: the damping moves them by O(1/Q^2).
fn stiffness_modes_hz(c: &Config) -> [f64; 2] {
    let p = c.resonator_params();
    let (w1, w2) = (2.0 * PI * p.mode1.f0_hz, 2.0 * PI * p.mode2.f0_hz);
    let k = p.quadrature_coupling_rad2_s2;
    let mean = 0.5 * (w1 * w1 + w2 * w2);
    let half = (0.25 * (w2 * w2 - w1 * w1).powi(2) + k * k).sqrt();
    [
        (mean - half).sqrt() / (2.0 * PI),
        (mean + half).sqrt() / (2.0 * PI),
    ]
}

/// How many of `r`'s warnings contain `needle`.
fn warned(r: &FrequencyResponse, needle: &str) -> usize {
    r.measured
        .warnings
        .iter()
        .filter(|w| w.contains(needle))
        .count()
}

fn coupled(c: &Config) -> FrequencyResponse {
    frequency_response_from(c, measure(c))
}

#[test]
fn quadrature_coupling_moves_the_fitted_modes_as_the_coupled_plant_says() {
    // Modes 40 Hz (about 10 half-bandwidths) apart, coupled by k12 = 2 w0 x 2 pi x 5 Hz: the
    // stiffness matrix's eigenvalues move each mode by about 0.6 Hz (0.17 half-bandwidth),
    // outward. The other mode's residue in a driven response is (5/40)^2 = 1.6 %.
    let w0 = 2.0 * PI * 15e3;
    let k12 = 2.0 * w0 * 2.0 * PI * 5.0;
    let c = config(40.0, 2000.0, k12, 61, "");
    let r = coupled(&c);
    let eig = stiffness_modes_hz(&c);
    let shift = [eig[0] - 15000.0, eig[1] - 15040.0];
    assert!(shift[0] < -0.5 && shift[1] > 0.5, "{shift:?}");
    for k in 0..2 {
        let m = r.modes[k];
        // The damped eigenvalues against the stiffness matrix's: O(1/Q^2) of f0.
        assert!((m.coupled_f0_hz - eig[k]).abs() < 1e-5, "{m:?} {eig:?}");
        // A one-mode fit sees the coupled mode: its f0 moved by the eigenvalue's shift, to
        // within what the neighbour's residue adds (4 % of the shift here).
        let fit = m.fit.unwrap();
        let moved = fit.f0_hz - m.configured_f0_hz;
        assert!(
            (moved / shift[k] - 1.0).abs() < 0.1,
            "mode {k}: moved {moved}, eigen {}",
            shift[k]
        );
        // ... and what it sees is exactly what the held steady state gives.
        let exp = m.expected.unwrap();
        assert!((fit.f0_hz - exp.f0_hz).abs() < 1e-6 && (fit.q / exp.q - 1.0).abs() < 1e-6);
    }
    // The 2 x 2 identification takes the coupling apart: the configured modes and k12.
    let mx = r.matrix.unwrap();
    let hb = 3.75;
    assert!((mx.f0_hz[0] - 15000.0).abs() < 1e-4 * hb, "{mx:?}");
    assert!((mx.f0_hz[1] - 15040.0).abs() < 1e-4 * hb, "{mx:?}");
    assert!(
        (mx.q[0] / 2000.0 - 1.0).abs() < 1e-5 && (mx.q[1] / 2000.0 - 1.0).abs() < 1e-5,
        "{mx:?}"
    );
    assert!(
        (mx.coupling_rad2_s2 / k12 - 1.0).abs() < 1e-5,
        "{mx:?} {k12}"
    );
}

#[test]
fn the_coupled_modes_are_the_stiffness_eigenvalues_for_uniform_damping() {
    // With the same w/Q on both modes the damping matrix is c I and commutes with K: the
    // damped eigenvalues are exactly s^2 + c s + lambda = 0, |s| = sqrt(lambda), Q = |s| / c.
    let (f1, q1) = (15e3, 2000.0); // the preset's mode 1
    let f2 = 15012.0;
    let q2 = q1 * f2 / f1;
    let k12 = 3e6;
    let c = config(12.0, q2, k12, 11, "");
    let eig = stiffness_modes_hz(&c);
    let damping = 2.0 * PI * f1 / q1;
    let modes = coupled_modes(&c.resonator_params());
    for k in 0..2 {
        assert!(
            (modes[k].0 / eig[k] - 1.0).abs() < 1e-13,
            "{modes:?} {eig:?}"
        );
        let q = 2.0 * PI * eig[k] / damping;
        assert!((modes[k].1 / q - 1.0).abs() < 1e-9, "{modes:?} {q}");
    }
    // Mode 2 below mode 1: the names follow the modes, not the order.
    let c = config(-12.0, q1 * (f1 - 12.0) / f1, k12, 11, "");
    let modes = coupled_modes(&c.resonator_params());
    assert!(
        modes[1].0 < modes[0].0 && (modes[1].0 - 14988.0).abs() < 1.0,
        "{modes:?}"
    );
}

#[test]
fn the_results_do_not_depend_on_the_thread_count() {
    // Noise on, so every run's own stream is exercised.
    let noise = "\n[noise]\nseed = 7\ntia_current_noise_a_per_rthz = 1e-11\n";
    let c = config(2.0, 1500.0, 2e5, 7, noise);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| measure(&c))
    };
    let (one, three) = (run(1), run(3));
    assert_eq!(one, three);
    // The noise is there (the test is not comparing two noiseless runs).
    let quiet = config(2.0, 1500.0, 2e5, 7, "");
    let q = measure(&quiet);
    assert!(one.points.iter().zip(&q.points).all(|(a, b)| a.z != b.z));
}

#[test]
fn a_cross_coupling_below_the_adc_resolution_is_nan_with_a_warning_not_zero() {
    // 8-bit ADC at 0.05 V full scale: the driven TIA output (21 mV at resonance) is resolved,
    // a cross-coupling of about 1e-4 of it is below half an LSB (0.2 mV): the ADC of the mode
    // read puts out only zeros, which must not pass for "no coupling".
    let mut c = config(2.0, 1500.0, 1e3, 7, "");
    c.board.adc_bits = Some(8);
    c.board.adc_full_scale_v = 0.05;
    c.validate_sweep().unwrap();
    let m = run_stepped_sine(&c, &|_, _| {}).unwrap();
    assert!(m.problems.is_empty(), "{:?}", m.problems);
    assert!(
        m.warnings
            .iter()
            .any(|w| w.contains("below the ADC's resolution")),
        "{:?}",
        m.warnings
    );
    for p in &m.points {
        assert!(
            p.response[0][1].re.is_nan() && p.response[1][0].re.is_nan(),
            "{p:?}"
        );
        assert!(p.response[0][0].norm() > 0.0 && p.response[1][1].norm() > 0.0);
    }
}

/// Noise at 40 % of the peak over 31 points: a fit either lands within 6 of its own sigmas of
/// the noiseless fit, or is not read (null) with a warning naming the mode. Seed 2 once ran
/// away to Q = 7e20 with f0 39 sigma off and no warning.
#[test]
fn a_noisy_fit_is_within_its_sigma_or_not_read() {
    let (mut read, mut nulled) = (0, 0);
    for seed in 0..12 {
        let extra = format!("\n[noise]\nseed = {seed}\ntia_current_noise_a_per_rthz = 3e-9\n");
        let c = config(20.0, 2000.0, 0.0, 31, &extra);
        let r = frequency_response_from(&c, run_stepped_sine(&c, &|_, _| {}).unwrap());
        for m in &r.modes {
            let truth = m.expected.as_ref().expect("noiseless fit").f0_hz;
            match &m.fit {
                Some(f) => {
                    read += 1;
                    let z = (f.f0_hz - truth) / f.f0_sigma_hz;
                    assert!(
                        z.abs() <= 6.0,
                        "seed {seed}, mode {}: {z} sigma: {f:?}",
                        m.mode
                    );
                }
                None => {
                    nulled += 1;
                    let named = format!("mode {}:", m.mode);
                    assert!(
                        r.measured.warnings.iter().any(|w| w.starts_with(&named)),
                        "seed {seed}: {:?}",
                        r.measured.warnings
                    );
                }
            }
        }
    }
    assert!(read >= 16, "{read} read, {nulled} not");
}

/// The 2 x 2 fit under noise at 13 % of the peak (even seeds) and at 0.13 % (odd ones): read
/// only when it gives each mode's own f0 within a half-bandwidth (3.75 Hz) of the configured
/// one, else null with a warning (a fit 5.2 Hz off, Q 605 against 2000 and a coupling of
/// -1.4e6 against 0 was printed as the device). The quiet seeds must be read.
#[test]
fn a_noisy_matrix_fit_is_near_the_device_or_not_read() {
    let (mut read, mut nulled) = (0, 0);
    for seed in 0..12 {
        let noise = if seed % 2 == 0 { 1e-9 } else { 1e-11 };
        let extra = format!("\n[noise]\nseed = {seed}\ntia_current_noise_a_per_rthz = {noise:e}\n");
        let c = config(20.0, 2000.0, 0.0, 31, &extra);
        let r = frequency_response_from(&c, run_stepped_sine(&c, &|_, _| {}).unwrap());
        match &r.matrix {
            Some(mf) => {
                read += 1;
                for (k, f0) in [15000.0, 15020.0].into_iter().enumerate() {
                    assert!((mf.f0_hz[k] - f0).abs() < 3.75, "seed {seed}: {mf:?}");
                }
            }
            None => {
                nulled += 1;
                assert!(
                    r.measured
                        .warnings
                        .iter()
                        .any(|w| w.starts_with("matrix_fit is not read")),
                    "seed {seed}: {:?}",
                    r.measured.warnings
                );
            }
        }
    }
    assert!(read >= 6, "{read} read, {nulled} not");
}

/// On a mode-matched device |s| is the same for both eigenvalues up to the damping, so sorting
/// by it named them at random (mode 1's Q was given mode 2's). Weakly coupled, each coupled
/// mode is its configured one; coupled below the exceptional point, the eigenmode mode 1
/// dominates keeps the lighter damping when Q1 > Q2.
#[test]
fn coupled_modes_are_named_by_their_mode_shape_on_a_matched_device() {
    let weak = coupled_modes(&config(0.0, 1500.0, 1.0, 21, "").resonator_params());
    for (k, q) in [2000.0, 1500.0].into_iter().enumerate() {
        assert!((weak[k].0 / 15e3 - 1.0).abs() < 1e-9, "{weak:?}");
        assert!((weak[k].1 / q - 1.0).abs() < 1e-6, "{weak:?}");
    }
    let strong = coupled_modes(&config(0.0, 1500.0, 2e4, 21, "").resonator_params());
    assert!(strong[0].1 > strong[1].1, "{strong:?}");
}

/// At Q = 1 over 5 to 45 kHz (16 samples per period at 15 kHz) the DAC hold's images bias the
/// one-mode fit (f0 +380 Hz, 0.05 half-bandwidths, with no warning before); at Q = 2000 the
/// bias stays far below the 1 % stated.
#[test]
fn a_fit_the_dac_hold_biases_says_so() {
    let text = preset_text("m2tfg-sweep")
        .unwrap()
        .replacen("q = 36000.0", "q = 1.0", 1)
        .replacen("q_mode2 = 30000.0", "q_mode2 = 1.0", 1)
        .replacen(
            "quadrature_coupling_rad2_s2 = 2e4",
            "quadrature_coupling_rad2_s2 = 0.0",
            1,
        )
        .replacen("# start_hz = 14997.9167", "start_hz = 5000.0", 1)
        .replacen("# stop_hz = 15003.0001", "stop_hz = 45000.0", 1)
        .replacen("points = 61", "points = 41", 1)
        .replacen("spacing = \"resonance\"", "spacing = \"log\"", 1)
        .replacen("# average_s = 1.53", "average_s = 0.05", 1);
    let c = parse_config(&text).unwrap();
    c.validate_sweep().unwrap();
    let r = frequency_response_from(&c, run_stepped_sine(&c, &|_, _| {}).unwrap());
    let said = |r: &FrequencyResponse| warned(r, "zero-order hold biases its fit");
    assert_eq!(said(&r), 2, "{:?}", r.measured.warnings);
    let c = config(2.0, 1950.0, 0.0, 21, "");
    let r = frequency_response_from(&c, measure(&c));
    assert_eq!(said(&r), 0, "{:?}", r.measured.warnings);
}

/// On a matched device each driven response is half of each coupled mode: the one-mode fits
/// read a split of 0 where the stiffness eigenvalues are 0.84 Hz apart (k12 = 5e5, Q = 2000),
/// with sigmas from the model's error, not noise. Each mode says so. Modes 40 Hz apart with
/// a small coupling stay unwarned: their fits follow the coupled modes to within 1 % of a
/// half-bandwidth.
#[test]
fn a_fit_the_coupling_pulls_off_the_devices_modes_says_so() {
    let said = |r: &FrequencyResponse| warned(r, "quadrature coupling mixes both modes");
    let c = config(0.0, 2000.0, 5e5, 41, "");
    let r = coupled(&c);
    let eig = stiffness_modes_hz(&c);
    let (split, sigma) = r.mode_split_hz();
    assert!(eig[1] - eig[0] > 0.8, "{eig:?}");
    assert!(
        (split - (eig[1] - eig[0])).abs() > 100.0 * sigma,
        "the fit found the split: {split} +- {sigma} against {eig:?}"
    );
    assert_eq!(said(&r), 2, "{:?}", r.measured.warnings);
    let w0 = 2.0 * PI * 15e3;
    let c = config(40.0, 2000.0, 2.0 * w0 * 2.0 * PI * 5.0, 41, "");
    let r = coupled(&c);
    let eig = stiffness_modes_hz(&c);
    for (m, e) in r.modes.iter().zip(eig) {
        let off = (m.fit.unwrap().f0_hz - e).abs() / 3.75;
        assert!(off < 1e-2, "mode {}: {off} half-bandwidths", m.mode);
    }
    assert_eq!(said(&r), 0, "{:?}", r.measured.warnings);
}

/// A 4-bit DAC (step 0.25 against a drive of 1) rounds the 16-sample carrier at 15 kHz the
/// same way every period: the drive's fundamental is (2/16) sum q_n cos(2 pi n / 16) = 1.0728
/// of the nominal, and the sweep, which divides by the nominal drive, reads the resonance
/// 0.61 dB high. The config's rule states it for each drive before any sample; at 16 bits
/// it is silent.
#[test]
fn a_sweep_the_dacs_rounding_moves_says_so() {
    let text = |bits: u32| {
        preset_text("m2tfg-coriolis")
            .unwrap()
            .replacen("# dac_bits = 16", &format!("dac_bits = {bits} #"), 1)
            .replacen("dac_full_scale = 1.0", "dac_full_scale = 2.0", 1)
            + "\n[sweep]\npoints = 21\n"
    };
    let said = |w: &[String]| w.iter().filter(|w| w.contains("DAC's rounding")).count();
    let c = parse_config(&text(4)).unwrap();
    let warnings = c.validate_sweep().unwrap();
    assert_eq!(said(&warnings), 2, "{warnings:?}");
    let fundamental: f64 = (0..16)
        .map(|n| {
            let c = (2.0 * PI * n as f64 / 16.0).cos();
            (c / 0.25).round() * 0.25 * c
        })
        .sum::<f64>()
        / 8.0;
    assert!((fundamental - 1.0728).abs() < 1e-4, "{fundamental}");
    assert!(
        warnings[warnings.len() - 2..]
            .iter()
            .all(|w| w.contains(&format!("{:.2e}", fundamental - 1.0))),
        "{warnings:?}"
    );
    let m = run_stepped_sine(&c, &|_, _| {}).unwrap();
    let at = m.points.iter().find(|p| p.freq_hz == 15_000.0).unwrap();
    let plant = Resonator::<f64>::new(&c.resonator_params(), 0.0).unwrap();
    let want = held_response(&plant, 15_000.0, 0)[0];
    let read = at.response[0][0].norm() / want.norm();
    assert!(
        (read / fundamental - 1.0).abs() < 1e-4,
        "{read} {fundamental}"
    );
    let c = parse_config(&text(16)).unwrap();
    assert_eq!(said(&c.validate_sweep().unwrap()), 0);
}

/// The sweep preset's board with this device, without noise or converters changed.
fn sweep_preset(q: f64, q2: f64, k12: &str, points: usize) -> Config {
    let text = preset_text("m2tfg-sweep")
        .unwrap()
        .replacen("q = 36000.0", &format!("q = {q:?}"), 1)
        .replacen("q_mode2 = 30000.0", &format!("q_mode2 = {q2:?}"), 1)
        .replacen(
            "quadrature_coupling_rad2_s2 = 2e4",
            &format!("quadrature_coupling_rad2_s2 = {k12}"),
            1,
        )
        .replacen("points = 61", &format!("points = {points}"), 1);
    let c = parse_config(&text).unwrap();
    c.validate_sweep().unwrap();
    c
}

/// A fit's sigma is its scatter about the model; the DAC hold's bias is not in it. At Q = 10
/// each fitted f0 sits 1.3 Hz above the device's (1.7e-3 half-bandwidths, below the 1 % hold
/// rule) with a sigma of 0.3 Hz, and on the sweep preset (Q 36000 and 30000, k12 = 2e4) the
/// split is read 8 of its sigmas from the coupled modes'. Each says so; a fit whose bias is
/// inside 2 sigma, or below 1e-4 half-bandwidths (Q = 2000), does not.
#[test]
fn a_fit_whose_sigma_does_not_cover_the_methods_bias_says_so() {
    const NEEDLE: &str = "do not cover the method's bias";
    const SPLIT: &str = "split's sigma";
    let c = sweep_preset(10.0, 10.0, "0.0", 21);
    let r = frequency_response_from(&c, run_stepped_sine(&c, &|_, _| {}).unwrap());
    for (m, dev) in r.modes.iter().zip(stiffness_modes_hz(&c)) {
        let fit = m.fit.unwrap();
        let off = (fit.f0_hz - dev).abs();
        assert!(off > 2.0 * fit.f0_sigma_hz && off > 1e-4 * 750.0, "{fit:?}");
    }
    assert_eq!(warned(&r, NEEDLE), 2, "{:?}", r.measured.warnings);
    // Both modes move alike: the split is within its sigma of the device's, and unwarned.
    let (split, sigma) = r.mode_split_hz();
    assert!((split - 0.5).abs() < 2.0 * sigma, "{split} {sigma}");
    assert_eq!(warned(&r, SPLIT), 0, "{:?}", r.measured.warnings);

    let c = sweep_preset(36000.0, 30000.0, "2e4", 31);
    let r = frequency_response_from(&c, run_stepped_sine(&c, &|_, _| {}).unwrap());
    let eig = stiffness_modes_hz(&c);
    let (split, sigma) = r.mode_split_hz();
    // The damping moves the eigenvalues from the stiffness ones by O(f0 / Q^2), 1e-5 Hz.
    assert!(
        (split - (eig[1] - eig[0])).abs() > 5.0 * sigma + 2e-5,
        "{split} +- {sigma} against {eig:?}"
    );
    assert_eq!(warned(&r, SPLIT), 1, "{:?}", r.measured.warnings);

    let c = config(2.0, 1500.0, 0.0, 41, "");
    let r = frequency_response_from(&c, measure(&c));
    for m in &r.modes {
        let off = (m.fit.unwrap().f0_hz - m.configured_f0_hz).abs();
        assert!(off < 1e-4 * m.configured_half_bandwidth_hz(), "{m:?}");
    }
    assert_eq!(
        warned(&r, NEEDLE) + warned(&r, SPLIT),
        0,
        "{:?}",
        r.measured.warnings
    );
}

/// The number after `label` in `text`.
fn stated_after(text: &str, label: &str) -> f64 {
    let rest = &text[text.find(label).unwrap() + label.len()..];
    rest.split_whitespace().next().unwrap().parse().unwrap()
}

#[test]
fn the_hold_bias_of_the_matrix_fit_is_stated_and_is_what_the_emulation_reads() {
    // Q 2000 beside a mode 2 of Q 8 (coupled): the 2 x 2 fit read mode 1's f0 0.083
    // half-bandwidths off with masses within 0.1 % and no warning (the DAC's hold images:
    // 16 times smaller at 4 times the rate). The stated bias is the held theory's; the
    // noiseless emulation reads it.
    let cfg = config(0.0, 8.0, 1e6, 61, "");
    let r = coupled(&cfg);
    let fit = r.matrix.expect("a matrix fit");
    let w = r
        .measured
        .warnings
        .iter()
        .find(|w| w.starts_with("matrix_fit: the DAC's zero-order hold"))
        .unwrap_or_else(|| panic!("{:?}", r.measured.warnings));
    let b = cfg.device.f0_hz / (2.0 * cfg.device.q);
    let read = (fit.f0_hz[0] - cfg.device.f0_hz) / b;
    let stated = stated_after(w, "mode 1's f0 ");
    assert!(stated > 0.05, "{w}");
    assert!(
        (read - stated).abs() < 1e-3 * stated.abs().max(1.0),
        "read {read}, stated {stated}"
    );
    // The device of the fits test (Q 2000 and 2200, no coupling) is below the rule.
    let plain = coupled(&config(0.5, 2200.0, 0.0, 61, ""));
    assert_eq!(
        warned(&plain, "matrix_fit: the DAC"),
        0,
        "{:?}",
        plain.measured.warnings
    );
}
