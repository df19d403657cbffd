//! A run stopped by its cancel flag marks complete exactly the lanes whose window ended
//! before the stop, and those lanes hold the bits (averages and counts) an uninterrupted run
//! returns; an uninterrupted run marks every lane complete.

mod common;

use common::{m2tfg, noisy, point};
use gyroemu_board::{Board, RunOptions, Shape};
use gyroemu_core::f64x4;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

#[test]
fn a_cancelled_run_keeps_the_lanes_whose_window_ended() {
    let n_settle = 12;
    // Windows ending near decimated sample 313, 3013 and 6013 (decimation 100): a cancel
    // raised once 100 000 input samples (1000 decimated) are done stops between the first
    // and the second.
    let points = [point(25.0, 300), point(100.0, 3000), point(175.0, 6000)];
    let rad: Vec<f64> = points.iter().map(|p| p.rate_rad_s).collect();
    let streams = [7, 3, 11];
    for shape in [
        Shape::Coriolis,
        Shape::RateTable { freq_hz: 2.0 },
        Shape::Rotating,
    ] {
        let p = noisy(m2tfg(shape), 42);
        let whole = Board::<f64x4>::new(&p, &rad, &streams)
            .unwrap()
            .run(n_settle, &points, RunOptions::default(), &|_| {})
            .unwrap();
        assert_eq!(whole.complete, [true; 3], "{shape:?}");

        let mut board = Board::<f64x4>::new(&p, &rad, &streams).unwrap();
        let flag = Arc::new(AtomicBool::new(false));
        board.set_cancel(flag.clone());
        let at = AtomicU64::new(0);
        let cut = board
            .run(n_settle, &points, RunOptions::default(), &|n| {
                if n >= 100_000 && !flag.swap(true, Ordering::SeqCst) {
                    at.store(n, Ordering::SeqCst);
                }
            })
            .unwrap();
        // The stop comes at the report that raised the flag: blocks before it are averaged.
        let stop_k = at.load(Ordering::SeqCst) / 100 - 1;
        let ends: Vec<u64> = points
            .iter()
            .map(|q| n_settle + q.window.samples())
            .collect();
        assert!(ends[0] <= stop_k && stop_k < ends[1], "{shape:?}: {stop_k}");
        assert_eq!(cut.complete, [true, false, false], "{shape:?}");
        assert_eq!(cut.lanes[0], whole.lanes[0], "{shape:?}: the complete lane");
        assert_eq!(cut.lanes[0].health, whole.lanes[0].health);
        assert_ne!(
            cut.lanes[2], whole.lanes[2],
            "{shape:?}: a cut lane differs"
        );
    }
}
