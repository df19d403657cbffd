//! The loop design and the loop filter against closed forms: the sampled loop's poles at
//! `e^{sT}` of the continuous design, the continuous gains in the limit `T -> 0`, the
//! `Kp >= 0` boundary at `2 zeta wn tau = 1`, the noise bandwidth by numerical integration,
//! the filter's response and first outputs by hand; then the limits (no wind-up), lock
//! detection, no-signal handling and the parameter errors.

use core::f64::consts::{PI, TAU};
use gyroemu_core::{Complex64, Response, Stage};
use gyroemu_pll::{LoopDesign, Pll, PllParams, MAX_NATURAL_PER_UPDATE};

/// The continuous closed-loop poles `s = -zeta wn +- wn sqrt(zeta^2 - 1)`.
fn continuous_poles(natural_hz: f64, zeta: f64) -> [Complex64; 2] {
    let wn = TAU * natural_hz;
    let root = Complex64::new(zeta * zeta - 1.0, 0.0).sqrt() * wn;
    [-zeta * wn + root, -zeta * wn - root]
}

#[test]
fn the_sampled_loop_has_its_poles_at_exp_s_t() {
    for &(fnat, zeta, tau, rate) in &[
        (1.0, 0.7, 0.3, 1000.0),
        (1.0, 0.4, 0.3, 1000.0),
        (2.5, 0.7, 0.0637, 1000.0),
        (20.0, 0.5, 0.05, 200.0),
        (3.0, 1.0, 0.2, 500.0),
        (3.0, 2.5, 0.2, 500.0),
        (0.01, 0.8, 36_000.0 / (PI * 15_000.0), 100.0),
    ] {
        let d = LoopDesign::new(fnat, zeta, tau, rate);
        let t = 1.0 / rate;
        let alpha = (-t / tau).exp();
        let g = tau * (1.0 - alpha);
        // z^2 + c1 z + c0 of the sampled loop with these gains (crate docs).
        let c1 = g * (d.kp_per_s + d.ki_t_per_s) - 1.0 - alpha;
        let c0 = alpha - g * d.kp_per_s;
        let p = continuous_poles(fnat, zeta).map(|s| (s * t).exp());
        let want_c1 = -(p[0] + p[1]).re;
        let want_c0 = (p[0] * p[1]).re;
        assert!((c1 - want_c1).abs() < 1e-14, "c1 {c1} vs {want_c1}");
        assert!((c0 - want_c0).abs() < 1e-14, "c0 {c0} vs {want_c0}");
        // 1 + c1 + c0 = (1 - p1)(1 - p2) is tiny for a slow loop: relative check.
        let want = ((Complex64::new(1.0, 0.0) - p[0]) * (Complex64::new(1.0, 0.0) - p[1])).re;
        let got = g * d.ki_t_per_s;
        assert!(((got - want) / want).abs() < 1e-9, "{got} vs {want}");
        for (a, b) in d.poles.iter().zip(&p) {
            assert!((a - b).norm() < 1e-14, "pole {a} vs {b}");
        }
    }
}

#[test]
fn the_gains_tend_to_the_continuous_design() {
    let (fnat, zeta, tau) = (1.3, 0.6, 0.25);
    let wn = TAU * fnat;
    let d = LoopDesign::new(fnat, zeta, tau, 1e6);
    let kp = 2.0 * zeta * wn - 1.0 / tau;
    assert!(
        ((d.kp_per_s - kp) / kp).abs() < 1e-4,
        "{} vs {kp}",
        d.kp_per_s
    );
    assert!(((d.ki_per_s2() - wn * wn) / (wn * wn)).abs() < 1e-4);
}

#[test]
fn kp_is_negative_exactly_below_2_zeta_wn_tau_1_and_refused_there() {
    let (zeta, tau, rate) = (0.7, 0.1, 1000.0);
    // 2 zeta wn tau = 1 at fn = 1 / (4 pi zeta tau).
    let f_edge = 1.0 / (4.0 * PI * zeta * tau);
    let above = LoopDesign::new(f_edge * (1.0 + 1e-6), zeta, tau, rate);
    let below = LoopDesign::new(f_edge * (1.0 - 1e-6), zeta, tau, rate);
    assert!(above.kp_per_s > 0.0 && below.kp_per_s < 0.0);
    assert!(Pll::new(&PllParams::new(1e3, rate, f_edge * (1.0 + 1e-6), zeta, tau)).is_ok());
    let e = Pll::new(&PllParams::new(1e3, rate, f_edge * (1.0 - 1e-6), zeta, tau)).unwrap_err();
    assert_eq!((e.stage, e.param), ("pll", "natural_hz"));
    assert!(
        e.rule.contains("proportional gain would be negative"),
        "{e}"
    );
}

