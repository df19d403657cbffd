//! The flicker filter's design against the ideal it approximates and against itself: its
//! exact density against `S1 / f` within the stated ripple, the corners flat, the modal form
//! (the one that runs) against the product form (via the impulse response and the stage
//! contract's DFT check), and its variance against the integral of its density.

use gyroemu_core::check;
use gyroemu_core::flicker::{Flicker, FlickerDesign, FlickerParams, RIPPLE_DB};
use gyroemu_core::{Response, Stage};

/// Designs that span the board's uses: normalised rates, a 320 kHz board with a 1000 s
/// record (f_lo = 1e-3 Hz), a band of interest well below Nyquist, and the narrowest band
/// the validation accepts (two decades, up to Nyquist).
fn designs() -> Vec<FlickerParams> {
    let p = |fs_hz, f_lo_hz, f_hi_hz| FlickerParams {
        fs_hz,
        psd_at_1hz: 2.5e-7,
        f_lo_hz,
        f_hi_hz,
    };
    vec![
        p(1.0, 1e-5, 0.5),
        p(1.0, 1e-4, 0.05),
        p(3.2e5, 1e-3, 1.6e5),
        p(3.2e5, 1e-3, 1e3),
        p(1.0, 5e-3, 0.5),
        p(1.0, 3e-3, 0.4),
        p(100.0, 0.5, 50.0),
    ]
}

#[test]
fn density_is_s1_over_f_within_the_stated_ripple() {
    for p in designs() {
        let d = FlickerDesign::new(&p).unwrap();
        let (lo, hi) = (10.0 * p.f_lo_hz, p.f_hi_hz / 10.0);
        let (mut min_db, mut max_db) = (f64::INFINITY, f64::NEG_INFINITY);
        // 400 points per decade resolve the lattice (two periods per decade).
        let n = ((hi / lo).log10() * 400.0).ceil().max(1.0) as usize;
        for i in 0..=n {
            let f = lo * (hi / lo).powf(i as f64 / n as f64);
            let db = 10.0 * (d.psd(f) * f / p.psd_at_1hz).log10();
            min_db = min_db.min(db);
            max_db = max_db.max(db);
        }
        eprintln!(
            "fs {} band [{}, {}] Hz: {} poles, ripple {min_db:+.4} .. {max_db:+.4} dB",
            p.fs_hz,
            p.f_lo_hz,
            p.f_hi_hz,
            d.poles()
        );
        assert!(
            min_db > -RIPPLE_DB && max_db < RIPPLE_DB,
            "{p:?}: ripple {min_db} .. {max_db} dB"
        );
    }
}

#[test]
fn density_flattens_outside_the_corners() {
    for p in designs() {
        let d = FlickerDesign::new(&p).unwrap();
        // Below the lowest pole: within 1 % of the DC level a decade below f_lo (a one-pole
        // corner gives 1/(1 + 0.01) there; the zeros and higher poles less).
        let dc = d.psd(0.0);
        let below = d.psd(p.f_lo_hz / 10.0);
        assert!(
            (below / dc - 1.0).abs() < 0.011,
            "{p:?}: {below} vs DC {dc}"
        );
        // The DC level is finite and just above the 1/f line at f_lo (a plateau, not a
        // divergence; the lowest pole's corner sums with the tails of the others): +1 to +2 dB
        // over S1 / f_lo, as documented.
        let plateau_db = 10.0 * (dc * p.f_lo_hz / p.psd_at_1hz).log10();
        assert!(
            plateau_db > 1.0 && plateau_db < 2.0,
            "{p:?}: plateau {plateau_db} dB"
        );
    }
}

#[test]
fn modal_form_equals_product_form() {
    // At every frequency, D + sum rho_k / (1 - a_k e^{-jw}) against the product form, in the
    // designs that reach 1e-5 fs (radii within 6e-5 of 1: the residues' accuracy is tested
    // where it is hardest).
    for p in designs() {
        let d = FlickerDesign::new(&p).unwrap();
        assert!(d.residues().iter().all(|&r| r > 0.0), "{p:?}");
        for i in 0..=2000 {
            let f = p.fs_hz / 2.0 * (1e-7f64).powf(i as f64 / 2000.0);
            let w = -core::f64::consts::TAU * f / p.fs_hz;
            let z1 = gyroemu_core::Complex64::new(w.cos(), w.sin());
            let modal = d.pole_radii().iter().zip(d.residues()).fold(
                gyroemu_core::Complex64::new(d.direct(), 0.0),
                |h, (&a, &r)| h + r / (1.0 - a * z1),
            );
            let prod = d.response(f);
            assert!(
                (modal - prod).norm() < 1e-9 * prod.norm(),
                "{p:?} at {f} Hz: modal {modal}, product {prod}"
            );
        }
    }
}

#[test]
fn the_running_filter_has_the_designed_response() {
    // The stage contract's DFT check on the realised recursion, started at rest. Poles from
    // fs/200: a_0^4096 = exp(-2 pi 4096 / 200) < 1e-55, so 4096 points hold the response.
    let p = FlickerParams {
        fs_hz: 1.0,
        psd_at_1hz: 1.0,
        f_lo_hz: 5e-3,
        f_hi_hz: 0.5,
    };
    let f = Flicker::<f64>::at_rest(&p).unwrap();
    let mut s = f.clone();
    let worst = check::response_matches_impulse("flicker", 1.0, &f, |x| s.tick(x), 4096, 1e-12);
    eprintln!("flicker: worst |DFT - H| / peak = {worst:e}");
}

#[test]
fn variance_is_the_integral_of_the_density() {
    // Var = int_0^{fs/2} S(f) df, by the trapezoid rule in ln f below f_lo (where S is flat,
    // the part under f_lo / 1e4 taken as S(0) f) and in f above: an independent path to the
    // closed form D^2 + 2 D sum rho + rho^T C rho.
    for p in designs() {
        let d = FlickerDesign::new(&p).unwrap();
        let f0 = p.f_lo_hz * 1e-4;
        let mut total = d.psd(0.0) * f0;
        let trap = |a: f64, b: f64, n: usize, log: bool| -> f64 {
            let x = |i: usize| {
                let t = i as f64 / n as f64;
                if log {
                    a * (b / a).powf(t)
                } else {
                    a + (b - a) * t
                }
            };
            (0..n)
                .map(|i| {
                    let (x0, x1) = (x(i), x(i + 1));
                    0.5 * (d.psd(x0) + d.psd(x1)) * (x1 - x0)
                })
                .sum()
        };
        total += trap(f0, p.fs_hz / 2.0, 400_000, true);
        let v = d.variance();
        assert!(
            (total / v - 1.0).abs() < 1e-6,
            "{p:?}: integral {total}, closed form {v}"
        );
    }
}
