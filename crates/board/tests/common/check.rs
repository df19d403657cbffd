//! The fused boards against the reference board (every stage through its own `Stage::tick`),
//! lane by lane and bit for bit.

use gyroemu_board::reference::run_reference;
use gyroemu_board::{eight_lanes_available, BoardParams, GroupBoard, Point, RunOptions};

/// The lane widths this CPU runs.
pub fn widths() -> Vec<usize> {
    if eight_lanes_available() {
        vec![4, 8]
    } else {
        eprintln!("no AVX-512 on this CPU: only groups of four lanes are checked");
        vec![4]
    }
}

/// The group's lanes (up to its width of `points`) against the reference board, one point
/// at a time, in every lane width.
pub fn check(name: &str, p: &BoardParams, points: &[Point], n_settle: u64) {
    for width in widths() {
        check_width(
            &format!("{name} in {width} lanes"),
            width,
            p,
            points,
            n_settle,
        );
    }
}

pub fn check_width(name: &str, width: usize, p: &BoardParams, points: &[Point], n_settle: u64) {
    let points = &points[..points.len().min(width)];
    let streams: Vec<u64> = (0..points.len() as u64).map(|i| 3 * i + 1).collect();
    let rates: Vec<f64> = points.iter().map(|q| q.rate_rad_s).collect();
    let fused = GroupBoard::with_width(width, p, &rates, &streams)
        .unwrap()
        .run(n_settle, points, RunOptions::default(), &|_| {})
        .unwrap()
        .lanes;
    for (i, q) in points.iter().enumerate() {
        let want = run_reference(p, q.rate_rad_s, streams[i], n_settle, q).unwrap();
        assert_eq!(fused[i], want, "{name}: lane {i}");
        let finite = [want.z, want.c, want.s]
            .iter()
            .flatten()
            .chain(want.table_z.iter().flatten())
            .all(|v| v.re.is_finite() && v.im.is_finite());
        assert!(finite, "{name}: lane {i}: {want:?}");
    }
}
