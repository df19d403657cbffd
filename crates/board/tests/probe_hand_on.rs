//! A run hands its probe on (`RunOptions::on_probe_recorded`) once both dump windows have
//! ended: exactly once, while the run goes on, holding what a run without the hand-on records;
//! and the run's results do not change.

mod common;

use common::{m2tfg, noisy, point};
use gyroemu_board::{Board, BoardParams, Point, Probe, RunOptions, RunOutput, Shape, DUMP_NODES};
use gyroemu_core::f64x4;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// A four-lane run of `points` on `p` (lanes at `rates`, lane seeds from 1).
fn run(
    p: &BoardParams,
    rates: &[f64],
    n_settle: u64,
    points: &[Point],
    opts: RunOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> RunOutput {
    let seeds: Vec<u64> = (1..=rates.len() as u64).collect();
    Board::<f64x4>::new(p, rates, &seeds)
        .unwrap()
        .run(n_settle, points, opts, progress)
        .unwrap()
}

/// Every file a probe writes, by name, with its bytes.
fn files(p: &Probe) -> Vec<(String, Vec<u8>)> {
    let dir = tempfile::tempdir().unwrap();
    let mut out: Vec<(String, Vec<u8>)> = p
        .write(dir.path(), "dump")
        .unwrap()
        .iter()
        .map(|f| {
            let name = f.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(f).unwrap())
        })
        .collect();
    out.sort();
    out
}

#[test]
fn the_probe_is_handed_on_once_its_windows_end_with_a_whole_runs_recording() {
    let n_settle = 12;
    let points = [point(25.0, 300), point(100.0, 3000)];
    let rad: Vec<f64> = points.iter().map(|p| p.rate_rad_s).collect();
    let nodes: Vec<String> = DUMP_NODES.map(String::from).to_vec();
    // From 10 ms: 2 ms at the full rate and 50 ms decimated, then 30.1 ms and 5 ms (either
    // window ends last); both end before input sample 14 400, long before the run's 301 200.
    let windows = [(0.002, 0.05), (0.0301, 0.005)];
    let shapes = [
        Shape::Coriolis,
        Shape::RateTable { freq_hz: 2.0 },
        Shape::Rotating,
    ];
    for (shape, (full_s, dec_s)) in shapes.into_iter().flat_map(|s| windows.map(|w| (s, w))) {
        let p = noisy(m2tfg(shape), 5);
        let (fs, m) = (p.fs_hz(), p.decimation);
        let probe = || Probe::new(&nodes, fs, m, 0.01, full_s, 1).with_decimated_duration(dec_s);
        let mut whole = probe();
        let plain = run(
            &p,
            &rad,
            n_settle,
            &points,
            RunOptions {
                probe: Some(&mut whole),
                ..Default::default()
            },
            &|_| {},
        );

        let done = AtomicU64::new(0);
        let handed = Mutex::new(Vec::new());
        let hand_on = |pr: &Probe| {
            let at = done.load(Ordering::SeqCst);
            handed.lock().unwrap().push((at, files(pr)));
        };
        let mut early = probe();
        let out = run(
            &p,
            &rad,
            n_settle,
            &points,
            RunOptions {
                probe: Some(&mut early),
                on_probe_recorded: Some(&hand_on),
                ..Default::default()
            },
            &|n| done.store(n, Ordering::SeqCst),
        );
        let handed = handed.into_inner().unwrap();
        assert_eq!(handed.len(), 1, "{shape:?}: handed on once");
        let (at, got) = &handed[0];
        let end = (n_settle + 3000 + 1) * m as u64;
        assert!(*at < end / 10, "{shape:?}: handed on at {at} of {end}");
        assert_eq!(*got, files(&whole), "{shape:?}");
        assert_eq!(files(&early), files(&whole), "{shape:?}");
        assert_eq!(out.lanes, plain.lanes, "{shape:?}");
    }
}

#[test]
fn a_finite_check_is_never_handed_on() {
    let points = [point(25.0, 30)];
    let p = m2tfg(Shape::Rotating);
    let calls = AtomicU64::new(0);
    let hand_on = |_: &Probe| {
        calls.fetch_add(1, Ordering::SeqCst);
    };
    let mut check = Probe::finite_check(1);
    run(
        &p,
        &[points[0].rate_rad_s],
        12,
        &points,
        RunOptions {
            probe: Some(&mut check),
            on_probe_recorded: Some(&hand_on),
            ..Default::default()
        },
        &|_| {},
    );
    assert_eq!(calls.load(Ordering::SeqCst), 0);
    assert!(check.fault().is_none());
}

/// Decimated output k is formed at input sample kM + M - 1, so at (kM + M - 1) / fs: a window
/// records from the first output formed at or after its start (it took up to one more, 0.9 s
/// late at fs = 300 Hz, M = 200), and a window shorter than an output period at the run's end
/// holds the output formed there (it wrote an empty recording).
#[test]
fn the_decimated_window_starts_at_the_first_output_formed_in_it() {
    let n_settle = 12;
    let points = [point(100.0, 30)];
    let p = m2tfg(Shape::Rotating);
    let (fs, m) = (p.fs_hz(), p.decimation);
    let fs_out = fs / m as f64;
    let formed = |k: u64| (k * m as u64 + m as u64 - 1) as f64 / fs;
    // The run's outputs are 0 ..= 42; the last is formed at 4299 / fs = 17.9125 ms.
    let last = formed(n_settle + 30);
    // Starts between outputs, on one (output 23), and just before the last.
    for start in [
        0.0,
        0.0003,
        0.0101,
        formed(23),
        0.01538,
        last - 4e-5,
        last - 1e-6,
    ] {
        let mut probe = Probe::new(&["lowpass".to_string()], fs, m, start, 1.0 / fs, 1);
        run(
            &p,
            &[points[0].rate_rad_s],
            n_settle,
            &points,
            RunOptions {
                probe: Some(&mut probe),
                ..Default::default()
            },
            &|_| {},
        );
        let dir = tempfile::tempdir().unwrap();
        probe.write(dir.path(), "dump").unwrap();
        let d = gyroemu_io::read_dump(&dir.path().join("dump_decimated.sigmf-meta"))
            .unwrap_or_else(|e| panic!("start {start}: {e}"));
        assert_eq!(d.frames(), 1, "start {start}");
        let t = d.time_s(0);
        assert!(
            (t - formed(d.global_index)).abs() < 1e-15,
            "start {start}: {t}"
        );
        assert!(
            t >= start - 1e-12 && t < start + 1.0 / fs_out,
            "start {start}: the first output is formed at {t}"
        );
    }
}
