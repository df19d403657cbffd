//! The closed forms against independent routes to the same numbers, away from the special
//! values (lambda = 1, F1 = F2, small rates) where a wrong factor cancels: the Coriolis phases
//! against the plant's steady state by a linear solve, psi against a mode's transfer function
//! at the two sidebands, the rate table's first-order response against its definition; and
//! the imperfect-device path against the closed forms as the imperfection goes to zero.

use core::f64::consts::{FRAC_PI_2, PI, TAU};
use gyroemu_resonator::{continuous_steady_state, ModeParams, ResonatorParams};
use gyroemu_theory::{
    coriolis_theta_rad, mechanical_tau_s, rate_table_gain, rotating_psi_rad, rotating_theta0_rad,
    DrivenDevice,
};
use num_complex::Complex64;

fn plant(f0_hz: f64, q: f64, lambda: f64) -> ResonatorParams {
    let mode = ModeParams { f0_hz, q };
    ResonatorParams {
        mode1: mode,
        mode2: mode,
        angular_gain: lambda,
        quadrature_coupling_rad2_s2: 0.0,
        transduction_a_s_per_m: 1e-6,
        fs_hz: 240e3,
    }
}

/// Phase lag of `x` behind `x0`, (-pi, pi].
fn lag(x: Complex64, x0: Complex64) -> f64 {
    (x0 / x).arg()
}

#[test]
fn coriolis_phases_are_the_plants_steady_state_lags() {
    for (f0, q, lambda) in [
        (15e3, 2000.0, 0.6),
        (1e3, 50.0, 0.83),
        (3.3e5, 36_000.0, 1.0),
    ] {
        let p = plant(f0, q, lambda);
        for (f1, f2) in [(1.0, 1.0), (1.0, 0.4), (2.5, 1.0)] {
            // Drive 2 is the quadrature of drive 1: F2 sin = Re{F2 e^{-j pi/2} e^{jwt}}.
            let force = [
                Complex64::new(f1, 0.0),
                Complex64::from_polar(f2, -FRAC_PI_2),
            ];
            let x0 = continuous_steady_state(&p, 0.0, f0, force);
            for rate_dps in [1.0, 30.0, 175.0, -60.0] {
                let omega = rate_dps * PI / 180.0;
                let x = continuous_steady_state(&p, omega, f0, force);
                let want = [lag(x[2], x0[2]), lag(x[3], x0[3])];
                let got = coriolis_theta_rad(f0, q, lambda, f1, f2, omega);
                for k in 0..2 {
                    assert!(
                        (got[k] - want[k]).abs() <= 1e-9 * want[k].abs().max(1e-6),
                        "f0 {f0}, Q {q}, lambda {lambda}, F {f1}/{f2}, {rate_dps} deg/s, mode \
                         {}: {} against {}",
                        k + 1,
                        got[k],
                        want[k]
                    );
                }
            }
        }
    }
}

#[test]
fn psi_is_the_mean_of_the_sidebands_phase_departures() {
    // One mode, H(w) = 1 / (w0^2 - w^2 + j w w0 / Q): the upper sideband lags the
    // resonance by d+, the lower leads it by d-, and psi = (d+ + d-) / 2. Rates up to a
    // third of w0, where the two sidebands' departures differ by tens of degrees.
    for (f0, q) in [(15e3, 2000.0), (1e3, 10.0), (2e5, 50.0)] {
        let w0 = TAU * f0;
        // At w = w0 + x, with w0^2 - w^2 written -x (2 w0 + x) so no digits cancel.
        let h = |x: f64| {
            Complex64::new(1.0, 0.0) / Complex64::new(-x * (2.0 * w0 + x), (w0 + x) * w0 / q)
        };
        for frac in [1e-5, 1e-3, 0.05, 0.33, -0.2] {
            let omega = frac * w0;
            let d_plus = lag(h(omega), h(0.0));
            let d_minus = lag(h(0.0), h(-omega));
            let want = 0.5 * (d_plus + d_minus);
            let got = rotating_psi_rad(f0, q, omega);
            assert!(
                (got - want).abs() <= 1e-12 * want.abs().max(1e-9),
                "f0 {f0}, Q {q}, Omega/w0 {frac}: {got} against {want}"
            );
        }
        // And theta0 is the envelope's lag 2 Q Omega / w0 under the tangent.
        let omega = 0.01 * w0;
        let want = (2.0 * q * omega / w0).atan();
        assert!((rotating_theta0_rad(f0, q, omega) - want).abs() <= 1e-15);
    }
}

