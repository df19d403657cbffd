//! The converter and rail rules weigh the TIA output the run really has: the steady state of the
//! configured device at the carrier (detuned or not), at every rate of the run, through the
//! DAC hold and the TIA. Each amplitude stated is checked against an independent closed form:
//! the 2-DOF phasor solve of THEORY.md section 2 (eq. 1 at the carrier), the hold's sinc and
//! the one-pole TIA recursion's exact |H|.

use gyroemu_config::{parse_config, Config};
use gyroemu_core::Complex64;
use std::f64::consts::PI;

/// The m2tfg-coriolis board (Q = 2000, lambda = 1, F1 = F2 = 1, 1 uA s/m, 1 MOhm, pole 60 kHz,
/// fs 240 kHz) with `extra` added to `[board]`, the carrier at `carrier_hz` and the given rates.
fn coriolis(carrier_hz: f64, extra: &str, rates: &str, noise: bool) -> Config {
    let noise = if noise {
        "[noise]\ntia_current_noise_a_per_rthz = 1e-15\n"
    } else {
        ""
    };
    parse_config(&format!(
        "[device]\nf0_hz = 15000.0\nq = 2000.0\nangular_gain = 1.0\ntransduction_a_s_per_m = 1e-6\n\
         [drive]\nf1 = 1.0\nf2 = 1.0\ncarrier_hz = {carrier_hz:?}\n\
         [board]\nfs_hz = 240000.0\ntia_gain_ohm = 1e6\ntia_pole_hz = 60000.0\nlpf_order = 4\n\
         lpf_cutoff_hz = 200.0\ndecimation = 100\n{extra}\n\
         [experiment]\nkind = \"coriolis\"\nrates_dps = {rates}\naverage_s = 2.0\n{noise}"
    ))
    .unwrap()
}

/// The TIA output amplitude, V, at `rate_dps` and carrier `fc` of the board above: eq. 1 in
/// phasors, `d X1 - c X2 = F1`, `c X1 + d X2 = F2` with `d = w0^2 - w^2 + j w w0/Q`,
/// `c = 2 lambda Omega j w`, F2 = -j F1 (the sin drive); velocity `j w X`; then 1 uA s/m,
/// 1 MOhm, the hold |sin(pi f Ts)/(pi f Ts)| and the recursion `y = a y + (1 - a) G x`,
/// |H| = (1 - a)/|1 - a e^{-j w Ts}|, a = e^{-2 pi 60 kHz Ts}.
fn tia_amplitude(fc: f64, rate_dps: f64) -> [f64; 2] {
    let (w0, w, ts) = (2.0 * PI * 15e3, 2.0 * PI * fc, 1.0 / 240e3);
    let j = Complex64::new(0.0, 1.0);
    let d = w0 * w0 - w * w + j * w * w0 / 2000.0;
    let c = 2.0 * rate_dps.to_radians() * j * w;
    let (f1, f2) = (Complex64::new(1.0, 0.0), -j);
    let det = d * d + c * c;
    let x = [(d * f1 + c * f2) / det, (d * f2 - c * f1) / det];
    let a = (-2.0 * PI * 60e3 * ts).exp();
    let tia = (1.0 - a) / (1.0 - a * (-j * w * ts).exp()).norm();
    let hold = (PI * fc * ts).sin() / (PI * fc * ts);
    x.map(|x| (j * w * x).norm() * 1e-6 * 1e6 * tia * hold)
}

/// The number after `(about ` and the rate after `V at ` in the warning of mode `k` holding
/// `needle`.
fn stated(w: &[String], needle: &str, k: usize) -> (f64, f64) {
    let m = format!("mode {k} (about ");
    let s = w
        .iter()
        .find(|s| s.contains(needle) && s.contains(&m))
        .unwrap_or_else(|| panic!("no '{needle}' warning for mode {k}: {w:?}"));
    let rest = &s[s.find(&m).unwrap() + m.len()..];
    let (amp, rest) = rest.split_once(" V at ").unwrap();
    let (rate, _) = rest.split_once(" deg/s").unwrap();
    (amp.parse().unwrap(), rate.parse().unwrap())
}

#[test]
fn a_detuned_carrier_states_the_adc_bound_from_the_smallest_real_amplitude() {
    // 200 Hz above f0 (53 half-bandwidths): the TIA output is about 0.39 mV, not the 21 mV at
    // resonance the rule used to weigh (it stated 85 mdeg where the run erred by 142 mdeg).
    let rates = [100.0, 500.0, 1000.0, 2000.0, 4000.0, 8000.0];
    let c = coriolis(
        15200.0,
        "adc_bits = 16\nadc_full_scale_v = 1.0",
        &format!("{rates:?}"),
        false,
    );
    let w = c.validate().unwrap();
    let lsb = 1.0 / 32768.0;
    for k in 0..2 {
        // The smallest amplitude over the run's points, zero rate included.
        let (want, at) = std::iter::once(0.0)
            .chain(rates)
            .map(|r| (tia_amplitude(15200.0, r)[k], r))
            .fold(
                (f64::INFINITY, f64::NAN),
                |m, x| if x.0 < m.0 { x } else { m },
            );
        let (amp, rate) = stated(&w, "rounding error", k + 1);
        assert!(
            (amp / want - 1.0).abs() < 1e-9,
            "mode {k}: {amp} against {want}"
        );
        assert_eq!(rate, at);
        assert!(amp < 4e-4, "{amp}");
        // The stated bound is asin(LSB / A) of that amplitude (THEORY of the quantiser: twice
        // the half-LSB bias over the amplitude).
        let bound_mdeg = (lsb / want).asin().to_degrees() * 1e3;
        assert!(
            w.iter().any(|s| s.contains(&format!("mode {}", k + 1))
                && s.contains(&format!("{bound_mdeg:.3e} mdeg"))),
            "{w:?} against {bound_mdeg:.3e}"
        );
        // The run measured errors up to 142 mdeg: the bound covers them.
        assert!(bound_mdeg > 142.0, "{bound_mdeg}");
    }
}