#[test]
fn noise_bandwidth_matches_numerical_integration() {
    for &(fnat, zeta, tau) in &[(1.0, 0.7, 0.3), (4.0, 0.4, 0.0637), (0.5, 1.5, 10.0)] {
        let pll = Pll::new(&PllParams::new(1e3, 1e3, fnat, zeta, tau)).unwrap();
        let wn = TAU * fnat;
        let kp = 2.0 * zeta * wn - 1.0 / tau;
        let h2 = |f: f64| {
            let s = Complex64::new(0.0, TAU * f);
            ((kp * s + wn * wn) / (s * s + 2.0 * zeta * wn * s + wn * wn)).norm_sqr()
        };
        // f = fn tan(u), u in [0, pi/2): Simpson's rule on the smooth integrand.
        let n = 20_000;
        let du = 0.5 * PI / n as f64;
        let g = |u: f64| {
            if u >= 0.5 * PI {
                // |H|^2 -> Kp^2 / (2 pi f)^2 far out: the integrand's limit.
                kp * kp / (TAU * TAU * fnat)
            } else {
                let c = u.cos();
                h2(fnat * u.tan()) * fnat / (c * c)
            }
        };
        let sum: f64 = (0..=n)
            .map(|i| {
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * g(i as f64 * du)
            })
            .sum();
        let numeric = sum * du / 3.0;
        let b = pll.noise_bandwidth_hz();
        assert!(((b - numeric) / numeric).abs() < 1e-8, "{b} vs {numeric}");
    }
}

#[test]
fn response_is_the_pi_closed_form() {
    let p = PllParams::new(1e3, 800.0, 3.0, 0.8, 0.1);
    let pll = Pll::new(&p).unwrap();
    let d = *pll.design();
    for f in [1e-6, 0.37, 3.0, 55.5, -17.0, 399.9, 400.0, 1234.5] {
        // 1 / (1 - e^{-jw}) = 1/2 - (j/2) cot(w/2): free of the cancellation near DC.
        let w = TAU * f / p.update_rate_hz;
        let integ = Complex64::new(0.5, -0.5 / (0.5 * w).tan()) * d.ki_t_per_s;
        let want = (integ + d.kp_per_s) / TAU;
        let got = pll.response(f);
        assert!(
            (got - want).norm() <= 1e-12 * want.norm(),
            "f {f}: {got} vs {want}"
        );
    }
    assert!(pll.response(0.0).norm().is_infinite());
    assert!(pll.response(800.0).norm().is_infinite());
}

#[test]
fn first_outputs_follow_the_pi_by_hand_and_the_sign_pulls_toward_resonance() {
    // A phase lead of the response (e > 0) means the carrier is below the resonance: the
    // frequency must go up.
    let mut p = PllParams::new(1e3, 1e3, 2.0, 0.7, 0.2);
    p.phase_offset_rad = 1.0;
    let mut pll = Pll::new(&p).unwrap();
    assert_eq!(pll.latency_samples(), 0.0);
    assert_eq!(pll.frequency_hz(), 1e3);
    let d = *pll.design();
    let errors = [0.1, 0.1, -0.05, 0.0];
    let mut integ = 0.0;
    for (k, e) in errors.into_iter().enumerate() {
        let f = pll.tick(Complex64::from_polar(2.0, 1.0 + e));
        integ += d.ki_t_per_s * e;
        let want = 1e3 + (d.kp_per_s * e + integ) / TAU;
        assert!((f - want).abs() < 1e-12, "tick {k}: {f} vs {want}");
        assert!((pll.phase_error_rad() - e).abs() < 1e-15);
        if k == 0 {
            assert!(f > 1e3);
        }
    }
    // The phase error wraps: an input just past pi from the offset reads as near -pi.
    pll.tick(Complex64::from_polar(1.0, 1.0 + PI + 0.01));
    assert!((pll.phase_error_rad() - (0.01 - PI)).abs() < 1e-12);
}

