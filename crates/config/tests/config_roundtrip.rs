//! Property test over valid configs: serialising to TOML and parsing back gives the same
//! config, it validates, and 1e4 input samples of the board run without a panic and give
//! finite averages.

use gyroemu_board::{Board, Point, RunOptions};
use gyroemu_config::presets::preset;
use gyroemu_config::{
    parse_config, Config, ExperimentKind, NoiseConfig, RateTable, SelfcalConfig, WindowKind,
};
use gyroemu_lpf::Window;
use proptest::prelude::*;

/// Device and drive draws: f0, Q, lambda, mismatch (fraction of f0), Q of mode 2, k12
/// (fraction of w0^2), F1, F2.
type DeviceDraw = (f64, f64, f64, f64, Option<f64>, f64, f64, f64);
/// Board draws: fs/f0, decimation, cutoff (fraction of its limit), order, TIA pole (fraction
/// of Nyquist), TIA gain, inverting, DAC bits, ADC bits, phase-shifter error.
type BoardDraw = (
    f64,
    usize,
    f64,
    usize,
    Option<f64>,
    f64,
    bool,
    Option<u32>,
    Option<u32>,
    f64,
);
/// Experiment draws: kind (0 Coriolis, 1 rate table, 2 rotating), rates (fractions of their
/// limit, signed), average multiple, hann, settle_s, noise, selfcal.
type ExperimentDraw = (u8, Vec<f64>, f64, bool, Option<f64>, bool, bool);

fn device() -> impl Strategy<Value = DeviceDraw> {
    (
        1.0e3f64..1.0e5,
        10.0f64..5000.0,
        0.1f64..1.5,
        -0.01f64..0.01,
        proptest::option::of(10.0f64..5000.0),
        -1e-4f64..1e-4,
        0.1f64..10.0,
        0.1f64..10.0,
    )
}

fn board() -> impl Strategy<Value = BoardDraw> {
    (
        8.0f64..40.0,
        1usize..200,
        0.05f64..0.9,
        1usize..=8,
        proptest::option::of(0.1f64..0.95),
        1e3f64..1e7,
        any::<bool>(),
        // Converter bits, raised where the levels drawn need more (`build`).
        proptest::option::of(6u32..=32),
        proptest::option::of(6u32..=32),
        -10.0f64..10.0,
    )
}

fn experiment() -> impl Strategy<Value = ExperimentDraw> {
    (
        0u8..3,
        proptest::collection::vec(prop_oneof![-0.9f64..-0.05, 0.05f64..0.9], 1..5),
        1.0f64..3.0,
        any::<bool>(),
        proptest::option::of(0.0f64..2.0),
        any::<bool>(),
        any::<bool>(),
    )
}

