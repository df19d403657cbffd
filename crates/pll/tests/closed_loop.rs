//! The PLL closed around a chain of the real stages (tests/common: resonator mode 1, carrier
//! NCO, TIA, stage-1 mixer, Butterworth low-pass on I and Q, the PLL steering the NCO once per
//! decimation block): the detector against the resonator's phase, lock acquisition from
//! several half-bandwidths off, the step response of the carrier to a step of the resonance
//! against the linear models, and a loop of the wrong sign running away.

mod common;

use common::models::{continuous_step, sampled_loop, worst_difference, PLL};
use common::{Loop, Setup};
use core::f64::consts::TAU;
use gyroemu_core::{Complex64, Response};
use gyroemu_mixer::wrap_pi;

/// Peak value, the update of the peak, and the last update outside `1 +- band`.
fn metrics(y: &[f64], band: f64) -> (f64, usize, usize) {
    let (k_peak, peak) = y
        .iter()
        .enumerate()
        .fold((0, f64::MIN), |a, (k, &v)| if v > a.1 { (k, v) } else { a });
    let settle = y.iter().rposition(|v| (v - 1.0).abs() > band).unwrap_or(0);
    (peak, k_peak, settle)
}

/// Open loop, carrier held off resonance by `x` half-bandwidths, plant in its steady state:
/// the detector reads the chain's exact phase (the plant's sampled steady state and the TIA's
/// response at the carrier, minus the offset) to 2e-4 rad, the image's leak through the
/// low-pass (8e-5 rad) and its start-up being all that is left; and the envelope model's
/// `-atan(tau dw)` to 2e-3 rad (the hold and the TIA pole turn by up to 7e-4 rad between f0
/// and the carrier, the envelope model is off by `O(dw / w0)`).
#[test]
fn the_detector_reads_the_resonators_phase_lag() {
    let s = Setup::new(1000.0, 500.0, 1.0, 0.7);
    for x in [-3.0, -1.0, 0.0, 0.5, 2.0] {
        let fc = s.f0_hz + x * s.half_bandwidth_hz();
        let p = s.pll_params(fc);
        let mut lp = Loop::new(&s, &p);
        lp.closed = false;
        lp.settle_plant(fc);
        for _ in 0..500 {
            lp.block();
        }
        let e = lp.pll.phase_error_rad();
        let force = [Complex64::new(common::FORCE, 0.0), Complex64::new(0.0, 0.0)];
        let v = s.plant(s.f0_hz).held_steady_state(fc, force)[2];
        let exact = wrap_pi((v * s.tia().response(fc)).arg() - p.phase_offset_rad);
        let envelope = -(s.tau_s() * TAU * (fc - s.f0_hz)).atan();
        println!("x = {x}: e = {e:.6}, exact {exact:.6}, envelope model {envelope:.6}");
        assert!((e - exact).abs() < 2e-4, "x = {x}: e {e}, exact {exact}");
        assert!(
            (e - envelope).abs() < 2e-3,
            "x = {x}: e {e}, model {envelope}"
        );
    }
}

/// Lock acquisition from rest, the carrier several half-bandwidths `f0/(2Q)` off (above and
/// below, up to 20): the carrier ends within 1e-3 half-bandwidths of f0 (the 2 f0 image
/// leaks 8e-5 rad through the low-pass, which the loop reads as 8e-5 half-bandwidths of
/// detuning), the lock indicator is on, and it gets there within 1.5 times the linear loop's
/// time to the same tolerance, `ln(K offset / tol) / (zeta wn)` with `K` the envelope of its
/// step response (the detector's gain falls far out, so the pull-in is slower than linear).
#[test]
fn locks_from_several_half_bandwidths_off() {
    for (q, fnat, zeta, offset_hbw) in [
        (1000.0, 1.0, 0.7, 5.0),
        (1000.0, 1.0, 0.7, -8.0),
        (1000.0, 1.0, 0.7, 20.0),
        (200.0, 2.5, 0.7, 5.0),
    ] {
        let s = Setup::new(1000.0, q, fnat, zeta);
        let hbw = s.half_bandwidth_hz();
        let p = s.pll_params(s.f0_hz + offset_hbw * hbw);
        let mut lp = Loop::new(&s, &p);
        let n = 6000;
        let mut f = Vec::with_capacity(n);
        let mut locked = Vec::with_capacity(n);
        for _ in 0..n {
            f.push(lp.block().0 - s.f0_hz);
            locked.push(lp.pll.is_locked());
        }
        let tol = 1e-3 * hbw;
        let t_up = 1.0 / s.update_rate_hz();
        let within = f.iter().rposition(|v| v.abs() > tol).map_or(0, |k| k + 1);
        let lock = locked.iter().rposition(|&l| !l).map_or(0, |k| k + 1);
        let tail = f[n - 1000..].iter().map(|v| v.abs()).fold(0.0, f64::max);
        let (wn, tau) = (TAU * fnat, s.tau_s());
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let k_env = (1.0 + ((1.0 / tau - zeta * wn) / wd).powi(2)).sqrt();
        let t_linear = (k_env * offset_hbw.abs() * hbw / tol).ln() / (zeta * wn);
        println!(
            "Q {q}, {offset_hbw} half-bandwidths ({} Hz) off: within {tol:e} Hz of f0 after \
            {:.3} s, lock indicator on after {:.3} s (linear loop: {t_linear:.3} s); last 1 s \
            within {tail:.2e} Hz",
            offset_hbw * hbw,
            within as f64 * t_up,
            lock as f64 * t_up
        );
        assert!(
            tail < tol,
            "Q {q}, offset {offset_hbw}: |f - f0| = {tail} Hz"
        );
        assert!(lp.pll.is_locked() && !locked[0]);
        assert!(
            within as f64 * t_up < 1.5 * t_linear,
            "slow: {within} updates"
        );
        assert!(lock <= within + p.lock_updates as usize);
    }
}

