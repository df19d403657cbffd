//! The drive-amplitude AGC: the stage contract, its design against closed forms (the sampled
//! loop's poles at `e^{sT}`), and closed around the chain of the real stages (tests/common):
//! the amplitude's response to a step of the setpoint against the linear models, and
//! acquisition from rest, alone and together with the PLL from a detuned carrier.

mod common;

use common::models::{continuous_step, sampled_loop, worst_difference, AGC};
use common::{Loop, Setup};
use core::f64::consts::TAU;
use gyroemu_core::check::{self, FnResponse, Gen};
use gyroemu_core::{Complex64, Response, Stage};
use gyroemu_pll::{Agc, AgcParams, LoopDesign};

fn params() -> AgcParams {
    let mut p = AgcParams::new(1000.0, 2.0, 0.7, 0.5, 1.0, 4.0);
    p.min_gain = 0.25;
    p.min_amplitude = 1e-3;
    p
}

/// Amplitudes from 0 to 3 (now and then zero, not finite, or at the no-signal floor), so the
/// gain runs into both limits and out again.
fn input(g: &mut Gen) -> Complex64 {
    let pick = g.unit();
    if pick < 0.02 {
        Complex64::new(0.0, 0.0)
    } else if pick < 0.03 {
        Complex64::new(1.0, f64::INFINITY)
    } else if pick < 0.04 {
        Complex64::new(1e-3, 0.0)
    } else {
        g.phasor() * g.uniform(0.0, 3.0)
    }
}

#[test]
fn blocks_and_reset_are_bit_exact() {
    let agc = Agc::new(&params()).unwrap();
    check::tick_vs_process("agc", &agc, input, check::same);
    check::reset_restores("agc", &agc, input, check::same);
    // reset also restores a changed setpoint.
    let mut used = agc.clone();
    used.set_setpoint(2.0).unwrap();
    used.tick(Complex64::new(0.5, 0.0));
    used.reset();
    let mut fresh = agc.clone();
    for k in 0..100 {
        let z = Complex64::from_polar(0.5 + 0.01 * k as f64, 0.3);
        assert_eq!(used.tick(z), fresh.tick(z));
    }
}

/// The log gain's first difference against `(1 - e^{-jwT})` times the stage's response
/// (the PI's integrator never decays, its difference does).
#[test]
fn differenced_log_gain_response_matches_the_impulse_response() {
    let mut p = params();
    p.min_gain = 0.0;
    p.max_gain = 1e300;
    let agc = Agc::new(&p).unwrap();
    let ki_t = agc.design().ki_t_per_s;
    let mut s = agc.clone();
    let mut prev = 0.0;
    // An error of x neper is an amplitude setpoint e^{-x}.
    let adapter = |x: f64| {
        let lg = s.tick(Complex64::new((-x).exp(), 0.0)).ln();
        let y = lg - prev;
        prev = lg;
        y
    };
    let differenced = FnResponse(|f_hz: f64| {
        if f_hz == 0.0 {
            Complex64::new(ki_t, 0.0)
        } else {
            let w = TAU * f_hz / p.update_rate_hz;
            (Complex64::new(1.0, 0.0) - Complex64::from_polar(1.0, -w)) * agc.response(f_hz)
        }
    });
    let worst = check::response_matches_impulse("agc", 1000.0, &differenced, adapter, 64, 1e-12);
    println!("worst |DFT - H| / peak: {worst:e}");
}

/// The AGC's sampled loop `x[k+1] = alpha x[k] + (1 - alpha) ln g[k]` (the envelope's gain
/// is 1 in logs) with its gains has the continuous design's poles `e^{sT}`, and its gains tend
/// to `Kp = 2 zeta wn tau - 1`, `Ki = wn^2 tau`.
#[test]
fn the_sampled_amplitude_loop_has_its_poles_at_exp_s_t() {
    for &(fnat, zeta, tau, rate) in &[(1.0, 0.7, 0.3, 1000.0), (5.0, 0.4, 0.2, 400.0)] {
        let mut p = params();
        (p.natural_hz, p.damping, p.tau_s, p.update_rate_hz) = (fnat, zeta, tau, rate);
        let d = *Agc::new(&p).unwrap().design();
        let t = 1.0 / rate;
        let alpha = (-t / tau).exp();
        let c1 = (1.0 - alpha) * (d.kp_per_s + d.ki_t_per_s) - 1.0 - alpha;
        let c0 = alpha - (1.0 - alpha) * d.kp_per_s;
        let wn = TAU * fnat;
        let root = Complex64::new(zeta * zeta - 1.0, 0.0).sqrt() * wn;
        let p1 = ((-zeta * wn + root) * t).exp();
        let p2 = ((-zeta * wn - root) * t).exp();
        assert!((c1 + (p1 + p2).re).abs() < 1e-14, "{c1}");
        assert!((c0 - (p1 * p2).re).abs() < 1e-14, "{c0}");
    }
    let d = LoopDesign::new(1.3, 0.6, 0.25, 1e6);
    let mut p = params();
    (p.natural_hz, p.damping, p.tau_s, p.update_rate_hz) = (1.3, 0.6, 0.25, 1e6);
    let a = *Agc::new(&p).unwrap().design();
    let wn = TAU * 1.3;
    let kp = 2.0 * 0.6 * wn * 0.25 - 1.0;
    assert!(((a.kp_per_s - kp) / kp).abs() < 1e-4);
    assert!(((a.ki_per_s2() - wn * wn * 0.25) / (wn * wn * 0.25)).abs() < 1e-4);
    assert!(((a.kp_per_s - 0.25 * d.kp_per_s) / a.kp_per_s).abs() < 1e-15);
}

