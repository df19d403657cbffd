//! The flicker source as a stage and as a seeded generator: the stage contract (blocks, reset,
//! lanes bit for bit; blocks for every pole count), lanes of a stationary f64x4 source equal to scalar sources on their
//! own streams, same seed same bits, and a start drawn from the stationary law (the variance
//! of the first sample and of a long first average against their exact values).

mod flicker_common;

use flicker_common::{integrate, Gauss};
use gyroemu_core::check::{self, Gen};
use gyroemu_core::flicker::{Flicker, FlickerParams};
use gyroemu_core::{f64x4, Sample, Stage};

fn params() -> FlickerParams {
    FlickerParams {
        fs_hz: 1.0,
        psd_at_1hz: 0.7,
        f_lo_hz: 1e-3,
        f_hi_hz: 0.5,
    }
}

fn gaussian<S: Sample>(g: &mut Gen) -> S {
    // Any real input will do for the contract; Gaussian-ish by a sum of uniforms.
    S::from_fn(|_| (0..4).map(|_| g.uniform(-1.0, 1.0)).sum::<f64>())
}

#[test]
fn stage_contract_blocks_reset_and_lanes() {
    let p = params();
    let mut seeds = Gauss::new([1, 2, 3, 4]);
    for at_rest in [true, false] {
        let build = |g: &mut Gauss| {
            if at_rest {
                Flicker::<f64>::at_rest(&p).unwrap()
            } else {
                Flicker::<f64>::stationary(&p, || g.next().to_array()[0]).unwrap()
            }
        };
        let s = build(&mut seeds);
        check::tick_vs_process("flicker", &s, gaussian::<f64>, check::same);
        check::reset_restores("flicker", &s, gaussian::<f64>, check::same);
        let scalars: Vec<Flicker<f64>> = (0..4).map(|_| build(&mut seeds)).collect();
        // The f64x4 source with the scalar sources' start states in its lanes: built by
        // drawing each lane's start Gaussians from the matching scalar draw.
        let v = if at_rest {
            Flicker::<f64x4>::at_rest(&p).unwrap()
        } else {
            let mut again = Gauss::new([1, 2, 3, 4]);
            let _skip = build(&mut again);
            let lane_draws: Vec<Vec<f64>> = (0..4)
                .map(|_| {
                    let mut d = Vec::new();
                    let _ = Flicker::<f64>::stationary(&p, || {
                        let x = again.next().to_array()[0];
                        d.push(x);
                        x
                    })
                    .unwrap();
                    d
                })
                .collect();
            let mut i = 0;
            Flicker::<f64x4>::stationary(&p, || {
                let x = f64x4::new(core::array::from_fn(|l| lane_draws[l][i]));
                i += 1;
                x
            })
            .unwrap()
        };
        check::lanes_match(
            "flicker",
            &v,
            &scalars,
            gaussian::<f64x4>,
            |x, l| x.lane(l),
            |y, l| y.lane(l),
            check::same,
        );
    }
}

#[test]
fn blocks_are_ticks_for_every_pole_count() {
    // `process` runs the poles four at a time and the rest in one pass (eight at a time first
    // in eight lanes: `board`'s f64x8 tests): spans of 2 to 12 decades give 4 to 24 poles,
    // every remainder modulo four, each checked on blocks of every size of the contract
    // against `tick`, in one lane and in four.
    let mut counts = Vec::new();
    let mut g = Gauss::new([5, 6, 7, 8]);
    for tenth in (20..=120).step_by(5) {
        let p = FlickerParams {
            f_lo_hz: 0.5 * 10f64.powf(-(tenth as f64) / 10.0),
            ..params()
        };
        let scalar = Flicker::<f64>::stationary(&p, || g.next().to_array()[0]).unwrap();
        let lanes = Flicker::<f64x4>::stationary(&p, || g.next()).unwrap();
        counts.push(scalar.design().poles());
        check::tick_vs_process("flicker", &scalar, gaussian::<f64>, check::same);
        check::tick_vs_process("flicker x4", &lanes, gaussian::<f64x4>, check::same);
    }
    for r in 0..4 {
        assert!(counts.iter().any(|&n| n % 4 == r && n > 4), "{counts:?}");
    }
}

#[test]
fn sources_side_by_side_keep_their_bits_from_their_current_state() {
    // Four scalar sources, advanced apart first, joined as the four lanes of one source: each
    // lane continues its own source bit for bit (tick and process), and reset goes back to
    // the parts' start states.
    let p = params();
    let mut g = Gauss::new([1, 2, 3, 4]);
    let mut parts: Vec<Flicker<f64>> = (0..4)
        .map(|_| Flicker::<f64>::stationary(&p, || g.next().to_array()[0]).unwrap())
        .collect();
    for (j, f) in parts.iter_mut().enumerate() {
        for n in 0..(10 + 7 * j) {
            f.tick((n as f64 * 0.37).sin());
        }
    }
    let refs: Vec<&Flicker<f64>> = parts.iter().collect();
    let mut joined = Flicker::<f64x4>::from_parts(&refs);
    let mut fresh = joined.clone();
    fresh.reset();
    let input: Vec<f64x4> = (0..300).map(|_| g.next()).collect();
    let mut out = vec![f64x4::ZERO; input.len()];
    joined.process(&input, &mut out);
    for (j, f) in parts.iter_mut().enumerate() {
        let mut start = f.clone();
        start.reset();
        for (n, (x, y)) in input.iter().zip(&out).enumerate() {
            let want = f.tick(x.to_array()[j]);
            assert_eq!(
                y.to_array()[j].to_bits(),
                want.to_bits(),
                "lane {j} sample {n}"
            );
        }
        let x = input[0];
        assert_eq!(
            fresh.clone().tick(x).to_array()[j].to_bits(),
            start.tick(x.to_array()[j]).to_bits(),
            "lane {j} after reset"
        );
    }
}

