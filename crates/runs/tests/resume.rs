//! The run lifecycle as a library: a run cancelled after its first saved lane group keeps
//! exactly the saved points, marks its manifest interrupted and writes no results; the rerun
//! computes only the missing points and its outputs equal an uninterrupted run's byte for
//! byte; a third run reuses everything. A cancel raised before the start saves nothing.

mod common;

use common::*;
use gyroemu_config::Config;
use gyroemu_experiment::Quiet;
use gyroemu_runs::{prepare_out, run, RunError, RunOutcome, RunRequest};
use serde_json::Value;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Runs `cfg` into `out` on one worker thread (lane groups in turn), raising the cancel flag
/// once `stop_after` points are saved.
fn run_into(cfg: &Config, out: &Path, stop_after: Option<usize>) -> Result<RunOutcome, RunError> {
    prepare_out(out).unwrap();
    let cancel = Arc::new(AtomicBool::new(stop_after == Some(0)));
    let flag = cancel.clone();
    let on_saved = move |k: usize| {
        if stop_after.is_some_and(|s| k >= s) {
            flag.store(true, Ordering::SeqCst);
        }
    };
    let req = RunRequest {
        config: cfg,
        out,
        shard: None,
        force: false,
        cancel,
        on_saved: Some(&on_saved),
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(|| run(&req, &Quiet))
}

fn indices(v: &Value) -> Vec<u64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect()
}

fn point_files(out: &Path) -> Vec<String> {
    files_in(out, "points")
}

#[test]
fn interrupted_run_resumes_to_byte_identical_outputs() {
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("ref");
    let RunOutcome::Complete(files) = run_into(&cfg, &reference, None).unwrap() else {
        panic!("a whole run completes");
    };
    assert_eq!(
        files.len(),
        4,
        "results.csv, summary.json, plot.png, manifest.json"
    );

    let out = dir.path().join("out");
    let e = run_into(&cfg, &out, Some(1)).unwrap_err();
    assert!(matches!(&e, RunError::Interrupted(m) if m.contains("rerun the same command")));
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "interrupted");
    // One lane group finished before the flag stopped the rest: four points, or eight
    // where the CPU runs groups of eight.
    let (done, missing) = (indices(&m["points_done"]), indices(&m["points_missing"]));
    let k = done.len();
    assert!(k == 4 || k == 8, "one lane group saved, not {done:?}");
    assert_eq!(done, (0..k as u64).collect::<Vec<_>>());
    assert_eq!(missing, (k as u64..10).collect::<Vec<_>>());
    let saved: Vec<String> = (0..k).map(|i| format!("point-{i}.json")).collect();
    assert_eq!(point_files(&out), saved);
    for f in gyroemu_report::RUN_FILES {
        assert!(!out.join(f).exists(), "{f} written by an interrupted run");
    }

    // The rerun computes the missing points only; the outputs equal the reference's.
    let saved_before = std::fs::read(out.join("points/point-2.json")).unwrap();
    run_into(&cfg, &out, None).unwrap();
    assert_eq!(
        std::fs::read(out.join("points/point-2.json")).unwrap(),
        saved_before
    );
    for f in gyroemu_report::RUN_FILES {
        let (a, b) = (reference.join(f), out.join(f));
        assert_eq!(
            std::fs::read(&a).unwrap(),
            std::fs::read(&b).unwrap(),
            "{f}"
        );
    }
    assert_eq!(json(&out.join("manifest.json"))["status"], "complete");
}

#[test]
fn a_cancel_before_the_start_saves_nothing_and_says_so() {
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let e = run_into(&cfg, &out, Some(0)).unwrap_err();
    assert!(matches!(e, RunError::Interrupted(_)), "{e}");
    assert!(point_files(&out).is_empty());
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "interrupted");
    assert_eq!(indices(&m["points_missing"]).len(), 10);
}

/// Ctrl-C during a `[pll]`'s carrier lock stops the lock itself (it can run as long as the
/// user's pll.lock_s): the run ends interrupted before any point, having said nothing of a
/// lock. Were the lock to go on, it would end (0.01 s of emulation here) and report its
/// carrier, or fail to lock, before the sweep saw the flag.
#[test]
fn a_cancel_during_the_carrier_lock_stops_the_lock() {
    let cfg = pll_config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    prepare_out(&out).unwrap();
    let seen = Record::default();
    let req = RunRequest {
        config: &cfg,
        out: &out,
        shard: None,
        force: false,
        cancel: Arc::new(AtomicBool::new(true)),
        on_saved: None,
    };
    let e = run(&req, &seen).unwrap_err();
    assert!(matches!(e, RunError::Interrupted(_)), "{e}");
    let notes = seen.0.lock().unwrap();
    assert!(
        notes.iter().any(|n| n.contains("after a carrier lock of")),
        "{notes:?}"
    );
    assert!(!notes.iter().any(|n| n.contains("pll:")), "{notes:?}");
    assert!(point_files(&out).is_empty());
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "interrupted");
    assert_eq!(indices(&m["points_missing"]).len(), 10);
    drop(notes);
    // Lowered, the same run locks, says where, and saves every point.
    let req = RunRequest {
        cancel: Arc::new(AtomicBool::new(false)),
        ..req
    };
    run(&req, &seen).unwrap();
    let notes = seen.0.lock().unwrap();
    assert!(
        notes
            .iter()
            .any(|n| n.starts_with("pll: locked the carrier")),
        "{notes:?}"
    );
    assert_eq!(point_files(&out).len(), 10);
}
