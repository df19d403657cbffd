//! Lane refill (`Board::run_refilled`): a lane that takes another point after its own has
//! ended gives that point the bits of a board built for it alone (another rate, window,
//! table and start on its own time axis), in four and in eight lanes, on rotating and
//! rate-table boards, ideal and imperfect; a refill off the rules is refused before any
//! sample; and a non-finite value in a refilled lane is located on that point's own axis.

mod common;

use common::{imperfect, m2tfg, noisy, point};
use gyroemu_board::{
    eight_lanes_available, BoardParams, GroupBoard, LaneResult, Point, Refill, RefillError, Shape,
};
use gyroemu_lpf::Window;

const SETTLE: u64 = 12;
/// Blocks of 100 input samples between possible refills: 16 blocks are 1600 samples, a
/// whole number of fs/16 carrier periods and of the oscillators' 64-sample re-sets.
const GRAIN: u64 = 16;

/// A point's own run: lane `lane` of a board built for that point alone.
#[derive(Clone, Copy, Debug)]
struct Job {
    point: Point,
    /// Start on its own time axis, decimation blocks.
    start_block: u64,
    table_hz: f64,
}

/// The job on a board of its own (a one-lane group).
fn alone(p: &BoardParams, j: &Job) -> LaneResult {
    let r = [j.point.rate_rad_s];
    let starts = [j.start_block * p.decimation as u64];
    let mut b = match p.shape {
        Shape::RateTable { .. } => {
            GroupBoard::with_table_hz_starts(p, &r, &[j.table_hz], &[0], &starts).unwrap()
        }
        _ => GroupBoard::with_starts(p, &r, &[0], &starts).unwrap(),
    };
    b.run_refilled(SETTLE, &[j.point], &[], &|_| {})
        .unwrap()
        .lanes[0]
}

/// `lanes` lanes, lane `i` running `per_lane` jobs back to back, each refill at the first
/// grain block after its lane's job ends; every job against its run alone. `shared`: every
/// point on the board's own table (refills naming none) and the first points from one start,
/// so the board is built on the shared table and the refills switch it to per-lane tables.
fn check(name: &str, p: &BoardParams, lanes: usize, per_lane: usize, shared: bool) {
    let own_hz = match p.shape {
        Shape::RateTable { freq_hz } => freq_hz,
        _ => 0.0,
    };
    let jobs: Vec<Vec<Job>> = (0..lanes)
        .map(|i| {
            (0..per_lane)
                .map(|k| {
                    let s = (i * per_lane + k) as f64;
                    let start = 3 * k + if shared && k == 0 { 0 } else { i % 2 };
                    Job {
                        point: point(20.0 + 13.0 * s, 40 + 29 * ((i + 2 * k) % 5) as u64),
                        start_block: GRAIN * start as u64,
                        table_hz: if shared { own_hz } else { 0.5 + 1.75 * s },
                    }
                })
                .collect()
        })
        .collect();
    let firsts: Vec<Job> = jobs.iter().map(|l| l[0]).collect();
    let mut refills = Vec::new();
    for (lane, l) in jobs.iter().enumerate() {
        let mut end = SETTLE + l[0].point.window.samples();
        for j in &l[1..] {
            let at_block = end.next_multiple_of(GRAIN);
            refills.push(Refill {
                lane,
                at_block,
                point: j.point,
                start: j.start_block * p.decimation as u64,
                table_hz: (!shared).then_some(j.table_hz),
            });
            end = at_block + SETTLE + j.point.window.samples();
        }
    }
    refills.sort_by_key(|r| r.at_block);
    let rates: Vec<f64> = firsts.iter().map(|j| j.point.rate_rad_s).collect();
    let streams: Vec<u64> = (0..lanes as u64).collect();
    let starts: Vec<u64> = firsts
        .iter()
        .map(|j| j.start_block * p.decimation as u64)
        .collect();
    let mut b = match p.shape {
        Shape::RateTable { .. } if !shared => {
            let hz: Vec<f64> = firsts.iter().map(|j| j.table_hz).collect();
            GroupBoard::with_table_hz_starts(p, &rates, &hz, &streams, &starts).unwrap()
        }
        _ => GroupBoard::with_starts(p, &rates, &streams, &starts).unwrap(),
    };
    if shared {
        assert!(!b.table_per_lane(), "{name}: built on the shared table");
    }
    let points: Vec<Point> = firsts.iter().map(|j| j.point).collect();
    let out = b.run_refilled(SETTLE, &points, &refills, &|_| {}).unwrap();
    for (lane, l) in jobs.iter().enumerate() {
        let got: Vec<LaneResult> = out.refilled[lane]
            .iter()
            .copied()
            .chain([out.lanes[lane]])
            .collect();
        assert_eq!(got.len(), l.len(), "{name}: lane {lane}'s results");
        for (k, (g, j)) in got.iter().zip(l).enumerate() {
            assert_eq!(*g, alone(p, j), "{name}: lane {lane}, its point {k}: {j:?}");
        }
    }
}

fn boards() -> Vec<(&'static str, BoardParams)> {
    let table = m2tfg(Shape::RateTable { freq_hz: 2.0 });
    let rotating = m2tfg(Shape::Rotating);
    vec![
        ("rate table", table),
        ("rate table, imperfect device", imperfect(table)),
        ("rotating", rotating),
        ("rotating, imperfect device", imperfect(rotating)),
    ]
}