#[test]
fn limits_hold_the_output_without_wind_up() {
    let mut p = PllParams::new(1e3, 1e3, 2.0, 0.7, 0.2);
    p.min_hz = Some(999.0);
    p.max_hz = Some(1000.5);
    let mut pll = Pll::new(&p).unwrap();
    let z = |e: f64| Complex64::from_polar(1.0, e);
    // A constant lead drives the frequency up onto the limit and holds it there.
    let mut first_at_limit = None;
    for k in 0..5000 {
        let f = pll.tick(z(0.5));
        assert!(f <= 1000.5);
        if pll.at_limit() && first_at_limit.is_none() {
            first_at_limit = Some(k);
        }
    }
    assert!(first_at_limit.is_some() && pll.frequency_hz() == 1000.5);
    assert!(!pll.is_locked());
    // Without wind-up the integrator stopped where the output reached the limit, so the
    // first lag brings the output off it at once.
    let f = pll.tick(z(-0.05));
    assert!(f < 1000.5 && !pll.at_limit(), "{f}");
    // Same at the lower limit.
    for _ in 0..5000 {
        pll.tick(z(-0.5));
    }
    assert_eq!(pll.frequency_hz(), 999.0);
    assert!(pll.tick(z(0.05)) > 999.0);
}

#[test]
fn lock_needs_a_run_of_small_errors_and_a_signal() {
    let mut p = PllParams::new(1e3, 1e3, 2.0, 0.7, 0.2);
    p.lock_threshold_rad = 0.02;
    p.lock_updates = 10;
    p.min_amplitude = 1e-3;
    let mut pll = Pll::new(&p).unwrap();
    let z = |e: f64| Complex64::from_polar(1.0, e);
    for k in 1..=10 {
        pll.tick(z(0.01));
        assert_eq!(pll.is_locked(), k == 10, "tick {k}");
    }
    pll.tick(z(0.03));
    assert!(!pll.is_locked());
    for _ in 0..10 {
        pll.tick(z(-0.019));
    }
    assert!(pll.is_locked());
    // No signal: the frequency and integrator hold, the lock drops.
    let held = pll.frequency_hz();
    let integ = pll.integrator_hz();
    for bad in [
        Complex64::new(0.0, 0.0),
        Complex64::from_polar(1e-3, 0.5),
        Complex64::new(f64::NAN, 0.0),
        Complex64::new(f64::INFINITY, 1.0),
    ] {
        assert_eq!(pll.tick(bad), held);
        assert!(!pll.has_signal() && !pll.is_locked() && pll.phase_error_rad() == 0.0);
        assert_eq!(pll.integrator_hz(), integ);
    }
    pll.tick(Complex64::from_polar(1.1e-3, 0.0));
    assert!(pll.has_signal());
}

#[test]
fn bad_parameters_are_refused_naming_them() {
    let ok = {
        let mut p = PllParams::new(15e3, 1e3, 1.0, 0.7, PllParams::tau_s_of(15e3, 20_000.0));
        p.lowpass_delay_s = 1e-3;
        p.min_hz = Some(14e3);
        p.max_hz = Some(16e3);
        p
    };
    assert!(ok.validate().is_ok() && Pll::new(&ok).is_ok());
    type Edit = fn(&mut PllParams);
    let cases: [(&str, Edit); 20] = [
        ("carrier_hz", |p| p.carrier_hz = f64::NAN),
        ("update_rate_hz", |p| p.update_rate_hz = 0.0),
        ("update_rate_hz", |p| p.update_rate_hz = f64::INFINITY),
        ("natural_hz", |p| p.natural_hz = -1.0),
        ("natural_hz", |p| p.natural_hz = 101.0), // above update_rate / 10
        ("natural_hz", |p| p.lowpass_delay_s = 0.01), // wn d = 0.063 rad
        ("natural_hz", |p| p.natural_hz = 0.01),  // 2 zeta wn tau < 1
        ("damping", |p| p.damping = 0.0),
        ("damping", |p| p.damping = f64::NAN),
        ("tau_s", |p| p.tau_s = 0.0),
        ("phase_offset_rad", |p| p.phase_offset_rad = f64::INFINITY),
        ("lowpass_delay_s", |p| p.lowpass_delay_s = -1e-3),
        ("min_hz", |p| p.min_hz = Some(15e3)),
        ("min_hz", |p| p.min_hz = Some(f64::NAN)),
        ("max_hz", |p| p.max_hz = Some(14e3)),
        ("max_hz", |p| p.max_hz = Some(f64::INFINITY)),
        ("lock_threshold_rad", |p| p.lock_threshold_rad = 0.0),
        ("lock_threshold_rad", |p| p.lock_threshold_rad = 4.0),
        ("lock_updates", |p| p.lock_updates = 0),
        ("min_amplitude", |p| p.min_amplitude = -1.0),
    ];
    for (param, edit) in cases {
        let mut p = ok;
        edit(&mut p);
        let e = Pll::new(&p).unwrap_err();
        assert_eq!((e.stage, e.param), ("pll", param), "{e}");
        let m = e.to_string();
        assert!(m.contains(param) && m.contains("must"), "{m}");
    }
    // The defaults: lock over one natural period.
    assert_eq!(ok.lock_updates, 1000);
    assert!((PllParams::tau_s_of(1e3, 1e3) - 2.0 * 1e3 / (TAU * 1e3)).abs() < 1e-15);
}

