//! Invariants: f64x4 lanes equal scalar plants under a time-varying rate (`tick_with_rate`,
//! which the shared harness in tests/contract.rs does not reach; block processing, reset and
//! `tick` lanes are checked there), the decoupled step, and bad parameters refused with a
//! named ParamError.

use gyroemu_core::{f64x4, Sample, Stage};
use gyroemu_resonator::{ModeParams, PlantOutput, Resonator, ResonatorParams};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn lane_params(l: usize) -> (ResonatorParams, f64) {
    let f0 = [1000.0, 1500.0, 777.0, 2500.0][l];
    let q = [10.0, 1e3, 36_000.0, 1e6][l];
    let p = ResonatorParams {
        mode1: ModeParams { f0_hz: f0, q },
        mode2: ModeParams {
            f0_hz: 1.01 * f0,
            q: 0.7 * q,
        },
        angular_gain: [0.6, 1.0, 0.8, 0.9][l],
        quadrature_coupling_rad2_s2: [0.0, 1e3, -5e4, 2e2][l],
        transduction_a_s_per_m: [1.0, 2e-3, 0.5, 3.0][l],
        fs_hz: 16_000.0,
    };
    (p, [0.0, 2.0, -1.0, 3.0][l])
}

fn bits(y: &PlantOutput<f64>) -> [u64; 6] {
    [y.q[0], y.q[1], y.v[0], y.v[1], y.current[0], y.current[1]].map(f64::to_bits)
}

#[test]
fn f64x4_lanes_equal_four_scalar_plants_bit_for_bit() {
    let mut scalars: Vec<Resonator<f64>> = (0..4)
        .map(|l| {
            let (p, om) = lane_params(l);
            let mut r = Resonator::<f64>::new(&p, om).unwrap();
            r.set_state([1e-6 * l as f64, -2e-7, 3e-4, 1e-5 * l as f64]);
            r
        })
        .collect();
    let mut lanes = Resonator::<f64x4>::from_lanes(&scalars);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for n in 0..4000 {
        let f: [[f64; 2]; 4] =
            core::array::from_fn(|_| [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)]);
        let om: [f64; 4] = core::array::from_fn(|_| rng.random_range(-3.0..3.0));
        let force = [f64x4::from_fn(|l| f[l][0]), f64x4::from_fn(|l| f[l][1])];
        let y = if n % 3 == 0 {
            lanes.tick(force)
        } else {
            lanes.tick_with_rate(force, f64x4::from_fn(|l| om[l]))
        };
        for (l, s) in scalars.iter_mut().enumerate() {
            let ys = if n % 3 == 0 {
                s.tick(f[l])
            } else {
                s.tick_with_rate(f[l], om[l])
            };
            let yl = PlantOutput {
                q: y.q.map(|v| v.lane(l)),
                v: y.v.map(|v| v.lane(l)),
                current: y.current.map(|v| v.lane(l)),
            };
            assert_eq!(bits(&yl), bits(&ys), "lane {l} sample {n}");
        }
    }
}

#[test]
fn bad_parameters_are_refused_with_named_errors() {
    let ok = ResonatorParams::matched(1e3, 100.0, 1.0, 16e3);
    let check = |p: ResonatorParams, om: f64, name: &str| {
        let e = Resonator::<f64>::new(&p, om).unwrap_err();
        assert_eq!((e.stage, e.param), ("resonator", name), "{e}");
        assert!(e.to_string().contains(name));
    };
    for q in [0.0, -5.0, f64::NAN, f64::INFINITY] {
        let mut p = ok;
        p.mode1.q = q;
        check(p, 0.0, "mode1.q");
        let mut p = ok;
        p.mode2.q = q;
        check(p, 0.0, "mode2.q");
    }
    for f in [0.0, -1.0, f64::NAN] {
        let mut p = ok;
        p.mode1.f0_hz = f;
        check(p, 0.0, "mode1.f0_hz");
        let mut p = ok;
        p.mode2.f0_hz = f;
        check(p, 0.0, "mode2.f0_hz");
    }
    for fs in [2e3, 1.5e3, f64::NAN, f64::INFINITY] {
        let mut p = ok;
        p.fs_hz = fs;
        check(p, 0.0, "fs_hz");
    }
    let mut p = ok;
    p.mode2.f0_hz = 8e3; // fs = 2 * f0 of mode 2
    check(p, 0.0, "fs_hz");
    let mut p = ok;
    p.angular_gain = f64::NAN;
    check(p, 0.0, "angular_gain");
    let mut p = ok;
    p.quadrature_coupling_rad2_s2 = f64::NEG_INFINITY;
    check(p, 0.0, "quadrature_coupling_rad2_s2");
    let mut p = ok;
    p.transduction_a_s_per_m = f64::NAN;
    check(p, 0.0, "transduction_a_s_per_m");
    check(ok, f64::NAN, "omega_z_rad_s");
    assert!(ok.validate().is_ok());
}

