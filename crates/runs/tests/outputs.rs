//! What a run leaves in its output folder: a failed write of the results, or refused phases
//! (also in a merge of shards), leave the manifest `failed` with the cause; `[dump]` does not
//! change the config's identity (points reused, only the dumped point computed again to
//! record it, and an earlier dump deleted when the `[dump]` changes); a folder of another
//! config is refused naming the keys that differ, and `--force` deletes that config's dumps
//! with its points.

mod common;

use common::*;
use gyroemu_config::{parse_config, Config};
use gyroemu_runs::{dump_files, prepare_out, run, RunError, RunOutcome, RunRequest};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// Three listed rates plus the implicit zero: one lane group.
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
rates_dps = [25.0, 50.0, 75.0]
average_s = 0.1
settle_s = 0.05
"#;

const DUMP: &str = "[dump]\nrate_dps = 50.0\nnodes = [\"tia\", \"lowpass\"]\n";

fn config(text: &str) -> Config {
    let c = parse_config(text).unwrap();
    c.validate().unwrap();
    c
}

/// Runs `cfg` into `out`; returns the outcome, the points computed and the notes.
fn run_into(
    cfg: &Config,
    out: &Path,
    force: bool,
) -> (Result<RunOutcome, RunError>, usize, String) {
    prepare_out(out).unwrap();
    let computed = AtomicUsize::new(0);
    let on_saved = |k: usize| computed.store(k, Ordering::SeqCst);
    let req = RunRequest {
        config: cfg,
        out,
        shard: None,
        force,
        cancel: Arc::new(AtomicBool::new(false)),
        on_saved: Some(&on_saved),
    };
    let rec = Record::default();
    let r = run(&req, &rec);
    let notes = rec.0.into_inner().unwrap().join("\n");
    (r, computed.load(Ordering::SeqCst), notes)
}

#[test]
fn a_failed_write_of_the_results_leaves_the_manifest_failed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    // A folder where results.csv goes: its atomic rename fails (also as root).
    std::fs::create_dir_all(out.join("results.csv/x")).unwrap();
    let (r, computed, _) = run_into(&config(CONFIG), out, false);
    let e = r.unwrap_err();
    assert!(matches!(e, RunError::Report(_)), "{e}");
    assert_eq!(computed, 4);
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "failed", "{m}");
    assert_eq!(m["points_done"], serde_json::json!([0, 1, 2, 3]));
    let next = m["next"].as_str().unwrap();
    assert!(
        next.contains("results.csv") && next.contains("rerun"),
        "{next}"
    );
    // Fixed, the rerun reuses every point and completes.
    std::fs::remove_dir_all(out.join("results.csv")).unwrap();
    let (r, computed, _) = run_into(&config(CONFIG), out, false);
    assert!(matches!(r, Ok(RunOutcome::Complete(_))));
    assert_eq!(computed, 0);
    assert_eq!(json(&out.join("manifest.json"))["status"], "complete");
}

#[test]
fn refused_phases_leave_the_manifest_failed_with_the_files_written() {
    // A 2-bit ADC over 0.1 V reads the 20 mV signal as zeros: every phase is refused (NaN),
    // the run exits non-zero, and its manifest must not say `complete`.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    let text = CONFIG.replace(
        "[board]\n",
        "[board]\nadc_bits = 2\nadc_full_scale_v = 0.1\n",
    );
    let (r, computed, _) = run_into(&config(&text), out, false);
    let e = r.unwrap_err();
    assert!(e.to_string().contains("refused"), "{e}");
    // The error lists what was written, for the command to show as a completed run does.
    let RunError::Refused { files, .. } = &e else {
        panic!("{e:?}")
    };
    for f in ["results.csv", "summary.json", "manifest.json"] {
        assert!(files.contains(&out.join(f)), "{f}: {files:?}");
    }
    assert_eq!(computed, 4);
    assert!(out.join("results.csv").is_file() && out.join("summary.json").is_file());
    // Where they are listed, and how to rerun: the same config refuses them again, a changed
    // one meets this folder's results.
    let m = assert_failed(out, &["summary.json", "change it", "--force"]);
    assert_eq!(m["points_done"], serde_json::json!([0, 1, 2, 3]));
    let (r, _, _) = run_into(&config(CONFIG), out, true);
    assert!(matches!(r, Ok(RunOutcome::Complete(_))), "{r:?}");
    assert_eq!(json(&out.join("manifest.json"))["status"], "complete");

    // The same points run as two shards and merged: the merge fails alike.
    let split = dir.path().join("split");
    for s in ["0/2", "1/2"] {
        prepare_out(&split).unwrap();
        let req = RunRequest {
            config: &config(&text),
            out: &split,
            shard: Some(gyroemu_runs::shard::parse_shard(s).unwrap()),
            force: false,
            cancel: Arc::new(AtomicBool::new(false)),
            on_saved: None,
        };
        let r = run(&req, &Record::default());
        assert!(matches!(r, Ok(RunOutcome::ShardComplete { .. })), "{s}");
    }
    let e = gyroemu_runs::merge(&split, &gyroemu_experiment::Quiet).unwrap_err();
    assert!(e.to_string().contains("refused"), "{e}");
    let RunError::Refused { files, .. } = &e else {
        panic!("{e:?}")
    };
    assert!(
        files.contains(&split.join("results.csv")) && files.contains(&split.join("manifest.json"))
    );
    assert!(split.join("results.csv").is_file());
    assert_failed(&split, &["every shard with --force"]);
}

