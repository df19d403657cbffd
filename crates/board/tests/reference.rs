//! The fused kernel against the reference board (every stage through its own `Stage::tick`,
//! none of the kernel's shortcuts), bit for bit: every experiment shape, with and without
//! noise, flicker and converters, an imperfect device, decimation 1, 100, 256 and 600, each
//! lane of a group, in groups of four lanes and (on a CPU with AVX-512) of eight.

mod common;

use common::check::check;
use common::{flickering, imperfect, m2tfg, noisy, point};
use gyroemu_board::{eight_lanes_available, Board, BoardParams, GroupBoard, Shape};
use gyroemu_core::f64x4;

const SHAPES: [Shape; 3] = [
    Shape::Coriolis,
    Shape::RateTable { freq_hz: 20.0 },
    Shape::Rotating,
];

#[test]
fn fused_lanes_equal_the_reference_board_for_every_shape() {
    for shape in SHAPES {
        let p = m2tfg(shape);
        // Four points in groups of four; six (two lanes idle) in groups of eight.
        let pts = [
            point(25.0, 60),
            point(175.0, 37),
            point(-100.0, 50),
            point(60.0, 44),
            point(-175.0, 52),
            point(0.0, 41),
        ];
        check(&format!("{shape:?}"), &p, &pts, 30);
        check(&format!("{shape:?} noisy"), &noisy(p, 42), &pts, 30);
        check(
            &format!("{shape:?} imperfect"),
            &imperfect(noisy(p, 7)),
            &pts,
            30,
        );
        // Every flicker source on: the slow ones per block, the TIA's per sample, the
        // carrier's in the demodulation too.
        check(&format!("{shape:?} flicker"), &flickering(p, 5), &pts, 30);
        check(
            &format!("{shape:?} imperfect flicker"),
            &imperfect(flickering(p, 9)),
            &pts,
            30,
        );
    }
}

#[test]
fn fused_equals_reference_without_decimation_and_at_rest() {
    for shape in SHAPES {
        let mut p = m2tfg(shape);
        p.decimation = 1;
        p.lowpass = gyroemu_lpf::LowPassDesign::Butterworth {
            order: 3,
            cutoff_hz: 900.0,
        };
        // One point at rest: the decoupled plant step in a Coriolis run.
        check(&format!("{shape:?} M = 1"), &p, &[point(0.0, 3000)], 500);
        let pts = [
            point(0.0, 2000),
            point(60.0, 2000),
            point(-30.0, 1900),
            point(90.0, 2000),
            point(120.0, 1990),
        ];
        check(&format!("{shape:?} M = 1 noisy"), &noisy(p, 3), &pts, 500);
        check(
            &format!("{shape:?} M = 1 flicker"),
            &flickering(p, 4),
            &pts,
            500,
        );
    }
}

#[test]
fn fused_equals_reference_with_flicker_over_long_blocks() {
    // The TIA's flicker is drawn ahead at most 256 samples at a time and never past a
    // decimation block: M = 600 takes chunks of 256, 256 and 88, M = 256 one whole chunk.
    for m in [600, 256] {
        for shape in SHAPES {
            let mut p = m2tfg(shape);
            p.decimation = m;
            p.lowpass = gyroemu_lpf::LowPassDesign::Butterworth {
                order: 2,
                cutoff_hz: 60.0,
            };
            let pts = [
                point(25.0, 12),
                point(-100.0, 9),
                point(60.0, 11),
                point(175.0, 10),
                point(0.0, 12),
            ];
            check(
                &format!("{shape:?} M = {m} flicker"),
                &flickering(p, 6),
                &pts,
                6,
            );
        }
    }
}

#[test]
fn fused_equals_reference_with_some_slow_flicker_sources_off() {
    // The fused boards draw the slow sources' Gaussians in one fill per block, the reference
    // one pair per source that is on: every subset must take the same draws in the same order.
    let subsets: [(f64, f64, f64, f64); 4] = [
        (1e-3, 0.0, 0.0, 0.0),
        (0.0, 2e-3, 3e-3, 0.0),
        (0.0, 0.0, 3e-3, 5e4),
        (1e-3, 0.0, 3e-3, 0.0),
    ];
    for (amp, phase, carrier, tia_corner) in subsets {
        for shape in [Shape::Rotating, Shape::Coriolis] {
            let mut p = flickering(m2tfg(shape), 8);
            if let Some(n) = &mut p.noise {
                n.drive_amplitude_flicker_per_rthz = amp;
                n.drive_phase_flicker_rad_per_rthz = phase;
                n.carrier_phase_flicker_rad_per_rthz = carrier;
                n.tia_voltage_flicker_corner_hz = tia_corner;
            }
            let pts = [point(25.0, 12), point(-100.0, 9), point(60.0, 11)];
            let name = format!("{shape:?} slow flicker {amp} {phase} {carrier} {tia_corner}");
            check(&name, &p, &pts, 6);
        }
    }
}

#[test]
fn the_shortcuts_under_test_are_taken() {
    // A rotating run without coupling, and a Coriolis run at rest, take the decoupled plant
    // step (so the reference comparison covers it); rotation or coupling keep the full step.
    let rot = m2tfg(Shape::Rotating);
    assert!(Board::<f64x4>::new(&rot, &[0.5, 1.0], &[0, 1])
        .unwrap()
        .plant_decoupled());
    let cor = m2tfg(Shape::Coriolis);
    assert!(Board::<f64x4>::new(&cor, &[0.0], &[0])
        .unwrap()
        .plant_decoupled());
    assert!(!Board::<f64x4>::new(&cor, &[0.0, 1e-3], &[0, 1])
        .unwrap()
        .plant_decoupled());
    assert!(!Board::<f64x4>::new(&imperfect(rot), &[1.0], &[0])
        .unwrap()
        .plant_decoupled());
    // A rate table on a device without coupling takes the step split by mode; with the
    // imperfect device's quadrature coupling, the full time-varying step.
    // A four-lane board with the TIA's flicker runs its two sources as one of eight lanes
    // where the CPU has AVX-512 (the comparisons above cover that path then; the four-lane
    // path is checked under `--lanes 4` in `four_lane_code.rs`).
    let f = Board::<f64x4>::new(&flickering(m2tfg(Shape::Rotating), 1), &[0.0], &[0]).unwrap();
    assert_eq!(f.tia_flicker_joined(), eight_lanes_available());
    let table = m2tfg(Shape::RateTable { freq_hz: 2.0 });
    assert!(Board::<f64x4>::new(&table, &[0.0, 1.0], &[0, 1])
        .unwrap()
        .plant_decoupled());
    assert!(!Board::<f64x4>::new(&imperfect(table), &[1.0], &[0])
        .unwrap()
        .plant_decoupled());
    // Eight lanes: every lane is checked (one rotating lane among decoupled ones).
    if eight_lanes_available() {
        let rot = m2tfg(Shape::Rotating);
        let eight = |p: &BoardParams, rates: &[f64]| {
            let streams: Vec<u64> = (0..rates.len() as u64).collect();
            GroupBoard::with_width(8, p, rates, &streams)
                .unwrap()
                .plant_decoupled()
        };
        assert!(eight(&rot, &[0.5; 8]));
        let cor = m2tfg(Shape::Coriolis);
        assert!(eight(&cor, &[0.0; 8]));
        assert!(!eight(&cor, &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1e-3]));
    }
}
