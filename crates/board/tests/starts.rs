//! Lanes that start later on the time axis (`Board::with_starts`): a lane holds the bits of a
//! board started there alone, whatever the other lanes' starts; its oscillators are those of
//! the time axis where it starts, so its average over a window equals a board's that ran from
//! 0 to that window, up to the transient it settled from (a rate table's too, its table at
//! the time axis's phase); an overflow is placed on the time axis; and starts the carrier
//! cannot share are refused.

mod common;

use common::{m2tfg, noisy, point};
use gyroemu_board::{
    max_lanes, starts_share_carrier, Board, GroupBoard, LaneResult, Point, Probe, RunOptions,
    Shape, MAX_START,
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
    let table = Shape::RateTable { freq_hz: 1.7 };
    for shape in [Shape::Rotating, Shape::Coriolis, table] {
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
    // 16 mechanical time constants Q / (pi f0) at 2.4 kHz out: 1630 blocks.
    settled(shape, rate_dps, a, start_at, 1_630)
}

/// [`both_ways`] with a settling of `s` blocks.
fn settled(shape: Shape, rate_dps: f64, a: u64, start_at: u64, s: u64) -> (LaneResult, LaneResult) {
    let p = m2tfg(shape);
    let m = p.decimation as u64;
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

/// `|a - b| / |a|` over the phasors of both modes (C and S together for a rotating run).
fn rel(a: &[Complex64], b: &[Complex64]) -> f64 {
    let norm = |v: &mut dyn Iterator<Item = Complex64>| v.map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    norm(&mut a.iter().zip(b).map(|(x, y)| x - y)) / norm(&mut a.iter().copied())
}

fn rotating(r: &LaneResult) -> [Complex64; 4] {
    [r.c[0], r.c[1], r.s[0], r.s[1]]
}

#[test]
fn a_late_start_continues_the_time_axis() {
    // 3601 blocks (1.5004 s): 0.73 turns of the modulation at 175 deg/s and 22 506.25 turns
    // of the carrier (360 100 samples of 16), so the late board's oscillators start a quarter
    // of a carrier turn and most of a modulation turn on: both jumps are checked.
    let a = 3_601;
    // The transient left after 16 time constants is e^-16 = 1.1e-7 of the response and decays
    // within tau = 42 ms of the 1 s window: its share of the average is about 1.1e-7 x 0.042
    // = 5e-9.
    let (from0, late) = both_ways(Shape::Rotating, 175.0, a, a);
    let d = rel(&rotating(&from0), &rotating(&late));
    assert!(d < 1e-8, "rotating: {d:e}");
    let (from0, late) = both_ways(Shape::Coriolis, 175.0, a, a);
    let d = rel(&from0.z, &late.z);
    assert!(d < 1e-8, "Coriolis: {d:e}");
    // The test sees a start that does not continue the axis. A board started at 0 averages
    // the window 1.5 s earlier: the window is not a whole number of modulation periods, and
    // what it leaks there differs by 5.7e-2 of the sidebands. (A carrier left unjumped would
    // turn every phasor a quarter turn: 1.4.)
    let (from0, wrong) = both_ways(Shape::Rotating, 175.0, a, 0);
    let d = rel(&rotating(&from0), &rotating(&wrong));
    assert!(d > 1e-2, "{d:e}");
}

/// The table harmonics of both modes, -6 ..= 6.
fn table(r: &LaneResult) -> Vec<Complex64> {
    r.table_z.iter().flatten().copied().collect()
}

#[test]
fn a_late_start_continues_a_rate_tables_time_axis() {
    // A 1.7 Hz table over a 1 s window (1.7 periods, so what the window holds depends on
    // where it lies), 100 deg/s: the late board's table starts 2.55 turns on, and its
    // reference phase at each output is the time axis's. The transient's share is as in the
    // rotating case above.
    let shape = Shape::RateTable { freq_hz: 1.7 };
    let a = 3_601;
    let (from0, late) = both_ways(shape, 100.0, a, a);
    let d = rel(&table(&from0), &table(&late));
    assert!(d < 3e-8, "rate table: {d:e}");
    // What is left is the start transient: 370 blocks more settling (3.66 mechanical time
    // constants of 101 blocks) divide it by e^3.66 = 39 (measured: 1.13e-8, then 3.0e-10).
    let (from0, late) = settled(shape, 100.0, a, a, 2_000);
    let longer = rel(&table(&from0), &table(&late));
    let fold = d / longer;
    assert!((20.0..80.0).contains(&fold), "{d:e} then {longer:e}");
    // A table (or its reference) counted from the late board's own sample 0 reads the
    // window 1.5 s earlier on the table's cycle: its harmonics differ by far more.
    let (from0, wrong) = both_ways(shape, 100.0, a, 0);
    let d = rel(&table(&from0), &table(&wrong));
    assert!(d > 1e-2, "{d:e}");
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
    // A rate table's lanes follow the same rule (each lane has its own table).
    let t = m2tfg(Shape::RateTable { freq_hz: 2.0 });
    assert!(GroupBoard::with_starts(&t, &rad, &[0, 1], &[0, 16]).is_ok());
    let e = GroupBoard::with_starts(&t, &rad, &[0, 1], &[0, 1])
        .err()
        .unwrap();
    assert!(e.rule.contains("carrier"), "{}", e.rule);
    let tables = [2.0, 3.0];
    let e = GroupBoard::with_table_hz_starts(&t, &rad, &tables, &[0, 1], &[0])
        .err()
        .unwrap();
    assert!(e.rule.contains("one start per point"), "{}", e.rule);
    // Past 2^53 samples a start (and a sample index past it) is no longer exact: refused,
    // named; the last start allowed, a whole number of carrier turns, is taken.
    let late = MAX_START + 16;
    let e = Board::<f64>::with_starts(&p, &rad[..1], &[0], &[late])
        .err()
        .unwrap();
    assert_eq!(
        (e.param, e.value.as_str()),
        ("starts", late.to_string().as_str())
    );
    assert!(e.rule.contains("2^53"), "{}", e.rule);
    assert!(Board::<f64>::with_starts(&t, &rad[..1], &[0], &[MAX_START]).is_ok());
}

#[test]
fn an_overflow_in_a_late_lane_is_placed_on_the_runs_time_axis() {
    // Driven far beyond any full scale: the chain overflows a few milliseconds from rest
    // (`tests/nonfinite_guard.rs`), at the same sample of a lane's own run wherever it starts
    // (a start 160 000 samples late, a whole number of carrier turns).
    let mut p = m2tfg(Shape::Coriolis);
    p.drive = [1e295, 1e295];
    p.plant.transduction_a_s_per_m = 1e10;
    let q = point(50.0, 40);
    let fault = |start: u64| {
        Board::<f64>::with_starts(&p, &[q.rate_rad_s], &[0], &[start])
            .unwrap()
            .run(2, &[q], RunOptions::default(), &|_| {})
            .unwrap_err()
    };
    let (from0, late) = (fault(0), fault(160_000));
    assert_eq!(from0.stage, late.stage);
    assert!(from0.sample > 0 && from0.sample < 4_200, "{from0}");
    assert_eq!(late.sample, from0.sample + 160_000, "{late}");
    assert_eq!(late.time_s, late.sample as f64 / p.fs_hz());
}

/// The drives a board records over its input samples `from .. from + 32` of its own run
/// (`drive1`, `drive2` of the full-rate dump).
fn drives(p: &gyroemu_board::BoardParams, board_start: u64, from: u64) -> Vec<[f64; 2]> {
    let fs = p.fs_hz();
    let q = point(175.0, 3_610);
    let mut probe = Probe::new(
        &["drive".to_string()],
        fs,
        p.decimation,
        from as f64 / fs,
        32.0 / fs,
        0,
    );
    let opts = RunOptions {
        probe: Some(&mut probe),
        ..Default::default()
    };
    Board::<f64>::with_starts(p, &[q.rate_rad_s], &[0], &[board_start])
        .unwrap()
        .run(2, &[q], opts, &|_| {})
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    probe.write(dir.path(), "d").unwrap();
    let text = std::fs::read_to_string(dir.path().join("d_fullrate.csv")).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    // Columns: sample, time_s, drive1, drive2.
    rows.iter().map(|r| [r[2], r[3]]).collect()
}

#[test]
fn a_late_lanes_oscillators_are_those_of_the_time_axis_where_it_starts() {
    // A rotating drive is cos(Omega t) cos(w0 t) and sin(Omega t) cos(w0 t): both oscillators.
    // 360 100 samples is 22 506.25 carrier turns and 0.73 turns of the modulation at
    // 175 deg/s: a board started there must drive what one started at 0 drives there (within
    // the rotating oscillators' rounding, a few ulps: each is re-set from its exact phase word
    // every 64 samples).
    let p = m2tfg(Shape::Rotating);
    let start = 360_100;
    let (late, continuous) = (drives(&p, start, 0), drives(&p, 0, start));
    assert_eq!(late.len(), 32);
    for (j, (a, b)) in late.iter().zip(&continuous).enumerate() {
        for k in 0..2 {
            assert!(
                (a[k] - b[k]).abs() < 1e-13,
                "sample {j} drive {k}: {} {}",
                a[k],
                b[k]
            );
        }
    }
}