#[test]
fn each_rule_holds_its_bound_on_the_side_its_message_states() {
    let (carrier, rate, zeta, tau) = (1e3, 1000.0, 0.7, 0.5);
    // "at most MAX x update_rate_hz": the bound itself is accepted.
    let edge = MAX_NATURAL_PER_UPDATE * rate;
    assert!(Pll::new(&PllParams::new(carrier, rate, edge, zeta, tau)).is_ok());
    let above = f64::from_bits(edge.to_bits() + 1);
    assert!(Pll::new(&PllParams::new(carrier, rate, above, zeta, tau)).is_err());
    // "at least 1 / (4 pi tau_s)" for natural_hz x damping: 2 zeta wn tau = 1 exactly passes.
    let fnat = 2.0;
    let wn = TAU * fnat;
    let mut t = 1.0 / (2.0 * zeta * wn);
    for _ in 0..8 {
        if 2.0 * zeta * wn * t < 1.0 {
            t = f64::from_bits(t.to_bits() + 1);
        }
    }
    assert_eq!(
        2.0 * zeta * wn * t,
        1.0,
        "no tau_s hits the edge exactly here"
    );
    assert!(Pll::new(&PllParams::new(carrier, rate, fnat, zeta, t)).is_ok());
    let below = f64::from_bits(t.to_bits() - 1);
    assert!(2.0 * zeta * wn * below < 1.0);
    assert!(Pll::new(&PllParams::new(carrier, rate, fnat, zeta, below)).is_err());
    // "above carrier_hz" and "below carrier_hz": the carrier itself is refused by both.
    let mut p = PllParams::new(carrier, rate, 2.0, zeta, tau);
    p.max_hz = Some(carrier);
    assert_eq!(Pll::new(&p).unwrap_err().param, "max_hz");
    p.max_hz = Some(f64::from_bits(carrier.to_bits() + 1));
    assert!(Pll::new(&p).is_ok());
    p.min_hz = Some(carrier);
    assert_eq!(Pll::new(&p).unwrap_err().param, "min_hz");
}

#[test]
fn the_integrators_share_is_what_the_output_holds_beyond_the_proportional_term() {
    // Unlimited, the output is carrier + (Kp e + sum Ki T e) / (2 pi): the integrator's share
    // after n updates of errors e_i is sum Ki T e_i / (2 pi), and the rest is Kp e / (2 pi).
    let mut pll = Pll::new(&PllParams::new(1e3, 1000.0, 2.0, 0.7, 0.5)).unwrap();
    let (kp, ki_t) = (pll.design().kp_per_s, pll.design().ki_t_per_s);
    assert_eq!(pll.integrator_hz(), 0.0);
    let mut sum = 0.0;
    for k in 0..50 {
        let out = pll.tick(Complex64::from_polar(2.0, 0.3 - 0.01 * k as f64));
        let e = pll.phase_error_rad();
        sum += ki_t * e;
        assert!(!pll.at_limit());
        let want = sum / TAU;
        assert!(
            (pll.integrator_hz() - want).abs() <= 1e-12 * want.abs().max(1e-3),
            "update {k}"
        );
        let rest = out - 1e3 - pll.integrator_hz();
        assert!((rest - kp * e / TAU).abs() <= 1e-9, "update {k}: {rest}");
    }
}