fn agc_params(s: &Setup, setpoint: f64) -> AgcParams {
    let mut p = AgcParams::new(
        s.update_rate_hz(),
        s.natural_hz,
        s.damping,
        s.tau_s(),
        setpoint,
        4.0,
    );
    p.lowpass_delay_s = s.lowpass().latency_samples() / s.fs_hz;
    p
}

/// A 0.2 % step of the setpoint (the carrier held on the resonance, so the 2 f0 image's leak
/// is a constant that cancels): `ln |z|` against the continuous and sampled second-order
/// models (2 % of the step: the low-pass's delay is left out of them, as for the PLL) and the
/// sampled model with the low-pass in it (0.2 %: what is left is the linearisation of the
/// logarithm, about half the step's size relative).
#[test]
fn setpoint_step_response_matches_the_linear_models() {
    for (fnat, zeta) in [(1.0, 0.7), (1.0, 0.4)] {
        let s = Setup::new(1000.0, 1000.0, fnat, zeta);
        let a0 = s.z_at_resonance().norm();
        let mut lp = Loop::new(&s, &s.pll_params(s.f0_hz));
        lp.closed = false;
        lp.settle_plant(s.f0_hz);
        // The low-pass settles first (from rest its output starts at 0, which the AGC would
        // answer with a wound-up transient), then the AGC takes over at its equilibrium.
        for _ in 0..100 {
            lp.block();
        }
        lp.agc = Some(Agc::new(&agc_params(&s, a0)).unwrap());
        let mut before = 0.0;
        for _ in 0..2000 {
            before = lp.block().1.norm().ln();
        }
        let step = 1.002f64.ln();
        let agc = lp.agc.as_mut().unwrap();
        agc.set_setpoint(a0 * 1.002).unwrap();
        let d = *agc.design();
        let n = 4000;
        // The new setpoint acts at the end of the next block (update 0), whose gain reaches
        // the drive from update 1 on: update k is k T after the step, in every model.
        let y: Vec<f64> = (0..n)
            .map(|_| (lp.block().1.norm().ln() - before) / step)
            .collect();
        let model = |lowpass| -> Vec<f64> {
            sampled_loop(&s, &AGC, d.kp_per_s, d.ki_t_per_s, n, lowpass)
                .into_iter()
                .map(|(x, _)| x)
                .collect()
        };
        let (sampled, with_lowpass) = (model(false), model(true));
        let t_up = 1.0 / s.update_rate_hz();
        let analytic: Vec<f64> = (0..n)
            .map(|k| continuous_step(k as f64 * t_up, fnat, zeta, s.tau_s()))
            .collect();
        let worst = |m: &[f64]| worst_difference(&y, m);
        let (w_a, w_s, w_l) = (worst(&analytic), worst(&sampled), worst(&with_lowpass));
        println!(
            "AGC fn {fnat} Hz, zeta {zeta}: worst |ln|z| - model| / step: analytic {w_a:.4}, \
             sampled {w_s:.4}, with low-pass {w_l:.5}; gain now {}",
            lp.gain
        );
        assert!(w_a < 0.02 && w_s < 0.02, "{w_a} {w_s}");
        assert!(w_l < 0.002, "{w_l}");
        assert!((lp.gain - 1.002).abs() < 2e-4, "gain {}", lp.gain);
    }
}

/// From rest, the drive at half the gain that gives the setpoint: the AGC runs to its limit
/// while the amplitude builds, then holds `|z|` at the setpoint (within 2e-4: the 2 f0 image
/// leaks 8e-5 through the low-pass) with the gain the plant needs. With the PLL closed too and
/// the carrier 5 half-bandwidths off, both loops end on their targets.
#[test]
fn acquires_from_rest_alone_and_with_the_pll() {
    let s = Setup::new(1000.0, 1000.0, 1.0, 0.7);
    let a0 = s.z_at_resonance().norm();
    for with_pll in [false, true] {
        let carrier = if with_pll {
            s.f0_hz + 5.0 * s.half_bandwidth_hz()
        } else {
            s.f0_hz
        };
        let mut lp = Loop::new(&s, &s.pll_params(carrier));
        lp.closed = with_pll;
        let mut p = agc_params(&s, 2.0 * a0);
        p.initial_gain = 1.0;
        lp.agc = Some(Agc::new(&p).unwrap());
        let (mut hit_limit, mut amp) = (false, 0.0);
        let n = 8000;
        let mut settled_at = 0;
        for k in 0..n {
            amp = lp.block().1.norm();
            hit_limit |= lp.agc.as_ref().unwrap().at_limit();
            if ((amp / (2.0 * a0)) - 1.0).abs() > 1e-3 {
                settled_at = k + 1;
            }
        }
        let f = lp.pll.frequency_hz();
        println!(
            "AGC{}: |z| within 1e-3 of the setpoint after {:.3} s, ends {:.2e} off, gain {}",
            if with_pll { " + PLL" } else { "" },
            settled_at as f64 / s.update_rate_hz(),
            amp / (2.0 * a0) - 1.0,
            lp.gain,
        );
        assert!(hit_limit);
        assert!((amp / (2.0 * a0) - 1.0).abs() < 2e-4);
        assert!((lp.gain - 2.0).abs() < 4e-4, "gain {}", lp.gain);
        assert!(settled_at < n - 1000);
        if with_pll {
            println!("  carrier ends {:.2e} Hz off f0", f - s.f0_hz);
            assert!(lp.pll.is_locked() && (f - s.f0_hz).abs() < 1e-3 * s.half_bandwidth_hz());
        }
    }
}