#[test]
#[should_panic(expected = "one design")]
fn sources_of_different_designs_are_not_joined() {
    let mut g = Gauss::new([1, 2, 3, 4]);
    let a = Flicker::<f64>::stationary(&params(), || g.next().to_array()[0]).unwrap();
    let other = FlickerParams {
        f_lo_hz: 1e-4,
        ..params()
    };
    let b = Flicker::<f64>::stationary(&other, || g.next().to_array()[0]).unwrap();
    let _ = Flicker::<f64x4>::from_parts(&[&a, &a, &b, &a]);
}

#[test]
fn lanes_are_the_scalar_streams_and_seeds_decide_the_bits() {
    // Lane l of a source fed a 4-stream NoiseRng equals a scalar source fed that lane's seed
    // alone (NoiseRng lane 0 of [seed; 4]), start state included.
    let p = params();
    let seeds = [11, 22, 33, 44];
    let run_vec = |seeds: [u64; 4]| {
        let mut g = Gauss::new(seeds);
        let mut f = Flicker::<f64x4>::stationary(&p, || g.next()).unwrap();
        (0..20_000)
            .map(|_| f.tick(g.next()).to_array())
            .collect::<Vec<_>>()
    };
    let v = run_vec(seeds);
    for (l, &seed) in seeds.iter().enumerate() {
        let mut g = Gauss::new([seed; 4]);
        let mut f = Flicker::<f64>::stationary(&p, || g.next().to_array()[0]).unwrap();
        for (n, row) in v.iter().enumerate() {
            let y = f.tick(g.next().to_array()[0]);
            assert_eq!(y.to_bits(), row[l].to_bits(), "lane {l} sample {n}");
        }
    }
    let again = run_vec(seeds);
    assert!(v
        .iter()
        .flatten()
        .zip(again.iter().flatten())
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    let other = run_vec([12, 22, 33, 44]);
    assert!(v
        .iter()
        .zip(&other)
        .all(|(a, b)| a[0] != b[0] && a[1] == b[1]));
}

#[test]
fn start_is_drawn_from_the_stationary_law() {
    // 4096 independent starts (1024 seeds x 4 lanes). The first sample's variance against the
    // exact variance, and the variance of the mean of the first M = 100 samples (under the
    // slowest state's time constant 1 / (2 pi f_lo) = 159 samples, so a start at rest has not
    // built it up) against its exact value int S(f) sin^2(pi f M) / (M sin(pi f))^2 df.
    // The variance of n draws of a Gaussian has relative standard error sqrt(2/n); five.
    let p = params();
    const M: usize = 100;
    let mf = M as f64;
    let fejer = |f: f64| {
        let x = core::f64::consts::PI * f;
        ((mf * x).sin() / (mf * x.sin())).powi(2)
    };
    let mut first = Vec::new();
    let mut means = Vec::new();
    let mut means_at_rest = Vec::new();
    for seed in 0..1024u64 {
        let mut g = Gauss::new(core::array::from_fn(|l| 1000 + 4 * seed + l as u64));
        let mut f = Flicker::<f64x4>::stationary(&p, || g.next()).unwrap();
        let mut rest = Flicker::<f64x4>::at_rest(&p).unwrap();
        let (mut acc, mut acc_rest) = (f64x4::splat(0.0), f64x4::splat(0.0));
        for n in 0..M {
            let w = g.next();
            let y = f.tick(w);
            if n == 0 {
                first.extend(y.to_array());
            }
            acc += y;
            acc_rest += rest.tick(w);
        }
        means.extend((acc / f64x4::splat(mf)).to_array());
        means_at_rest.extend((acc_rest / f64x4::splat(mf)).to_array());
    }
    let var = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64;
    let d = Flicker::<f64>::at_rest(&p).unwrap().design().clone();
    let tol = 5.0 * (2.0 / first.len() as f64).sqrt();
    let v0 = var(&first);
    assert!(
        (v0 / d.variance() - 1.0).abs() < tol,
        "first sample: variance {v0}, exact {}",
        d.variance()
    );
    let exact = integrate(1.0, mf, |f| d.psd(f), fejer, 8.0);
    let (vm, vr) = (var(&means), var(&means_at_rest));
    eprintln!(
        "var(y[0]) / exact = {:.4}; var(mean of {M}) / exact = {:.4} (started at rest: {:.4}); \
         5 se = {tol:.3}",
        v0 / d.variance(),
        vm / exact,
        vr / exact
    );
    assert!(
        (vm / exact - 1.0).abs() < tol,
        "mean of {M}: {vm} vs {exact}"
    );
    // The check has the power to see a start at rest.
    assert!(vr / exact < 1.0 - 2.0 * tol, "at rest: {vr} vs {exact}");
}
