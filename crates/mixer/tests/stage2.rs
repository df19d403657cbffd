//! Stage 2 and the sideband estimator recover planted psi and alpha (THEORY section 6).

mod common;

use common::{angle_err, exact_phase, Planted};
use core::f64::consts::{FRAC_PI_2, PI, TAU};
use gyroemu_core::{Complex64, Stage};
use gyroemu_mixer::{sideband_estimate, Iq, Mode, Stage2Mixer};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Samples per modulation period at the decimated rate.
const M: u64 = 200;

/// Runs the stage-2 mixer over `half_periods` half periods starting at sample `n0` and
/// returns the boxcar averages `(C, S)`. `z_at` and `refs_at` take the exact modulation phase.
fn c_and_s(
    n0: u64,
    half_periods: u64,
    z_at: impl Fn(f64) -> Complex64,
    refs_at: impl Fn(f64) -> [f64; 2],
) -> (Complex64, Complex64) {
    let mut mix = Stage2Mixer::<f64>::new();
    let n_len = half_periods * M / 2;
    let (mut c, mut s) = (Complex64::default(), Complex64::default());
    for n in n0..n0 + n_len {
        let wt = exact_phase(n, 1, M);
        let z = z_at(wt);
        let o = mix.tick((Iq::new(z.re, z.im), refs_at(wt)));
        c += o.c.lane(0);
        s += o.s.lane(0);
    }
    (c / n_len as f64, s / n_len as f64)
}

fn ideal_refs(wt: f64) -> [f64; 2] {
    [wt.cos(), wt.sin()]
}

fn random_planted(rng: &mut ChaCha8Rng, mode2: bool, imbalance: f64) -> Planted {
    Planted {
        amp: rng.random_range(0.05..20.0),
        psi: rng.random_range(-FRAC_PI_2 + 1e-6..FRAC_PI_2),
        alpha: rng.random_range(-PI..PI),
        imbalance,
        mode2,
    }
}

#[test]
fn recovers_planted_psi_and_alpha_both_modes() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (mut wpsi, mut walpha): (f64, f64) = (0.0, 0.0);
    for trial in 0..400 {
        let mode2 = trial % 2 == 1;
        let mode = if mode2 { Mode::Two } else { Mode::One };
        // Balanced sidebands (the brief's form) and imbalanced ones (a real resonator).
        let imb = if trial % 4 < 2 {
            0.0
        } else {
            rng.random_range(-0.5..0.5)
        };
        let p = random_planted(&mut rng, mode2, imb);
        let n0 = rng.random_range(0..10 * M);
        let h = rng.random_range(1..7);
        let (c, s) = c_and_s(n0, h, |wt| p.z(wt), ideal_refs);
        let e = sideband_estimate(c, s, mode);
        wpsi = wpsi.max((e.psi_rad - p.psi).abs());
        walpha = walpha.max(angle_err(e.alpha_rad, p.alpha));
        // Sideband phasors by the closed form.
        let m_plus = if mode2 {
            Complex64::new(0.0, -1.0)
        } else {
            Complex64::new(1.0, 0.0)
        };
        let zp = m_plus * Complex64::from_polar(0.5 * p.amp * (1.0 - imb), p.alpha - p.psi);
        assert!((e.z_plus - zp).norm() < 1e-12 * p.amp);
    }
    println!("stage 2 recovery: worst psi err {wpsi:.2e} rad, alpha err {walpha:.2e} rad");
    assert!(wpsi < 1e-12 && walpha < 1e-12);
}

#[test]
fn branch_puts_psi_in_half_open_half_circle() {
    // psi outside (-pi/2, pi/2] is read as (psi - pi, alpha - pi): the sign of A is unobservable.
    for mode2 in [false, true] {
        let mode = if mode2 { Mode::Two } else { Mode::One };
        for (psi, alpha) in [(2.0, 0.4), (-2.5, -1.0), (FRAC_PI_2, 0.3), (3.0, 3.0)] {
            let p = Planted {
                amp: 1.0,
                psi,
                alpha,
                imbalance: 0.0,
                mode2,
            };
            let (c, s) = c_and_s(0, 2, |wt| p.z(wt), ideal_refs);
            let e = sideband_estimate(c, s, mode);
            assert!(e.psi_rad > -FRAC_PI_2 && e.psi_rad <= FRAC_PI_2 + 1e-15);
            assert!(e.alpha_rad > -PI && e.alpha_rad <= PI);
            let flip = if psi.abs() > FRAC_PI_2 + 1e-9 {
                PI
            } else {
                0.0
            };
            assert!(
                angle_err(e.psi_rad, psi - flip) < 1e-12,
                "{psi} -> {}",
                e.psi_rad
            );
            assert!(angle_err(e.alpha_rad, alpha - flip) < 1e-12);
        }
    }
}

