//! An abrupt exit (a second Ctrl-C) during a run: `abort_now` leaves the manifest
//! `interrupted` with the points saved so far and removes the folder lock, and the run's own
//! last write cannot overwrite it afterwards. Its own test binary: an abort is process-wide.

use gyroemu_config::parse_config;
use gyroemu_experiment::Quiet;
use gyroemu_runs::{abort_now, lock_out, prepare_out, run, LockScope, RunError, RunRequest};
use serde_json::Value;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// Nine listed rates plus the implicit zero: more than one lane group of four or of eight.
const CONFIG: &str = r#"
[device]
f0_hz = 15000.0
q = 1000.0
angular_gain = 1.0
[drive]
f1 = 1.0
[board]
fs_hz = 240000.0
lpf_cutoff_hz = 200.0
decimation = 100
[experiment]
kind = "coriolis"
rates_dps = [25.0, 50.0, 75.0, 100.0, 125.0, 150.0, 175.0, 200.0, 225.0]
average_s = 0.1
settle_s = 0.05
"#;

fn json(p: &std::path::Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn an_abort_leaves_the_saved_points_interrupted_and_no_lock() {
    let cfg = parse_config(CONFIG).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    prepare_out(out).unwrap();
    let lock = lock_out(out, "gyroemu run c.toml", LockScope::Folder, &Quiet).unwrap();
    let cancel = Arc::new(AtomicBool::new(false));
    let seen = Mutex::new(None);
    let on_saved = |k: usize| {
        // What a second Ctrl-C does before the process exits.
        let marked = abort_now();
        *seen.lock().unwrap() = Some((k, marked, json(&out.join("manifest.json"))));
        cancel.store(true, Ordering::SeqCst);
    };
    let req = RunRequest {
        config: &cfg,
        out,
        shard: None,
        force: false,
        cancel: cancel.clone(),
        on_saved: Some(&on_saved),
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let e = pool.install(|| run(&req, &Quiet)).unwrap_err();
    assert!(matches!(e, RunError::Interrupted(_)), "{e}");
    let (k, marked, m) = seen.into_inner().unwrap().unwrap();
    // One lane group saved: four points, or eight where the CPU runs groups of eight.
    assert!(k == 4 || k == 8, "one lane group saved, not {k} points");
    assert_eq!(marked, [out.join("manifest.json")]);
    assert_eq!(m["status"], "interrupted");
    let (done, missing): (Vec<usize>, Vec<usize>) = ((0..k).collect(), (k..10).collect());
    assert_eq!(m["points_done"], serde_json::json!(done));
    assert_eq!(m["points_missing"], serde_json::json!(missing));
    assert!(m["next"]
        .as_str()
        .unwrap()
        .contains("rerun the same command"));
    assert!(
        !out.join("gyroemu.lock").exists(),
        "the abort left the lock"
    );
    // The run's own last write came after the abort: it did not happen.
    assert_eq!(json(&out.join("manifest.json")), m);
    drop(lock);
}