/// With no Coriolis term and no quadrature coupling the step matrix has exact zeros across
/// the modes, and the decoupled step (three products per row) equals the full step bit for
/// bit; any coupling makes the plant refuse the shortcut.
#[test]
fn decoupled_step_equals_full_step_and_is_only_offered_without_coupling() {
    let mut p = lane_params(2).0;
    p.quadrature_coupling_rad2_s2 = 0.0;
    let mut full = Resonator::<f64x4>::new(&p, 0.0).unwrap();
    assert!(full.decoupled());
    full.set_state([1e-6, -2e-7, 3e-4, 1e-5].map(f64x4::splat));
    let mut dec = full.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for n in 0..20_000 {
        let force: [f64x4; 2] =
            core::array::from_fn(|_| f64x4::from_fn(|_| rng.random_range(-1.0..1.0)));
        let (a, b) = (full.tick(force), dec.tick_decoupled(force));
        for k in 0..2 {
            for (u, v) in [
                (a.q[k], b.q[k]),
                (a.v[k], b.v[k]),
                (a.current[k], b.current[k]),
            ] {
                let (u, v) = (u.to_array(), v.to_array());
                assert_eq!(u.map(f64::to_bits), v.map(f64::to_bits), "sample {n}");
            }
        }
    }
    // A rotation rate, a coupling, or one coupled lane among four: not decoupled.
    assert!(!Resonator::<f64>::new(&p, 0.5).unwrap().decoupled());
    let mut pk = p;
    pk.quadrature_coupling_rad2_s2 = 1e-3;
    assert!(!Resonator::<f64>::new(&pk, 0.0).unwrap().decoupled());
    let plain = Resonator::<f64>::new(&p, 0.0).unwrap();
    let coupled = Resonator::<f64>::new(&p, 0.5).unwrap();
    let mixed = [plain.clone(), plain.clone(), coupled, plain];
    assert!(!Resonator::<f64x4>::from_lanes(&mixed).decoupled());
}

/// On a rate table about zero rate with no quadrature coupling, the rate expansion splits by
/// mode (E0 and E2 within a mode, E1 across, with exact zeros elsewhere), and the split step
/// (nine products per row) equals the full time-varying step bit for bit, mode mismatch and
/// Q mismatch included; a coupling, a design rate, or one such lane refuses the shortcut.
#[test]
fn rate_split_step_equals_the_full_time_varying_step() {
    let mut p = lane_params(2).0;
    p.quadrature_coupling_rad2_s2 = 0.0;
    let mut full = Resonator::<f64x4>::new(&p, 0.0).unwrap();
    assert!(full.rate_split_by_mode());
    full.set_state([1e-6, -2e-7, 3e-4, 1e-5].map(f64x4::splat));
    let mut split = full.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for n in 0..20_000 {
        let force: [f64x4; 2] =
            core::array::from_fn(|_| f64x4::from_fn(|_| rng.random_range(-1.0..1.0)));
        let rate = f64x4::from_fn(|_| rng.random_range(-30.0..30.0));
        let (a, b) = (
            full.tick_with_rate(force, rate),
            split.tick_with_rate_split(force, rate),
        );
        for k in 0..2 {
            let (u, v) = (a.v[k].to_array(), b.v[k].to_array());
            assert_eq!(u.map(f64::to_bits), v.map(f64::to_bits), "sample {n}");
            let (u, v) = (a.q[k].to_array(), b.q[k].to_array());
            assert_eq!(u.map(f64::to_bits), v.map(f64::to_bits), "sample {n}");
        }
    }
    let mut pk = p;
    pk.quadrature_coupling_rad2_s2 = 1e-3;
    assert!(!Resonator::<f64>::new(&pk, 0.0)
        .unwrap()
        .rate_split_by_mode());
    assert!(!Resonator::<f64>::new(&p, 0.5).unwrap().rate_split_by_mode());
    let plain = Resonator::<f64>::new(&p, 0.0).unwrap();
    let coupled = Resonator::<f64>::new(&pk, 0.0).unwrap();
    let mixed = [plain.clone(), coupled, plain.clone(), plain];
    assert!(!Resonator::<f64x4>::from_lanes(&mixed).rate_split_by_mode());
}

/// The state a tick leaves is `Phi x + Gamma u` of the reported matrices at the reported
/// design rate, and `state` reports it.
#[test]
fn state_after_a_tick_is_phi_x_plus_gamma_u() {
    for l in 0..4 {
        let (p, omega) = lane_params(l);
        let mut r = Resonator::<f64>::new(&p, omega).unwrap();
        assert_eq!(r.omega_z_rad_s(), omega);
        let x = [2e-7, -1e-7, 3e-4, 5e-5];
        r.set_state(x);
        assert_eq!(r.state(), x);
        let u = [0.7, -0.2];
        r.tick(u);
        let (phi, gamma) = (r.phi(), r.gamma());
        let got = r.state();
        for i in 0..4 {
            let want: f64 = (0..4).map(|j| phi[i][j] * x[j]).sum::<f64>()
                + (0..2).map(|k| gamma[i][k] * u[k]).sum::<f64>();
            let scale: f64 = (0..4).map(|j| (phi[i][j] * x[j]).abs()).sum::<f64>()
                + (0..2).map(|k| (gamma[i][k] * u[k]).abs()).sum::<f64>();
            assert!((got[i] - want).abs() <= 1e-14 * scale, "lane {l} state {i}");
        }
        r.reset();
        assert_eq!(r.state(), [0.0; 4]);
    }
}
