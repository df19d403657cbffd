//! Phi and Gamma against the golden vectors of `fixtures/plant_zoh`: the exact zero-order-hold
//! step `expm([[A, B], [0, 0]] Ts)` of the 2-DOF plant computed by mpmath at 50 digits
//! (`fixtures/generate.py`), for the presets' devices, a BAW disk, imperfect devices and a
//! coarse sample rate.

#[path = "../../../fixtures/load.rs"]
mod load;

use gyroemu_resonator::{ModeParams, Resonator, ResonatorParams};
use load::{nums, Fixture};
use std::f64::consts::TAU;

/// Tolerance on the balanced error relative to the balanced norm (see `balanced_error`). The
/// plant takes nalgebra's Pade-13 scaling-and-squaring exponential of the balanced 6x6 matrix,
/// whose entries are all of order `w Ts` (0.4 at 16 samples per period, 2.5 at the coarsest
/// fixture): that is accurate to a few eps relative to the norm, and the exact back-transform
/// adds one rounding per entry; the squarings can grow it by their count (up to ~4 here).
/// Measured worst: 5.9e-16 (2.7 eps). A 1e-9 relative change of f0 moves the block by ~1e-10.
const TOL: f64 = 4e-15;

fn params(f: &Fixture) -> (ResonatorParams, f64) {
    let p = |k: &str| f.num(&format!("params/{k}"));
    let plant = ResonatorParams {
        mode1: ModeParams {
            f0_hz: p("f0_hz"),
            q: p("q"),
        },
        mode2: ModeParams {
            f0_hz: p("f0_mode2_hz"),
            q: p("q_mode2"),
        },
        angular_gain: p("angular_gain"),
        quadrature_coupling_rad2_s2: p("quadrature_coupling_rad2_s2"),
        transduction_a_s_per_m: 1.0,
        fs_hz: p("fs_hz"),
    };
    (plant, p("omega_z_rad_s"))
}

/// `max |got - want| s_i / s_j` over the 4x6 block `[Phi | Gamma]`, divided by the balanced
/// block's largest entry, with the balancing `s = [w1, w2, 1, 1, 1/w1, 1/w1]` (state
/// `[w q, v]`, input `u / w1`). Raw entries span 20 decades (w^2 Ts beside Ts^2), so an
/// entrywise relative error would be dominated by entries that are zero but for rounding; in
/// balanced units every entry is measured against the size that matters for the state.
fn balanced_error(r: &Resonator<f64>, f: &Fixture, p: &ResonatorParams) -> f64 {
    let [w1, w2] = [TAU * p.mode1.f0_hz, TAU * p.mode2.f0_hz];
    let s = [w1, w2, 1.0, 1.0, 1.0 / w1, 1.0 / w1];
    let (phi, gamma) = (r.phi(), r.gamma());
    let (mut err, mut norm) = (0.0f64, 0.0f64);
    for i in 0..4 {
        let want_phi = nums(&f.doc["phi"][i]);
        let want_gamma = nums(&f.doc["gamma"][i]);
        for j in 0..6 {
            let (got, want) = if j < 4 {
                (phi[i][j], want_phi[j])
            } else {
                (gamma[i][j - 4], want_gamma[j - 4])
            };
            err = err.max((got - want).abs() * s[i] / s[j]);
            norm = norm.max(want.abs() * s[i] / s[j]);
        }
    }
    err / norm
}

#[test]
fn phi_and_gamma_match_the_mpmath_exponential() {
    let mut worst: f64 = 0.0;
    for f in load::family(env!("CARGO_MANIFEST_DIR"), "plant_zoh", 7) {
        let (p, omega) = params(&f);
        let r = Resonator::<f64>::new(&p, omega).unwrap();
        let err = balanced_error(&r, &f, &p);
        eprintln!("{}: balanced relative error {err:e}", f.name);
        worst = worst.max(err);
        assert!(err < TOL, "{}: {err:e} >= {TOL:e}", f.name);
        // The tolerance resolves the parameters: f0 off by 1e-9 (both modes) must fail it, and
        // so must a rate off by 1e-3 of itself (the Coriolis entries are small beside w Ts).
        let mut q = p;
        q.mode1.f0_hz *= 1.0 + 1e-9;
        q.mode2.f0_hz *= 1.0 + 1e-9;
        let off = balanced_error(&Resonator::new(&q, omega).unwrap(), &f, &p);
        eprintln!("  f0 * (1 + 1e-9): {off:e}");
        assert!(
            off > 10.0 * TOL,
            "{}: f0 * (1 + 1e-9) gives {off:e}",
            f.name
        );
        if omega != 0.0 {
            let off = balanced_error(&Resonator::new(&p, omega * 1.001).unwrap(), &f, &p);
            eprintln!("  rate * 1.001: {off:e}");
            assert!(off > 10.0 * TOL, "{}: rate * 1.001 gives {off:e}", f.name);
        }
    }
    eprintln!("plant_zoh: worst balanced relative error {worst:e} (tolerance {TOL:e})");
}