#[test]
fn refilled_lanes_hold_the_bits_of_their_points_alone() {
    for (name, p) in boards() {
        for shared in [false, true] {
            let name = format!("{name}, shared table {shared}");
            check(&format!("{name}, four lanes"), &p, 3, 3, shared);
            if eight_lanes_available() {
                check(&format!("{name}, eight lanes"), &p, 7, 2, shared);
            }
        }
    }
}

/// A rotating board's first points and one valid refill of lane 0.
fn rotating_run() -> (BoardParams, Vec<Point>, Refill) {
    let p = m2tfg(Shape::Rotating);
    let points = vec![point(40.0, 30), point(90.0, 50)];
    let ok = Refill {
        lane: 0,
        at_block: 48,
        point: point(60.0, 20),
        start: 0,
        table_hz: None,
    };
    (p, points, ok)
}

fn refused(p: &BoardParams, points: &[Point], refills: &[Refill]) -> &'static str {
    let rates: Vec<f64> = points.iter().map(|q| q.rate_rad_s).collect();
    let streams: Vec<u64> = (0..points.len() as u64).collect();
    let mut b = GroupBoard::new(p, &rates, &streams).unwrap();
    let ran = std::sync::atomic::AtomicBool::new(false);
    let progress = |_| ran.store(true, std::sync::atomic::Ordering::Relaxed);
    match b.run_refilled(SETTLE, points, refills, &progress) {
        Err(RefillError::Refused(e)) => {
            let ran = ran.load(std::sync::atomic::Ordering::Relaxed);
            assert!(!ran, "refused after samples ran: {e}");
            e.param
        }
        other => panic!("not refused: {other:?}"),
    }
}

#[test]
fn refills_off_the_rules_are_refused_before_any_sample() {
    let (p, points, ok) = rotating_run();
    let with = |f: &dyn Fn(&mut Refill)| {
        let mut r = ok;
        f(&mut r);
        refused(&p, &points, &[r])
    };
    // Before the lane's point ends (block 12 + 31 = 43 ends it; 32 is a re-set).
    assert_eq!(with(&|r| r.at_block = 32), "refill.at_block");
    // Not at a re-set of the oscillators: 50 blocks are 5000 samples.
    assert_eq!(with(&|r| r.at_block = 50), "refill.at_block");
    // A start whose carrier phase is not the one at the refill (8 samples: half a period).
    assert_eq!(with(&|r| r.start = 8), "refill.start");
    assert_eq!(with(&|r| r.lane = 2), "refill.lane");
    // Points that would end past 2^53 input samples (the block counts would overflow).
    let huge = Window::Boxcar {
        n: u64::MAX - 3,
        frac: 0.0,
    };
    assert_eq!(with(&|r| r.point.window = huge), "refill.window");
    let long_first = [
        Point {
            window: huge,
            ..points[0]
        },
        points[1],
    ];
    assert_eq!(refused(&p, &long_first, &[ok]), "points.window");
    assert_eq!(
        with(&|r| r.point.rate_rad_s = f64::NAN),
        "refill.rate_rad_s"
    );
    // Out of block order.
    let late = Refill {
        lane: 1,
        at_block: 64,
        ..ok
    };
    assert_eq!(refused(&p, &points, &[late, ok]), "refill.at_block");
    // Boards a refill cannot keep the bits of.
    let coriolis = m2tfg(Shape::Coriolis);
    assert_eq!(refused(&coriolis, &points, &[ok]), "refills");
    assert_eq!(refused(&noisy(p, 3), &points, &[ok]), "refills");
    // The rules kept, the same run goes through, once: a board that has run no longer
    // stands where its refills' blocks count from.
    let rates: Vec<f64> = points.iter().map(|q| q.rate_rad_s).collect();
    let mut b = GroupBoard::new(&p, &rates, &[0, 1]).unwrap();
    let out = b.run_refilled(SETTLE, &points, &[ok], &|_| {}).unwrap();
    assert_eq!(out.refilled[0].len(), 1);
    match b.run_refilled(SETTLE, &points, &[ok], &|_| {}) {
        Err(RefillError::Refused(e)) => assert_eq!(e.param, "refills", "{e}"),
        other => panic!("a second run's refills went through: {other:?}"),
    }
}

#[test]
fn a_fault_in_a_refilled_lane_is_located_on_its_points_axis() {
    // A table amplitude that overflows the plant's rate terms, in the point lane 0 takes at
    // block 48 (input sample 4800), started 1600 samples into its own axis.
    let p = m2tfg(Shape::RateTable { freq_hz: 2.0 });
    let points = [point(40.0, 30), point(90.0, 50)];
    let huge = Refill {
        lane: 0,
        at_block: 48,
        point: Point {
            rate_rad_s: 1e200,
            ..point(60.0, 20)
        },
        start: 1600,
        table_hz: Some(3.0),
    };
    let rates: Vec<f64> = points.iter().map(|q| q.rate_rad_s).collect();
    let mut b = GroupBoard::new(&p, &rates, &[0, 1]).unwrap();
    match b.run_refilled(SETTLE, &points, &[huge], &|_| {}) {
        Err(RefillError::NonFinite(f)) => {
            // Found by a replay that refilled the lane too: in the plant (the fallback names
            // the low-pass), at the point's rate, at sample 1601 of its own axis (the plant
            // outputs its state before each step: at 1600 its rest, at 1601 the first state
            // stepped at that rate), not at the run's 4801.
            assert_eq!(f.stage, "resonator", "{f}");
            assert_eq!(f.rate_dps, 1e200f64.to_degrees(), "{f}");
            assert_eq!(f.sample, 1601, "{f}");
        }
        other => panic!("expected a located fault: {other:?}"),
    }
}