#[test]
fn rate_table_gain_is_the_dc_slope_through_a_first_order_low_pass() {
    for (f0, q, lambda, fs, fo) in [(15e3, 2000.0, 0.7, 1.0, 0.5), (1e3, 100.0, 1.0, 2.0, 3.0)] {
        let tau = mechanical_tau_s(f0, q);
        assert!((tau - 2.0 * q / (TAU * f0)).abs() <= 1e-15 * tau);
        // The DC slope is the Coriolis phase's at small rates: theta of mode `self` for drives
        // (self, other), divided by the rate.
        let small = 1e-6;
        let slope = coriolis_theta_rad(f0, q, lambda, fs, fo, small)[0] / small;
        for table_hz in [0.0, 0.1 / tau, 1.0 / tau, 7.0 / tau] {
            let (gain, lag_rad) = rate_table_gain(f0, q, lambda, fs, fo, table_hz);
            let h = Complex64::new(1.0, 0.0) / Complex64::new(1.0, TAU * table_hz * tau);
            assert!(
                (gain - slope * h.norm()).abs() <= 1e-9 * gain,
                "{table_hz} Hz"
            );
            assert!((lag_rad + h.arg()).abs() <= 1e-15, "{table_hz} Hz");
        }
    }
}

fn driven(q: f64, lambda: f64, drive: [f64; 2]) -> DrivenDevice {
    DrivenDevice {
        plant: plant(15e3, q, lambda),
        drive,
        phase_shifter_error_deg: 0.0,
        carrier_hz: 15e3,
    }
}

#[test]
fn ideal_means_every_imperfection_exactly_zero() {
    let ideal = driven(2000.0, 0.8, [1.0, 0.5]);
    assert!(ideal.is_ideal());
    let mut each: Vec<DrivenDevice> = vec![ideal; 5];
    each[0].carrier_hz += 1e-9;
    each[1].plant.mode2.f0_hz += 1e-9;
    each[2].plant.mode2.q += 1e-9;
    each[3].plant.quadrature_coupling_rad2_s2 = 1e-12;
    each[4].phase_shifter_error_deg = 1e-12;
    for (i, d) in each.iter().enumerate() {
        assert!(!d.is_ideal(), "imperfection {i}");
    }
}

#[test]
fn the_imperfect_path_tends_to_the_closed_forms() {
    // A phase-shifter error of 1e-9 deg takes the plant's steady-state route: its phases must
    // be those of the closed forms to about that size, for both experiments and both modes.
    for (q, lambda, drive) in [(2000.0, 0.8, [1.0, 0.5]), (300.0, 1.0, [0.7, 1.3])] {
        let ideal = driven(q, lambda, drive);
        let mut near = ideal;
        near.phase_shifter_error_deg = 1e-9;
        assert!(!near.is_ideal());
        for rate_dps in [5.0, 100.0, -40.0] {
            let omega = rate_dps * PI / 180.0;
            let (a, b) = (
                ideal.coriolis_phase_rad(omega),
                near.coriolis_phase_rad(omega),
            );
            let (c, d) = (ideal.rotating_psi_rad(omega), near.rotating_psi_rad(omega));
            for k in 0..2 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-9,
                    "Coriolis mode {}: {a:?} {b:?}",
                    k + 1
                );
                assert!(
                    (c[k] - d[k]).abs() <= 1e-9,
                    "rotating mode {}: {c:?} {d:?}",
                    k + 1
                );
            }
        }
    }
}