#[test]
fn bad_parameters_are_refused_naming_them() {
    let ok = params();
    assert!(Agc::new(&ok).is_ok());
    type Edit = fn(&mut AgcParams);
    let cases: [(&str, Edit); 12] = [
        ("update_rate_hz", |p| p.update_rate_hz = -1.0),
        ("natural_hz", |p| p.natural_hz = 200.0),
        ("natural_hz", |p| p.natural_hz = 0.1), // 2 zeta wn tau < 1
        ("damping", |p| p.damping = f64::NAN),
        ("tau_s", |p| p.tau_s = 0.0),
        ("lowpass_delay_s", |p| p.lowpass_delay_s = f64::NAN),
        ("setpoint", |p| p.setpoint = 0.0),
        ("initial_gain", |p| p.initial_gain = -1.0),
        ("max_gain", |p| p.max_gain = 1.0),
        ("max_gain", |p| p.max_gain = f64::INFINITY),
        ("min_gain", |p| p.min_gain = 1.0),
        ("min_amplitude", |p| p.min_amplitude = -1.0),
    ];
    for (param, edit) in cases {
        let mut p = ok;
        edit(&mut p);
        let e = Agc::new(&p).unwrap_err();
        assert_eq!((e.stage, e.param), ("agc", param), "{e}");
    }
    let mut agc = Agc::new(&ok).unwrap();
    assert_eq!(agc.set_setpoint(f64::NAN).unwrap_err().param, "setpoint");
    assert_eq!(agc.setpoint(), 1.0);
    // No signal holds the gain.
    agc.tick(Complex64::new(0.5, 0.0));
    let g = agc.gain();
    assert!(g > 1.0);
    assert_eq!(agc.tick(Complex64::new(0.0, 0.0)), g);
    assert!(!agc.has_signal() && agc.error_np() == 0.0);
}

#[test]
fn the_reported_state_is_what_the_last_tick_saw() {
    let p = params(); // setpoint 1, gains in [0.25, 4], no signal at |z| <= 1e-3
    let mut agc = Agc::new(&p).unwrap();
    assert_eq!(agc.setpoint(), 1.0);
    assert_eq!(agc.latency_samples(), 0.0);
    assert!(!agc.has_signal() && !agc.at_limit() && agc.error_np() == 0.0);

    // The error is ln(setpoint / |z|) in neper, and the first output already follows it
    // (latency 0): an amplitude below the setpoint raises the gain, one above lowers it.
    let g_low = agc.clone().tick(Complex64::from_polar(0.5, 1.0));
    let g_high = agc.clone().tick(Complex64::from_polar(2.0, -2.0));
    assert!(g_low > 1.0 && g_high < 1.0, "{g_low} {g_high}");
    agc.tick(Complex64::from_polar(0.5, 1.0));
    assert!(agc.has_signal());
    assert!((agc.error_np() - 2f64.ln()).abs() < 1e-15);
    agc.set_setpoint(3.0).unwrap();
    assert_eq!(agc.setpoint(), 3.0);
    agc.tick(Complex64::new(0.0, 0.5));
    assert!((agc.error_np() - 6f64.ln()).abs() < 1e-15);

    // At exactly min_amplitude there is no signal: the gain holds and the error reads 0.
    let held = agc.gain();
    assert_eq!(agc.tick(Complex64::new(p.min_amplitude, 0.0)), held);
    assert!(!agc.has_signal());
    assert_eq!(agc.error_np(), 0.0);

    // A large amplitude drives the gain down to min_gain, where it sits and says so; an
    // amplitude a little below the setpoint then lets it leave the floor.
    agc.reset();
    for _ in 0..2000 {
        agc.tick(Complex64::new(1e3, 0.0));
    }
    assert_eq!(agc.gain(), p.min_gain);
    assert!(agc.at_limit());
    agc.tick(Complex64::new(0.9, 0.0));
    assert!(agc.gain() > p.min_gain && !agc.at_limit(), "{}", agc.gain());
}