/// The carrier's response to a small step of the resonance (0.05 half-bandwidths: the phase
/// error stays below 0.05 rad, where atan is linear to 0.1 %), against three linear models: the continuous second-order
/// loop of the crate docs (analytic), the sampled loop the gains were designed for, and the
/// sampled loop with the demodulation low-pass in it. Tolerances, in units of the step: 2 %
/// against the first two, which leave out the low-pass: its DC group delay `d` (2.08 ms
/// here) delays the loop's reaction, about `d max|y'| = d Kp` (1.2 % to 1.4 %); 0.4 % against
/// the third (what is left: the image's leak, 1.5e-3 of the step, and the linearisation).
/// Overshoot within 1 % of the step, peak time and 2 % settling time within 3 % of the
/// analytic model's.
#[test]
fn step_response_matches_the_linear_models() {
    for (q, fnat, zeta) in [(1000.0, 1.0, 0.7), (1000.0, 1.0, 0.4), (200.0, 2.5, 0.7)] {
        let s = Setup::new(1000.0, q, fnat, zeta);
        let p = s.pll_params(s.f0_hz);
        let mut lp = Loop::new(&s, &p);
        lp.settle_plant(s.f0_hz);
        for _ in 0..2000 {
            lp.block();
        }
        assert!(lp.pll.is_locked());
        let delta = 0.05 * s.half_bandwidth_hz();
        lp.step_resonance(&s, s.f0_hz + delta);
        let n = 4000;
        let y: Vec<f64> = (0..n).map(|_| (lp.block().0 - s.f0_hz) / delta).collect();
        let d = *lp.pll.design();
        let model = |lowpass| -> Vec<f64> {
            sampled_loop(&s, &PLL, d.kp_per_s, d.ki_t_per_s, n, lowpass)
                .into_iter()
                .map(|(_, y)| y)
                .collect()
        };
        let (sampled, with_lowpass) = (model(false), model(true));
        // Update k's phase is sampled (k + 1) T after the step.
        let t_up = 1.0 / s.update_rate_hz();
        let analytic: Vec<f64> = (0..n)
            .map(|k| continuous_step((k + 1) as f64 * t_up, fnat, zeta, s.tau_s()))
            .collect();
        let worst = |m: &[f64]| worst_difference(&y, m);
        let (w_a, w_s, w_l) = (worst(&analytic), worst(&sampled), worst(&with_lowpass));
        let (peak, k_peak, k_settle) = metrics(&y, 0.02);
        let (peak_a, k_peak_a, k_settle_a) = metrics(&analytic, 0.02);
        println!(
            "Q {q}, fn {fnat} Hz, zeta {zeta}: worst |y - model| / step: analytic {w_a:.4}, \
            sampled {w_s:.4}, with low-pass {w_l:.5}; overshoot {:.4} (analytic {:.4}), \
            peak at {:.3} s ({:.3} s), 2 % settling {:.3} s ({:.3} s); low-pass delay {:.2} ms",
            peak - 1.0,
            peak_a - 1.0,
            (k_peak + 1) as f64 * t_up,
            (k_peak_a + 1) as f64 * t_up,
            (k_settle + 1) as f64 * t_up,
            (k_settle_a + 1) as f64 * t_up,
            p.lowpass_delay_s * 1e3
        );
        assert!(w_a < 0.02 && w_s < 0.02, "{w_a} {w_s}");
        assert!(w_l < 0.004, "{w_l}");
        assert!(
            ((peak - peak_a).abs()) < 0.01,
            "overshoot {peak} vs {peak_a}"
        );
        let near = |a: usize, b: usize| (a as f64 - b as f64).abs() <= 0.03 * b as f64;
        assert!(near(k_peak, k_peak_a), "peak at {k_peak} vs {k_peak_a}");
        assert!(
            near(k_settle, k_settle_a),
            "settled at {k_settle} vs {k_settle_a}"
        );
    }
}

/// A loop of the wrong sign runs away instead of locking: with the detector mirrored
/// (`conj z`), or with the TIA's inversion left out of the phase offset (the detector then
/// sits near +-pi), the carrier leaves f0 and ends on a frequency limit, never locked. (The
/// same loops with the right sign lock: the test above.)
#[test]
fn a_loop_of_the_wrong_sign_runs_away() {
    let s = Setup::new(1000.0, 1000.0, 1.0, 0.7);
    let hbw = s.half_bandwidth_hz();
    for case in ["mirrored detector", "inversion left out"] {
        let mut p = s.pll_params(s.f0_hz + 2.0 * hbw);
        p.min_hz = Some(s.f0_hz - 30.0 * hbw);
        p.max_hz = Some(s.f0_hz + 30.0 * hbw);
        if case == "inversion left out" {
            p.phase_offset_rad = wrap_pi(p.phase_offset_rad + core::f64::consts::PI);
        }
        let mut lp = Loop::new(&s, &p);
        lp.mirrored = case == "mirrored detector";
        let mut ever_locked = false;
        let mut f = 0.0;
        for _ in 0..6000 {
            f = lp.block().0;
            ever_locked |= lp.pll.is_locked();
        }
        println!("{case}: ends at f - f0 = {} Hz", f - s.f0_hz);
        assert!(lp.pll.at_limit() && !ever_locked, "{case}");
        assert!((f - s.f0_hz).abs() > 29.0 * hbw, "{case}: {f}");
    }
}