#[test]
fn the_rail_rule_weighs_the_largest_amplitude_rotation_gives_a_detuned_device() {
    // Carrier 7.5 Hz (two half-bandwidths) above f0: rotation splits the modes by about
    // +-lambda Omega, and at 2700 deg/s (7.5 Hz) one of them sits on the carrier, so the
    // amplitude rises well above the zero-rate one.
    let fc = 15007.5;
    let rates = [-2700.0, 0.0, 900.0, 2700.0];
    let amps: Vec<[f64; 2]> = rates.iter().map(|&r| tia_amplitude(fc, r)).collect();
    for k in 0..2 {
        let (max, at) = rates
            .iter()
            .zip(&amps)
            .map(|(&r, a)| (a[k], r))
            .fold((0.0, f64::NAN), |m, x| if x.0 > m.0 { x } else { m });
        assert!(max > 1.5 * amps[1][k], "the test's premise: {amps:?}");
        // A rail between the zero-rate amplitude and the largest: stated at the largest.
        let rail = 0.5 * (max + amps[1][k]);
        let c = coriolis(
            fc,
            &format!("tia_rail_v = {rail:?}"),
            &format!("{rates:?}"),
            false,
        );
        let w = c.validate().unwrap();
        let (amp, rate) = stated(&w, "tia_rail_v", k + 1);
        assert!(
            (amp / max - 1.0).abs() < 1e-9,
            "mode {k}: {amp} against {max}"
        );
        assert_eq!(rate, at);
        // Above the largest: nothing to say (the resonance amplitude, 20.6 mV, used to be).
        let c = coriolis(
            fc,
            &format!("tia_rail_v = {:?}", 1.01 * max),
            "[0.0, 900.0]",
            false,
        );
        let w = c.validate().unwrap();
        assert!(!w.iter().any(|s| s.contains("tia_rail_v")), "{w:?}");
    }
    // The ADC's range likewise: at 16000 Hz the output is 79 uV, inside 0.1 mV (the
    // resonance's 21 mV used to clip it) and beyond 50 uV.
    let c = coriolis(
        16000.0,
        "adc_bits = 24\nadc_full_scale_v = 5e-5",
        "[25.0]",
        false,
    );
    let clip = c.validate().unwrap();
    let c = coriolis(
        16000.0,
        "adc_bits = 24\nadc_full_scale_v = 1e-4",
        "[25.0]",
        false,
    );
    assert!(clip.iter().any(|s| s.contains("ADC's range")), "{clip:?}");
    assert!(!c
        .validate()
        .unwrap()
        .iter()
        .any(|s| s.contains("ADC's range")));
}

#[test]
fn a_signal_below_half_an_lsb_is_called_dead_without_noise_and_dithered_with_it() {
    // 16 kHz carrier: 79 uV of TIA output against a half LSB of 244 uV (12 bits, 1 V), 0.32
    // LSB: warned, not refused (the refusal is kept for a clearly dead ADC, below 1/8 LSB).
    let adc = "adc_bits = 12\nadc_full_scale_v = 1.0";
    let want = tia_amplitude(16000.0, 75.0)[0];
    assert!(want > 0.125 / 2048.0 && want < 0.5 / 2048.0, "{want}");
    let w = coriolis(16000.0, adc, "[25.0, 75.0]", false)
        .validate()
        .unwrap();
    let dead: Vec<&String> = w
        .iter()
        .filter(|s| s.contains("below half an LSB"))
        .collect();
    assert_eq!(dead.len(), 2, "{w:?}");
    assert!(
        dead.iter()
            .all(|s| s.contains("every sample there reads 0") && !s.contains("dither of the noise")),
        "{dead:?}"
    );
    let (amp, _) = stated(&w, "below half an LSB", 1);
    assert!((amp / want - 1.0).abs() < 1e-9, "{amp} against {want}");
    let w = coriolis(16000.0, adc, "[25.0, 75.0]", true)
        .validate()
        .unwrap();
    assert!(
        w.iter()
            .any(|s| s.contains("below half an LSB") && s.contains("dither of the noise")),
        "{w:?}"
    );
    // At 1/10 LSB without noise: refused, naming the key.
    let e = coriolis(
        16000.0,
        "adc_bits = 12\nadc_full_scale_v = 3.2",
        "[25.0]",
        false,
    )
    .validate()
    .unwrap_err();
    assert_eq!(e.key.as_deref(), Some("board.adc_bits"), "{e}");
}
