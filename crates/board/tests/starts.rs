//! Lanes that start later on the time axis (`Board::with_starts`): a lane holds the bits of a
//! board started there alone, whatever the other lanes' starts; its oscillators continue the
//! time axis (so its average over a window equals a board's that ran from 0 to that window, up
//! to the transient it settled from); and starts the carrier cannot share are refused.

mod common;

use common::{m2tfg, noisy, point};
use gyroemu_board::{
    max_lanes, starts_share_carrier, Board, GroupBoard, LaneResult, Point, RunOptions, Shape,
};
use gyroemu_core::Complex64;
use gyroemu_lpf::Window;

fn run_one(
    p: &gyroemu_board::BoardParams,
    q: Point,
    stream: u64,
    start: u64,
    n_settle: u64,
) -> LaneResult {
    Board::<f64>::with_starts(p, &[q.rate_rad_s], &[stream], &[start])
        .unwrap()
        .run(n_settle, &[q], RunOptions::default(), &|_| {})
        .unwrap()
        .lanes[0]
}

#[test]
fn a_lane_started_late_holds_the_bits_of_a_board_started_there_alone() {
    // At fs = 16 f0 the carrier repeats every 16 samples: these starts share it.
    let starts = [0, 1_600, 48_016, 16, 2_400_000, 160, 320_000];
    let rates = [25.0, 100.0, 175.0, 50.0, 150.0, 75.0, 125.0];
    for shape in [Shape::Rotating, Shape::Coriolis] {
        for p in [m2tfg(shape), noisy(m2tfg(shape), 9)] {
            assert!(starts_share_carrier(&p, &starts));
            let n = max_lanes().min(rates.len());
            let points: Vec<Point> = (0..n).map(|i| point(rates[i], 90 + 7 * i as u64)).collect();
            let rad: Vec<f64> = points.iter().map(|q| q.rate_rad_s).collect();
            let streams: Vec<u64> = (0..n as u64).map(|i| 3 * i + 1).collect();
            let lanes = GroupBoard::with_starts(&p, &rad, &streams, &starts[..n])
                .unwrap()
                .run(10, &points, RunOptions::default(), &|_| {})
                .unwrap()
                .lanes;
            for (i, q) in points.iter().enumerate() {
                let alone = run_one(&p, *q, streams[i], starts[i], 10);
                assert_eq!(lanes[i], alone, "{shape:?} lane {i} (start {})", starts[i]);
            }
        }
    }
}

/// The average over decimated samples `a + s .. a + s + len` of the absolute time axis, from a
/// board that ran from sample 0 (settling `a + s` blocks) and from one started at block `a`
/// (settling `s`).
fn both_ways(shape: Shape, rate_dps: f64, a: u64, start_at: u64) -> (LaneResult, LaneResult) {
    let p = m2tfg(shape);
    let m = p.decimation as u64;
    // 16 mechanical time constants Q / (pi f0) at 2.4 kHz out: 1630 blocks.
    let s = 1_630;
    let q = Point {
        rate_rad_s: rate_dps.to_radians(),
        window: Window::Boxcar {
            n: 2_400,
            frac: 0.0,
        },
    };
    (
        run_one(&p, q, 0, 0, a + s),
        run_one(&p, q, 0, start_at * m, s),
    )
}

fn rel(a: [Complex64; 2], b: [Complex64; 2]) -> f64 {
    (0..2)
        .map(|k| (a[k] - b[k]).norm() / a[k].norm())
        .fold(0.0, f64::max)
}

#[test]
fn a_late_start_continues_the_time_axis() {
    // 3604 blocks (1.5017 s): 0.73 turns of the modulation at 175 deg/s (not a whole
    // number), and 22 525 carrier turns (360 400 samples of 16), so the carrier is shared.
    let a = 3_604;
    // The transient left after 16 time constants is e^-16 = 1.1e-7 of the response: the
    // averages agree far inside 1e-6.
    let (from0, late) = both_ways(Shape::Rotating, 175.0, a, a);
    let (c, s) = (rel(from0.c, late.c), rel(from0.s, late.s));
    assert!(c < 1e-6 && s < 1e-6, "rotating: {c:e} {s:e}");
    let (from0, late) = both_ways(Shape::Coriolis, 175.0, a, a);
    let z = rel(from0.z, late.z);
    assert!(z < 1e-6, "Coriolis: {z:e}");
    // The test sees a start that does not continue the axis: a board started at 0 averages
    // the modulation 0.73 turns earlier, its C and S turned by that much.
    let (from0, wrong) = both_ways(Shape::Rotating, 175.0, a, 0);
    assert!(rel(from0.c, wrong.c) > 0.1, "{:e}", rel(from0.c, wrong.c));
}

#[test]
fn starts_the_carrier_cannot_share_are_refused_with_the_rule() {
    let p = m2tfg(Shape::Rotating);
    let rad = [0.1, 0.2];
    // One sample apart: 1/16 of a carrier turn.
    assert!(!starts_share_carrier(&p, &[0, 1]));
    let e = Board::<f64>::with_starts(&p, &rad[..1], &[0], &[0, 16])
        .err()
        .unwrap();
    assert_eq!(e.param, "starts");
    assert!(e.rule.contains("one start per point"), "{}", e.rule);
    let e = GroupBoard::with_starts(&p, &rad, &[0, 1], &[0, 1])
        .err()
        .unwrap();
    assert_eq!((e.param, e.value.as_str()), ("starts", "[0, 1]"));
    assert!(e.rule.contains("carrier"), "{}", e.rule);
    // A lone lane may start anywhere: nothing to share with.
    assert!(GroupBoard::with_starts(&p, &rad[..1], &[0], &[1]).is_ok());
    let t = m2tfg(Shape::RateTable { freq_hz: 2.0 });
    let e = GroupBoard::with_starts(&t, &rad, &[0, 1], &[0, 16])
        .err()
        .unwrap();
    assert!(e.rule.contains("rate table"), "{}", e.rule);
    assert!(GroupBoard::with_starts(&t, &rad, &[0, 1], &[0, 0]).is_ok());
}