/// A valid config built from the draws, starting from the Coriolis preset.
fn build(d: DeviceDraw, b: BoardDraw, e: ExperimentDraw) -> Config {
    let mut c = preset("m2tfg-coriolis").unwrap();
    let (f0, q, lambda, mismatch, q2, k12, f1, f2) = d;
    c.device.f0_hz = f0;
    c.device.q = q;
    c.device.angular_gain = lambda;
    c.device.mode2_f0_offset_hz = mismatch * f0;
    c.device.q_mode2 = q2;
    let w0 = std::f64::consts::TAU * f0;
    c.device.quadrature_coupling_rad2_s2 = k12 * w0 * w0;
    c.drive.f1 = f1;
    c.drive.carrier_hz = Some(f0); // the drawn f0 (the preset resolved its own)
    c.drive.f2 = Some(f2);

    let (fs_mult, dec, cut, order, pole, gain, inverting, dac, adc, shift) = b;
    let f_max = f0.max(c.f0_mode2_hz());
    c.board.fs_hz = Some(fs_mult * f_max);
    c.board.decimation = Some(dec);
    let nyq_out = 0.5 * c.fs_hz() / dec as f64;
    c.board.lpf_cutoff_hz = Some(cut * nyq_out.min(f0));
    c.board.lpf_order = order;
    c.board.tia_pole_hz = pole.map(|p| p * 0.5 * c.fs_hz());
    c.board.tia_gain_ohm = gain;
    c.board.tia_inverting = inverting;
    // Converters at least fine enough for the drawn ratio of the two channels' levels (with
    // four bits to spare): coarser ones would put out an all-zero channel, which validation
    // refuses, so such a draw is not a valid config.
    let bits_for = |ratio: f64| (ratio.log2().ceil() as u32 + 4).min(32);
    c.board.dac_bits = dac.map(|b| b.max(bits_for(1.5 * f1.max(f2) / f1.min(f2))));
    c.board.dac_full_scale = 1.5 * f1.max(f2);
    // The ADC's full scale at twice the TIA output at resonance (the larger mode).
    let amp = |f: f64, w: f64, q: f64| f * q / w * c.device.transduction_a_s_per_m * gain;
    let q2v = q2.unwrap_or(q);
    let w2 = std::f64::consts::TAU * c.f0_mode2_hz();
    let (a1, a2) = (amp(f1, w0, q), amp(f2, w2, q2v));
    c.board.adc_bits = adc.map(|b| b.max(bits_for(2.0 * a1.max(a2) / a1.min(a2))));
    c.board.adc_full_scale_v = 2.0 * a1.max(a2);
    c.board.phase_shifter_error_deg = shift;
    // Converter bits for what the run really sees below the resonance levels (validation weighs
    // the steady state at the carrier and every rate): mode 2 is |mismatch| off the carrier, a
    // rotating run's sidebands f_m off, and a Coriolis rate turns the phase by theta
    // (amplitude cos theta). Each lowers a level by at most 1 + 2 Q offset / f0 or 1 + tan.
    let raise = |c: &mut Config| {
        let qmax = q.max(q2v);
        let fm_max = match c.experiment.kind {
            ExperimentKind::Rotating => c.max_rate_rad_s() / std::f64::consts::TAU,
            ExperimentKind::Coriolis => 0.0,
        };
        let tan = 2.0 * qmax * lambda * c.max_rate_rad_s() / w0 * (f1 / f2).max(f2 / f1);
        let drop = 1.0 + 2.0 * qmax * ((mismatch * f0).abs() + fm_max) / f0 + tan;
        c.board.adc_bits = c
            .board
            .adc_bits
            .map(|b| (b + drop.log2().ceil() as u32).min(32));
    };

    let (kind, rates, avg_mult, hann, settle, noise, selfcal) = e;
    let cutoff = c.lpf_cutoff_hz();
    let fs = c.fs_hz();
    let x = &mut c.experiment;
    x.window = if hann {
        WindowKind::Hann
    } else {
        WindowKind::Boxcar
    };
    x.settle_s = settle;
    let out_period = dec as f64 / fs;
    match kind {
        0 => {
            x.kind = ExperimentKind::Coriolis;
            x.rate_table = RateTable::Constant;
            x.table_freq_hz = None;
            x.rates_dps = rates.iter().map(|r| r * 500.0).collect();
            x.average_s = avg_mult * out_period;
        }
        1 => {
            x.kind = ExperimentKind::Coriolis;
            x.rate_table = RateTable::Sinusoid;
            let ft = 0.5 * cutoff * rates[0].abs();
            x.table_freq_hz = Some(ft);
            // A table's rates are amplitudes (> 0).
            x.rates_dps = rates.iter().map(|r| r.abs() * 500.0).collect();
            x.average_s = avg_mult * (1.0 / ft).max(out_period);
        }
        _ => {
            x.kind = ExperimentKind::Rotating;
            x.rate_table = RateTable::Constant;
            x.table_freq_hz = None;
            // |rate|/360 below the cutoff.
            x.rates_dps = rates.iter().map(|r| r * 360.0 * cutoff).collect();
            let slowest = x.rates_dps.iter().map(|r| r.abs()).fold(f64::MAX, f64::min);
            // At least four output samples: a window of one keeps all of the 2 Omega term,
            // and the sidebands cannot be told apart (refused: a Hann window of 1.76 output
            // periods, one sample, was drawn at 209785 deg/s).
            x.average_s = avg_mult * (180.0 / slowest).max(4.0 * out_period);
        }
    }
    c.noise = noise.then_some(NoiseConfig {
        seed: (f0 * 1e3) as u64,
        temperature_k: 300.0,
        effective_mass_kg: Some(1e-9),
        tia_current_noise_a_per_rthz: 1e-12,
        tia_voltage_noise_v_per_rthz: 1e-8,
        ..Default::default()
    });
    c.selfcal = selfcal.then(|| SelfcalConfig {
        allan_record_s: Some(10.0f64.max(20.0 * out_period)),
        tau_max_s: Some(4.0),
        drift_delta_t_k: vec![-10.0, 25.0],
        f0_tc_ppm_per_k: -30.0,
        q_tc_ppm_per_k: -3000.0,
    });
    // A table swing that takes a mode's envelope around zero has no phase to read (refused),
    // so such a draw is no valid config: its amplitudes are halved until none does.
    if let Some(ft) = c.experiment.table_freq_hz {
        let winds = |c: &Config| {
            c.experiment.rates_dps.iter().any(|r| {
                let (amp, _) = c
                    .driven_device()
                    .rate_table_response(r.abs().to_radians(), ft);
                amp.iter().any(|a| a.is_nan())
            })
        };
        while winds(&c) {
            c.experiment.rates_dps.iter_mut().for_each(|r| *r *= 0.5);
        }
    }
    raise(&mut c);
    c
}

fn all_finite(z: &[gyroemu_core::Complex64]) -> bool {
    z.iter().all(|v| v.re.is_finite() && v.im.is_finite())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn valid_configs_round_trip_validate_and_run_finite(
        d in device(),
        b in board(),
        e in experiment(),
    ) {
        let cfg = build(d, b, e);
        let text = toml::to_string(&cfg).expect("serialises");
        let back = parse_config(&text).unwrap_or_else(|err| panic!("{err}\n{text}"));
        prop_assert_eq!(&back, &cfg);
        cfg.validate().unwrap_or_else(|err| panic!("{err}\n{text}"));

        // About 1e4 input samples: settling plus window plus the one extra output sample.
        let n_out = (10_000 / cfg.decimation() as u64).max(3);
        let n_settle = n_out / 2;
        let rate_rad_s = cfg.experiment.rates_dps[0].to_radians();
        let point = Point {
            rate_rad_s,
            window: Window::Boxcar {
                n: n_out - n_settle - 1,
                frac: 0.0,
            },
        };
        let mut board = Board::<f64>::new(&cfg.board_params(), &[rate_rad_s], &[0])
            .unwrap_or_else(|err| panic!("{err}\n{text}"));
        let lanes = board
            .run(n_settle, &[point], RunOptions::default(), &|_| {})
            .unwrap_or_else(|err| panic!("{err:?}\n{text}"))
            .lanes;
        prop_assert_eq!(lanes.len(), 1);
        let r = &lanes[0];
        for (name, v) in [("z", &r.z), ("c", &r.c), ("s", &r.s)] {
            prop_assert!(all_finite(v), "{} = {:?}\n{}", name, v, text);
        }
        for (md, h) in r.table_z.iter().enumerate() {
            prop_assert!(
                h.iter().all(|v| v.re.is_finite() && v.im.is_finite()),
                "table_z[{}] = {:?}\n{}", md, h, text
            );
        }
    }
}