#[test]
fn a_dump_does_not_change_the_points_identity() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let plain = config(CONFIG);
    let dumped = config(&format!("{CONFIG}{DUMP}"));
    let (r, computed, _) = run_into(&plain, &out, false);
    assert!(r.is_ok() && computed == 4);
    let results = std::fs::read(out.join("results.csv")).unwrap();
    assert!(dump_files(&out).is_empty());

    // Adding a dump: every point reused but the dumped one (50 deg/s, index 1).
    let (r, computed, notes) = run_into(&dumped, &out, false);
    assert!(r.is_ok(), "{notes}");
    assert_eq!(computed, 1, "{notes}");
    assert!(notes.contains("recomputing point 1 (50 deg/s)"), "{notes}");
    let names = |out: &Path| -> Vec<String> {
        dump_files(out)
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect()
    };
    assert_eq!(names(&out).len(), 8, "{:?}", names(&out));
    assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), results);
    // A fresh run with the dump gives the same results: the dump changes no number.
    let fresh = dir.path().join("fresh");
    assert!(run_into(&dumped, &fresh, false).0.is_ok());
    assert_eq!(std::fs::read(fresh.join("results.csv")).unwrap(), results);

    // The same dump again: nothing recomputed, the dump kept.
    let (r, computed, _) = run_into(&dumped, &out, false);
    assert!(r.is_ok() && computed == 0);
    assert_eq!(names(&out).len(), 8);
    // A file of the dump deleted by hand: the dumped point alone computed again, the dump
    // whole and the same bytes (it had reused every point and kept the dump with a part lost).
    let kept: Vec<Vec<u8>> = dump_files(&out)
        .iter()
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    for lost in ["dump_decimated.sigmf-meta", "dump_fullrate.csv"] {
        std::fs::remove_file(out.join(lost)).unwrap();
        let (r, computed, notes) = run_into(&dumped, &out, false);
        assert!(r.is_ok(), "{notes}");
        assert_eq!(computed, 1, "{notes}");
        assert!(
            notes.contains(&format!("lacks {lost}: recomputing point 1 (50 deg/s)")),
            "{notes}"
        );
        let now: Vec<Vec<u8>> = dump_files(&out)
            .iter()
            .map(|p| std::fs::read(p).unwrap())
            .collect();
        assert!(now == kept, "{lost}: {:?}", names(&out));
        assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), results);
    }

    // The dump removed: its files deleted (and said), nothing recomputed.
    let (r, computed, notes) = run_into(&plain, &out, false);
    assert!(r.is_ok() && computed == 0);
    assert!(dump_files(&out).is_empty(), "{:?}", names(&out));
    assert!(
        notes.contains("deleted the dump") && notes.contains("dump_decimated.csv"),
        "{notes}"
    );
    assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), results);
}

#[test]
fn another_config_is_refused_naming_the_keys_and_force_deletes_its_dumps() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    let a = config(&format!("{CONFIG}{DUMP}"));
    assert!(run_into(&a, out, false).0.is_ok());
    assert_eq!(dump_files(out).len(), 8);
    let b = config(
        &CONFIG
            .replace("q = 1000.0", "q = 1200.0")
            .replace("average_s = 0.1", "average_s = 0.12"),
    );
    let e = run_into(&b, out, false).0.unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, RunError::BadInput(_)), "{m}");
    for needle in [
        "device.q: 1000.0 -> 1200.0",
        "experiment.average_s: 0.1 -> 0.12",
        "--force",
    ] {
        assert!(m.contains(needle), "`{needle}` missing from: {m}");
    }
    assert!(!m.contains("dump"), "the dump is not a difference: {m}");
    let (r, computed, _) = run_into(&b, out, true);
    assert!(r.is_ok() && computed == 4);
    assert!(
        dump_files(out).is_empty(),
        "--force left the dumps of the other config"
    );
}

/// A drive of 1e-40 puts the TIA output near 1e-46 V, below float32's range: the dump's WAV
/// copy would be zeros, so it is not written and the run says why; CSV and SigMF are.
#[test]
fn a_dump_float32_cannot_hold_has_no_wav_and_the_run_says_why() {
    let cfg = config(&format!(
        "{}{DUMP}",
        CONFIG.replace("f1 = 1.0", "f1 = 1e-40")
    ));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tiny");
    let (r, _, notes) = run_into(&cfg, &out, false);
    r.unwrap();
    let files: Vec<String> = dump_files(&out)
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert!(
        files.contains(&"dump_fullrate.sigmf-data".to_string())
            && !files.iter().any(|f| f.ends_with(".wav")),
        "{files:?}"
    );
    assert!(
        notes.contains("warning: the full-rate dump has no .wav")
            && notes.contains("warning: the decimated dump has no .wav"),
        "{notes}"
    );
}
