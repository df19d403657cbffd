//! The TIA's frequency response against independent truths: a measured sine sweep and the
//! continuous-time prototype (the DFT of the impulse response is checked by the shared harness
//! in tests/contract.rs).

use gyroemu_core::{Complex64, Response, Stage};
use gyroemu_tia::{Tia, TiaParams};
use std::f64::consts::{PI, TAU};

fn params(pole_hz: Option<f64>, inverting: bool) -> TiaParams {
    TiaParams {
        gain_ohm: 1e5,
        pole_hz,
        inverting,
        rail_v: None,
        fs_hz: 1e6,
    }
}

#[test]
fn sine_sweep_amplitude_and_phase_equal_response() {
    let fs = 1e6;
    let n = 4096; // bins k*fs/n: a whole number of periods over the analysis window
    for k in [1usize, 7, 41, 160, 600, 1500, 2000] {
        let mut t = Tia::<f64>::new(&params(Some(2e4), true)).unwrap();
        let f = k as f64 * fs / n as f64;
        let x = |i: usize| ((k * i % n) as f64 / n as f64 * TAU).cos();
        // settle: a^n = exp(-2 pi 2e4 4096/1e6) ~ 1e-223
        for i in 0..n {
            t.tick(x(i));
        }
        let mut acc = Complex64::new(0.0, 0.0);
        for i in n..2 * n {
            let y = t.tick(x(i));
            acc += Complex64::from_polar(y, -((k * i % n) as f64 / n as f64 * TAU));
        }
        let measured = acc * (2.0 / n as f64);
        let h = t.response(f);
        let rel = (measured - h).norm() / h.norm();
        eprintln!("tia sweep f = {f} Hz: rel {rel:e}");
        assert!(
            rel < 1e-11,
            "f = {f} Hz: measured {measured}, response {h}, rel {rel:e}"
        );
        assert!((measured.arg() - h.arg()).abs() < 1e-11);
    }
}

/// With `s = 2 pi (pole + j f)/fs`, `H_d / H_c = g(2 pi pole/fs) / g(s)` where
/// `g(z) = (1 - e^{-z})/z`, hence `H_d / H_c = exp(j pi f/fs) (1 + O(|s|^2))`:
/// a half-sample lead and a second-order error bounded by `|s|^2 / 12` at small `|s|`.
#[test]
fn response_approaches_continuous_as_pole_over_fs_goes_to_zero() {
    let fs = 1e6;
    for pole in [1e4, 1e3, 1e2] {
        let t = Tia::<f64>::new(&params(Some(pole), true)).unwrap();
        for ratio in [0.0, 0.3, 1.0, 3.0] {
            let f = ratio * pole;
            let hd = t.response(f);
            let hc = t.continuous_response(f);
            let s = TAU * (pole * pole + f * f).sqrt() / fs;
            let lead = Complex64::from_polar(1.0, PI * f / fs);
            let err2 = (hd / (hc * lead) - 1.0).norm();
            eprintln!(
                "tia continuous pole {pole} f {f}: |Hd/(Hc lead)-1| = {err2:e}, |s|^2/12 = {:e}",
                s * s / 12.0
            );
            assert!(
                err2 <= s * s / 12.0 * 1.05 + 1e-15,
                "pole {pole} f {f}: {err2:e} vs {:e}",
                s * s / 12.0
            );
            // and plainly: |H_d/H_c - 1| <= pi f/fs + |s|^2/12
            let err1 = (hd / hc - 1.0).norm();
            assert!(err1 <= PI * f / fs + s * s / 12.0 * 1.05 + 1e-15);
        }
    }
    let hc = Tia::<f64>::new(&params(Some(1e2), false)).unwrap();
    assert!((hc.response(0.0).re - 1e5).abs() < 1e-9 && hc.continuous_response(0.0).re == 1e5);
}

#[test]
fn no_pole_is_a_pure_gain() {
    let mut t = Tia::<f64>::new(&params(None, true)).unwrap();
    for x in [1e-6, -3.7e-7, 0.0, 2.2e-9] {
        assert_eq!(t.tick(x), -1e5 * x);
    }
    assert_eq!(t.response(123.0), Complex64::new(-1e5, 0.0));
    assert_eq!(t.latency_samples(), 0.0);
}