#[test]
fn common_delay_of_z_and_references_leaves_psi_unchanged() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut worst: f64 = 0.0;
    for trial in 0..100 {
        let mode2 = trial % 2 == 1;
        let mode = if mode2 { Mode::Two } else { Mode::One };
        let imb = rng.random_range(-0.3..0.3);
        let p = random_planted(&mut rng, mode2, imb);
        // A fractional delay, in radians of modulation phase, and gains on z and refs.
        let d = rng.random_range(0.0..1.2);
        let (gz, gr) = (rng.random_range(0.2..1.0), rng.random_range(0.2..1.0));
        let (c, s) = c_and_s(
            7,
            4,
            |wt| p.z(wt - d) * gz,
            |wt| [gr * (wt - d).cos(), gr * (wt - d).sin()],
        );
        let e = sideband_estimate(c, s, mode);
        worst = worst
            .max((e.psi_rad - p.psi).abs())
            .max(angle_err(e.alpha_rad, p.alpha));
        // Uncompensated (ideal references): psi grows by the delay, Omega tau.
        let (c, s) = c_and_s(7, 4, |wt| p.z(wt - d) * gz, ideal_refs);
        let e = sideband_estimate(c, s, mode);
        let want = p.psi + d;
        let flip = if want > FRAC_PI_2 { PI } else { 0.0 };
        assert!((e.psi_rad - (want - flip)).abs() < 1e-12);
        assert!(angle_err(e.alpha_rad, p.alpha - flip) < 1e-12);
    }
    println!("common delay: worst psi/alpha change {worst:.2e} rad");
    assert!(worst < 1e-12);
}

#[test]
fn references_through_the_same_low_pass_compensate_it() {
    // One-pole low-pass y[n] = (1 - a) x[n] + a y[n-1], written here, run on I, Q and both
    // references; after it settles the compensated psi is exact and the uncompensated one is off
    // by -arg L(e^{j Omega Ts}).
    let a = 0.97;
    let l = {
        let zinv = Complex64::from_polar(1.0, -TAU / M as f64);
        (1.0 - a) / (1.0 - a * zinv)
    };
    for mode2 in [false, true] {
        let mode = if mode2 { Mode::Two } else { Mode::One };
        let p = Planted {
            amp: 3.0,
            psi: 0.4,
            alpha: -0.9,
            imbalance: 0.1,
            mode2,
        };
        let settle = 40 * M; // a^8000 ~ 1e-106
        let n_len = 3 * M / 2;
        let mut mix = Stage2Mixer::<f64>::new();
        let (mut fz, mut fr) = (Complex64::default(), [0.0f64; 2]);
        let (mut c, mut s, mut cu, mut su) = Default::default();
        for n in 0..settle + n_len {
            let wt = exact_phase(n, 1, M);
            fz = p.z(wt) * (1.0 - a) + fz * a;
            fr = [
                (1.0 - a) * wt.cos() + a * fr[0],
                (1.0 - a) * wt.sin() + a * fr[1],
            ];
            let z = Iq::new(fz.re, fz.im);
            let comp = mix.tick((z, fr));
            let unc = mix.tick((z, ideal_refs(wt)));
            if n >= settle {
                c += comp.c.lane(0);
                s += comp.s.lane(0);
                cu += unc.c.lane(0);
                su += unc.s.lane(0);
            }
        }
        let e = sideband_estimate(c, s, mode);
        let eu = sideband_estimate(cu, su, mode);
        println!(
            "one-pole: compensated psi err {:.2e}, uncompensated shift {:.6} rad (want {:.6})",
            e.psi_rad - p.psi,
            eu.psi_rad - p.psi,
            -l.arg()
        );
        assert!((e.psi_rad - p.psi).abs() < 1e-12);
        assert!((e.alpha_rad - p.alpha).abs() < 1e-12);
        assert!((eu.psi_rad - (p.psi - l.arg())).abs() < 1e-12);
        assert!((eu.alpha_rad - p.alpha).abs() < 1e-12);
    }
}
