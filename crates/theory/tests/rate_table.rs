//! The exact rate-table response (harmonic balance + phase fundamental) against its two
//! closed-form limits: the small-signal first-order low-pass of THEORY.md section 3, and the
//! quasi-static limit where the phase is eqs. 2-3 at every instant, theta = atan(c sin w_t t),
//! whose fundamental is 2 (sqrt(1 + c^2) - 1) / c (the Fourier series of atan(c sin x)).

use gyroemu_resonator::{ModeParams, ResonatorParams};
use gyroemu_theory::{rate_table_gain, DrivenDevice};
use std::f64::consts::PI;

fn fork(q: f64) -> DrivenDevice {
    let mode = ModeParams { f0_hz: 15e3, q };
    DrivenDevice {
        plant: ResonatorParams {
            mode1: mode,
            mode2: mode,
            angular_gain: 1.0,
            quadrature_coupling_rad2_s2: 0.0,
            transduction_a_s_per_m: 1e-6,
            fs_hz: 240e3,
        },
        drive: [1.0, 1.0],
        phase_shifter_error_deg: 0.0,
        carrier_hz: 15e3,
    }
}

#[test]
fn small_swings_follow_the_first_order_low_pass() {
    let dev = fork(36_000.0);
    for table_hz in [0.05, 0.21, 2.0, 10.0] {
        let amp = 1e-3; // rad/s: a phase swing of a few microradians
        let (a, lag) = dev.rate_table_response(amp, table_hz);
        let (g, l) = rate_table_gain(15e3, 36_000.0, 1.0, 1.0, 1.0, table_hz);
        for k in 0..2 {
            // The envelope model drops a'' beside 2 j w0 a': relative terms of order f_t/f0.
            assert!(
                (a[k] / (g * amp) - 1.0).abs() < 1e-3,
                "{table_hz} Hz: {a:?} vs {}",
                g * amp
            );
            assert!((lag[k] - l).abs() < 1e-3, "{table_hz} Hz: {lag:?} vs {l}");
        }
    }
}

#[test]
fn quasi_static_swings_are_atan_of_the_rate() {
    // Q = 2000: corner f0/(2Q) = 3.75 Hz; a 1 mHz table is quasi-static to (w_t tau)^2 ~ 1e-7.
    let (q, table_hz) = (2000.0, 1e-3);
    let dev = fork(q);
    let w0 = 2.0 * PI * 15e3;
    for swing_deg in [5.0f64, 40.0, 70.0] {
        let c = swing_deg.to_radians().tan();
        let amp = c * w0 / (2.0 * q); // rad/s with 2 Q lambda A / w0 = c
        let (a, lag) = dev.rate_table_response(amp, table_hz);
        let want = 2.0 * ((1.0 + c * c).sqrt() - 1.0) / c;
        for k in 0..2 {
            assert!(
                (a[k] - want).abs() < 1e-6 * want,
                "{swing_deg}: {} vs {want}",
                a[k]
            );
            assert!(lag[k].abs() < 1e-3, "{swing_deg}: lag {}", lag[k]);
        }
    }
}

#[test]
fn remembered_responses_are_the_solved_ones() {
    // The same device and table asked again, after other devices (a mistuned mode, a
    // coupling of -0 beside +0, other amplitudes) and after more than the memo holds: every
    // answer has the bits of a fresh solve, and a device one field apart gets its own.
    let bits = |r: ([f64; 2], [f64; 2])| [r.0[0], r.0[1], r.1[0], r.1[1]].map(f64::to_bits);
    let base = fork(36_000.0);
    let mut detuned = base;
    detuned.plant.mode2.f0_hz += 0.5;
    let mut minus_zero = base;
    minus_zero.plant.quadrature_coupling_rad2_s2 = -0.0;
    let devices = [base, detuned, minus_zero];
    let asks: Vec<(DrivenDevice, f64)> = (0..gyroemu_theory::MEMO_LEN + 6)
        .map(|i| (devices[i % 3], 0.01 * (1 + i % 5) as f64))
        .chain((0..gyroemu_theory::MEMO_LEN + 3).map(|i| (base, 0.2 + 1e-3 * i as f64)))
        .chain([(base, 0.01), (detuned, 0.01), (minus_zero, 0.02)])
        .collect();
    for (dev, amp) in asks {
        let want = bits(dev.rate_table_response_solved(amp, 2.0));
        assert_eq!(
            bits(dev.rate_table_response(amp, 2.0)),
            want,
            "{dev:?} {amp}"
        );
    }
    // The detuned device reads otherwise than the matched one (the memo keeps them apart).
    assert_ne!(
        bits(detuned.rate_table_response(0.01, 2.0)),
        bits(base.rate_table_response(0.01, 2.0))
    );
}
