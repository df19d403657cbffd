//! The stage contract (gyroemu_core::check) for the drive side: block processing, reset and
//! f64x4 lanes bit for bit for the modulator (both patterns, unit and general gains, four
//! operating points in the lanes), the quantiser and the DAC (inputs that clip), and the zero
//! latency of the memoryless modulator and quantiser.
//!
//! The DAC is memoryless (impulse response `[1]`, latency 0): its zero-order hold is realised by
//! the plant, whose `hold_response` is tested in the resonator crate (tests/hold.rs).

use gyroemu_am::{AmInput, AmModulator, Dac, DrivePattern, Quantizer};
use gyroemu_core::check::{self, Gen};
use gyroemu_core::{f64x4, Sample, Stage};

fn drive_input<S: Sample>(g: &mut Gen) -> AmInput<S> {
    AmInput {
        carrier_i: g.sample(-1.0, 1.0),
        carrier_q: g.sample(-1.0, 1.0),
        mod_cos: g.sample(-1.0, 1.0),
        mod_sin: g.sample(-1.0, 1.0),
    }
}

fn lane_of(x: &AmInput<f64x4>, l: usize) -> AmInput<f64> {
    AmInput {
        carrier_i: x.carrier_i.lane(l),
        carrier_q: x.carrier_q.lane(l),
        mod_cos: x.mod_cos.lane(l),
        mod_sin: x.mod_sin.lane(l),
    }
}

#[test]
fn modulator_blocks_reset_lanes_and_latency() {
    for pattern in [DrivePattern::Coriolis, DrivePattern::Rotating] {
        for (g1, g2) in [(1.0, 1.0), (1.5, -0.5)] {
            let m = AmModulator::<f64>::new(pattern, g1, g2).unwrap();
            check::tick_vs_process("am_modulator", &m, drive_input, check::same);
            check::reset_restores("am_modulator", &m, drive_input, check::same);
            let m4 = AmModulator::<f64x4>::new(pattern, g1, g2).unwrap();
            check::tick_vs_process("am_modulator<f64x4>", &m4, drive_input, check::same);
            // The carrier to drive 1 with the references at 1: `[g1]`, no delay.
            let mut s = m;
            let lat = s.latency_samples();
            let path = |x: f64| AmInput {
                carrier_i: x,
                carrier_q: 0.0,
                mod_cos: 1.0,
                mod_sin: 1.0,
            };
            check::latency_matches("am_modulator", lat, |x| s.tick(path(x))[0], 8, 0.0);
        }
        // Four operating points: the unit-gain shortcut in one lane only must not leak; nor
        // may it be taken when every lane's gains differ from 1, or only one drive's are 1.
        let lane_sets: [[(f64, f64); 4]; 4] = [
            [(1.0, 1.0), (0.3, -2.0), (1e-3, 7.5), (0.0, 1.1)],
            [(0.3, -2.0), (1e-3, 7.5), (0.0, 1.1), (2.0, 0.5)],
            [(1.0, 0.5), (1.0, -2.0), (1.0, 7.5), (1.0, 1.1)],
            [(1.0, 1.0); 4],
        ];
        for set in lane_sets {
            let scalars: Vec<AmModulator<f64>> = set
                .iter()
                .map(|&(a, b)| AmModulator::new(pattern, a, b).unwrap())
                .collect();
            check::lanes_match(
                "am_modulator",
                &AmModulator::<f64x4>::from_lanes(&scalars),
                &scalars,
                drive_input,
                lane_of,
                |y, l| y.map(|v| v.lane(l)),
                check::same,
            );
        }
    }
}

/// Inputs to 1.5 full scale: some clip at the end codes.
fn beyond_full_scale(g: &mut Gen) -> f64 {
    g.uniform(-1.95, 1.95)
}

#[test]
fn quantizer_and_dac_blocks_reset_and_lanes() {
    let q = Quantizer::<f64>::new(10, 1.3).unwrap();
    check::tick_vs_process("quantizer", &q, beyond_full_scale, check::same);
    check::reset_restores("quantizer", &q, beyond_full_scale, check::same);
    check::lanes_match(
        "quantizer",
        &Quantizer::<f64x4>::new(10, 1.3).unwrap(),
        &[q; 4],
        |g| g.sample(-1.95, 1.95),
        |x, l| x.lane(l),
        |y, l| y.lane(l),
        check::same,
    );
    // 1 is a level of 12 bits over 2 (step 2^-10): the impulse passes exactly, no delay.
    let mut unit = Quantizer::<f64>::new(12, 2.0).unwrap();
    let lat = unit.latency_samples();
    check::latency_matches("quantizer", lat, |x| unit.tick(x), 8, 0.0);
    for quant in [None, Some((10, 1.3))] {
        let d = Dac::<f64>::new(1e6, quant).unwrap();
        check::tick_vs_process("dac", &d, beyond_full_scale, check::same);
        check::reset_restores("dac", &d, beyond_full_scale, check::same);
        check::lanes_match(
            "dac",
            &Dac::<f64x4>::new(1e6, quant).unwrap(),
            &[d; 4],
            |g| g.sample(-1.95, 1.95),
            |x, l| x.lane(l),
            |y, l| y.lane(l),
            check::same,
        );
    }
    let mut ideal = Dac::<f64>::new(1e6, None).unwrap();
    let lat = ideal.latency_samples();
    check::latency_matches("dac", lat, |x| ideal.tick(x), 8, 0.0);
}
