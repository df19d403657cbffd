//! A rate-table group whose lanes follow different tables (`Board::with_table_hz`, how the
//! bandwidth sweep packs its frequencies) gives each lane the bits of the scalar board built
//! with that lane's frequency alone, in four and in eight lanes, with and without noise.

mod common;

use common::{m2tfg, noisy, point};
use gyroemu_board::{
    eight_lanes_available, Board, BoardParams, GroupBoard, RunOptions, RunOutput, Shape,
};
use gyroemu_core::f64x4;

/// Table frequencies far apart (Hz), so that a lane reading another lane's table would show.
const FREQS: [f64; 7] = [2.0, 0.5, 7.25, 3.0, 1.0, 11.0, 0.3];

fn scalar(p: &BoardParams, f: f64, q: gyroemu_board::Point, stream: u64) -> RunOutput {
    let p = BoardParams {
        shape: Shape::RateTable { freq_hz: f },
        ..*p
    };
    Board::<f64>::new(&p, &[q.rate_rad_s], &[stream])
        .unwrap()
        .run(12, &[q], RunOptions::default(), &|_| {})
        .unwrap()
}

fn check(name: &str, p: &BoardParams, lanes: usize, width: usize) {
    let points: Vec<_> = (0..lanes)
        .map(|i| point(25.0 * (i as f64 + 1.0), 110 + 3 * i as u64))
        .collect();
    let rad: Vec<f64> = points.iter().map(|q| q.rate_rad_s).collect();
    let streams: Vec<u64> = (0..lanes as u64).map(|i| 3 * i + 1).collect();
    let freqs = &FREQS[..lanes];
    let run = |out: RunOutput| {
        for (i, q) in points.iter().enumerate() {
            let one = scalar(p, freqs[i], *q, streams[i]);
            assert_eq!(
                out.lanes[i], one.lanes[0],
                "{name}: lane {i} at {} Hz",
                freqs[i]
            );
        }
    };
    // Each run is known to take the per-lane loop, whose lanes are held to the scalar
    // boards' (shared-table) bits.
    if width == 4 {
        let mut b = Board::<f64x4>::with_table_hz(p, &rad, freqs, &streams).unwrap();
        assert!(b.table_per_lane(), "{name}");
        run(b.run(12, &points, RunOptions::default(), &|_| {}).unwrap());
    } else {
        let mut b = GroupBoard::with_table_hz(p, &rad, freqs, &streams).unwrap();
        assert_eq!(b.width(), 8);
        assert!(b.table_per_lane(), "{name}");
        run(b.run(12, &points, RunOptions::default(), &|_| {}).unwrap());
    }
}

#[test]
fn each_lane_follows_its_own_table_bit_for_bit() {
    let p = m2tfg(Shape::RateTable { freq_hz: 2.0 });
    for (name, p) in [("noiseless", p), ("noisy", noisy(p, 9))] {
        check(name, &p, 4, 4);
        if eight_lanes_available() {
            check(name, &p, 7, 8);
        }
    }
}

#[test]
fn lanes_of_one_frequency_equal_the_shared_table() {
    // Tables given per lane that are all the board's run the shared table's loop, with the
    // bits of the board built without them.
    let p = m2tfg(Shape::RateTable { freq_hz: 3.0 });
    let points = [point(50.0, 100), point(150.0, 90)];
    let rad = [points[0].rate_rad_s, points[1].rate_rad_s];
    let run = |b: Board<f64x4>| {
        assert!(!b.table_per_lane());
        let mut b = b;
        b.run(12, &points, RunOptions::default(), &|_| {}).unwrap()
    };
    let shared = run(Board::new(&p, &rad, &[0, 1]).unwrap());
    let per_lane = run(Board::with_table_hz(&p, &rad, &[3.0, 3.0], &[0, 1]).unwrap());
    assert_eq!(shared.lanes, per_lane.lanes);
}

#[test]
fn lanes_take_the_per_lane_loop_exactly_where_their_tables_differ() {
    // Another frequency or another start on the time axis (a rate table's phase counts from
    // its sample 0) gives a lane a table of its own; one table for all keeps the shared loop.
    let p = m2tfg(Shape::RateTable { freq_hz: 3.0 });
    let rad = [0.5, 1.5];
    let per_lane = |b: Result<Board<f64x4>, gyroemu_core::ParamError>| b.unwrap().table_per_lane();
    assert!(!per_lane(Board::new(&p, &rad, &[0, 1])));
    assert!(!per_lane(Board::with_table_hz(
        &p,
        &rad,
        &[3.0, 3.0],
        &[0, 1]
    )));
    assert!(!per_lane(Board::with_starts(&p, &rad, &[0, 1], &[32, 32])));
    assert!(per_lane(Board::with_table_hz(
        &p,
        &rad,
        &[3.0, 2.0],
        &[0, 1]
    )));
    assert!(per_lane(Board::with_starts(&p, &rad, &[0, 1], &[0, 16])));
    let starts = [0, 16];
    let b = Board::with_table_hz_starts(&p, &rad, &[3.0, 3.0], &[0, 1], &starts);
    assert!(per_lane(b));
    // Other shapes have no table.
    let c = m2tfg(Shape::Coriolis);
    assert!(!per_lane(Board::with_starts(&c, &rad, &[0, 1], &[0, 16])));
}

#[test]
fn bad_table_frequencies_are_refused_naming_the_rule() {
    let p = m2tfg(Shape::RateTable { freq_hz: 2.0 });
    let e = |r: Result<Board<f64x4>, gyroemu_core::ParamError>| r.err().unwrap().to_string();
    let msg = e(Board::with_table_hz(&p, &[0.1, 0.2], &[1.0], &[0, 1]));
    assert!(msg.contains("one frequency per point"), "{msg}");
    for bad in [0.0, -1.0, f64::NAN] {
        let msg = e(Board::with_table_hz(&p, &[0.1], &[bad], &[0]));
        assert!(msg.contains("table_freq_hz"), "{msg}");
    }
    let c = m2tfg(Shape::Coriolis);
    let msg = e(Board::with_table_hz(&c, &[0.1], &[1.0], &[0]));
    assert!(msg.contains("rate-table board"), "{msg}");
}
