//! The stage contract (gyroemu_core::check) for the plant: block processing and reset bit
//! for bit (f64 and f64x4, coupled and decoupled devices), the f64x4 plant packed from four
//! different scalar plants lane by lane, and the plant's exact frequency response
//! ([`Resonator::held_steady_state`], `(e^{jw} I - Phi)^-1 Gamma`) against the DFT of the
//! impulse response of each force-to-output path.
//!
//! No latency check: the plant keeps the default `latency_samples` of 0, which is not the
//! DC group delay of its displacement paths (reported as a contract question; its current
//! paths have no DC gain, hence no DC group delay at all).

use gyroemu_core::check::{self, FnResponse, Gen};
use gyroemu_core::{f64x4, Complex64, Sample, Stage};
use gyroemu_resonator::{ModeParams, PlantOutput, Resonator, ResonatorParams};

/// Four devices: mismatched modes, Q from 10 to 1e6, with and without quadrature coupling
/// and rotation rate (the last one is decoupled).
fn device(l: usize) -> (ResonatorParams, f64) {
    let f0 = [1000.0, 1500.0, 777.0, 2500.0][l];
    let q = [10.0, 1e3, 36_000.0, 1e6][l];
    let p = ResonatorParams {
        mode1: ModeParams { f0_hz: f0, q },
        mode2: ModeParams {
            f0_hz: 1.01 * f0,
            q: 0.7 * q,
        },
        angular_gain: [0.6, 1.0, 0.8, 0.9][l],
        quadrature_coupling_rad2_s2: [0.0, 1e3, -5e4, 0.0][l],
        transduction_a_s_per_m: [1.0, 2e-3, 0.5, 3.0][l],
        fs_hz: 16_000.0,
    };
    (p, [2.0, 2.0, -1.0, 0.0][l])
}

fn plant<S: Sample>(l: usize) -> Resonator<S> {
    let (p, omega) = device(l);
    Resonator::new(&p, omega).unwrap()
}

fn force<S: Sample>(g: &mut Gen) -> [S; 2] {
    [g.sample(-1.0, 1.0), g.sample(-1.0, 1.0)]
}

fn view<S: Copy>(y: &PlantOutput<S>) -> ([S; 2], [S; 2], [S; 2]) {
    (y.q, y.v, y.current)
}

#[test]
fn blocks_and_reset_are_bit_exact() {
    for l in 0..4 {
        check::tick_vs_process("resonator", &plant::<f64>(l), force, view);
        check::reset_restores("resonator", &plant::<f64>(l), force, view);
    }
    let packed = Resonator::<f64x4>::from_lanes(&(0..4).map(plant).collect::<Vec<_>>());
    check::tick_vs_process("resonator<f64x4>", &packed, force, view);
    check::reset_restores("resonator<f64x4>", &packed, force, view);
}

#[test]
fn lanes_of_four_different_plants_are_bit_exact() {
    let scalars: Vec<Resonator<f64>> = (0..4).map(plant).collect();
    let lane = |v: [f64x4; 2], l: usize| v.map(|x| x.lane(l));
    check::lanes_match(
        "resonator",
        &Resonator::<f64x4>::from_lanes(&scalars),
        &scalars,
        force,
        |x, l| lane(*x, l),
        |y, l| (lane(y.q, l), lane(y.v, l), lane(y.current, l)),
        view,
    );
}

#[test]
fn a_lane_reset_mid_run_starts_as_a_fresh_plant() {
    // The state of one lane back to rest, its coefficients kept (a board's lane refilled
    // with another point at the same plant rate); the other lanes keep their bits.
    let scalars: Vec<Resonator<f64>> = (0..4).map(plant).collect();
    let lane = |v: [f64x4; 2], l: usize| v.map(|x| x.lane(l));
    check::lane_replaced_matches(
        "resonator",
        &Resonator::<f64x4>::from_lanes(&scalars),
        (3, 4, 901),
        Resonator::reset_lane,
        &scalars[3],
        force,
        |x, l| lane(*x, l),
        |y, l| (lane(y.q, l), lane(y.v, l), lane(y.current, l)),
        view,
    );
}

#[test]
fn lanes_past_the_slice_repeat_its_last_plant() {
    // A group with fewer points than lanes: the spare lanes run the last point's plant.
    let lane = |v: [f64x4; 2], l: usize| v.map(|x| x.lane(l));
    for given in 1..4 {
        let scalars: Vec<Resonator<f64>> = (0..4).map(|l| plant(l.min(given - 1))).collect();
        check::lanes_match(
            "resonator",
            &Resonator::<f64x4>::from_lanes(&scalars[..given]),
            &scalars,
            force,
            |x, l| lane(*x, l),
            |y, l| (lane(y.q, l), lane(y.v, l), lane(y.current, l)),
            view,
        );
    }
}

#[test]
fn every_force_path_matches_the_held_steady_state_response() {
    // Low Q so the impulse response decays within n: tau = Q / (pi f0) = 1.6 ms, 25 samples.
    let p = ResonatorParams {
        mode1: ModeParams {
            f0_hz: 1000.0,
            q: 5.0,
        },
        mode2: ModeParams {
            f0_hz: 1010.0,
            q: 3.5,
        },
        angular_gain: 0.8,
        quadrature_coupling_rad2_s2: 5e4,
        transduction_a_s_per_m: 0.5,
        fs_hz: 16_000.0,
    };
    let r = Resonator::<f64>::new(&p, 50.0).unwrap();
    let n = 2048;
    // (input mode, output: q1 q2 v1 v2 current1 current2)
    for (input, output) in [(0, 0), (0, 1), (1, 2), (1, 5), (0, 4)] {
        let forced = |x: f64| {
            let mut f = [0.0; 2];
            f[input] = x;
            f
        };
        let pick =
            |y: PlantOutput<f64>| [y.q[0], y.q[1], y.v[0], y.v[1], y.current[0], y.current[1]];
        let h = FnResponse(|f_hz: f64| {
            let mut unit = [Complex64::new(0.0, 0.0); 2];
            unit[input] = Complex64::new(1.0, 0.0);
            let x = r.held_steady_state(f_hz, unit);
            // The currents are the velocities times the transduction.
            let (k, scale) = match output {
                4 => (2, p.transduction_a_s_per_m),
                5 => (3, p.transduction_a_s_per_m),
                k => (k, 1.0),
            };
            x[k] * scale
        });
        let mut s = r.clone();
        let name = format!("resonator force {} -> output {output}", input + 1);
        let worst = check::response_matches_impulse(
            &name,
            p.fs_hz,
            &h,
            |x| pick(s.tick(forced(x)))[output],
            n,
            // Rounding: ~eps log2(n) in the FFT, ~eps times the resolvent's condition in the
            // solve; measured about 4e-15.
            1e-13,
        );
        eprintln!("{name}: worst |DFT - H| / peak = {worst:e}");
    }
}
