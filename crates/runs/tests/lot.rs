//! A production lot's lifecycle as a library: shards merged equal one machine byte for byte;
//! a lot cancelled after its second saved device keeps exactly those and resumes to the
//! uninterrupted lot's bytes; device `i` is the same in a lot of any size (a larger lot in the
//! same folder runs only the new devices, and equals a fresh one); a new spec reuses every
//! device; a folder holding a sweep refuses a lot and the reverse, naming both kinds, unless
//! `--force`; merge refuses shards run with another spec.

mod common;

use common::*;
use gyroemu_config::presets::preset;
use gyroemu_config::Config;
use gyroemu_experiment::Quiet;
use gyroemu_report::LOT_FILES;
use gyroemu_runs::shard::parse_shard;
use gyroemu_runs::{
    merge, prepare_out, run, run_lot, LotOutcome, RunError, RunOutcome, RunRequest,
};
use serde_json::Value;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// The lot preset made small (Q = 200, three rates, 0.2 s averages), noise on.
fn lot() -> Config {
    let mut c = preset("m2tfg-montecarlo").unwrap();
    c.device.q = 200.0;
    c.experiment.rates_dps = vec![900.0, 1800.0, 2700.0];
    c.experiment.average_s = 0.2;
    c.experiment.settle_s = Some(0.1);
    c.validate().unwrap();
    c
}

struct Ran {
    outcome: Result<LotOutcome, RunError>,
    computed: usize,
    notes: String,
}

/// Runs `n` devices of `cfg` into `out` (shard `shard` if given) on `threads` worker
/// threads, raising the cancel flag once `stop_after` devices are saved.
fn run_into(
    cfg: &Config,
    out: &Path,
    n: usize,
    shard: Option<&str>,
    force: bool,
    stop_after: Option<usize>,
) -> Ran {
    prepare_out(out).unwrap();
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = cancel.clone();
    let computed = AtomicUsize::new(0);
    let on_saved = |k: usize| {
        computed.store(k, Ordering::SeqCst);
        if stop_after.is_some_and(|s| k >= s) {
            flag.store(true, Ordering::SeqCst);
        }
    };
    let req = RunRequest {
        config: cfg,
        out,
        shard: shard.map(|s| parse_shard(s).unwrap()),
        force,
        cancel,
        on_saved: Some(&on_saved),
    };
    let rec = Record::default();
    let threads = if stop_after.is_some() { 1 } else { 2 };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let outcome = pool.install(|| run_lot(&req, n, &rec));
    Ran {
        outcome,
        computed: computed.load(Ordering::SeqCst),
        notes: rec.0.into_inner().unwrap().join("\n"),
    }
}

fn assert_same_files(a: &Path, b: &Path) {
    for f in LOT_FILES {
        let (x, y) = (std::fs::read(a.join(f)), std::fs::read(b.join(f)));
        assert!(x.is_ok() && y.is_ok(), "{f} missing in {a:?} or {b:?}");
        assert!(x.unwrap() == y.unwrap(), "{f} differs: {a:?} vs {b:?}");
    }
}

fn device_files(out: &Path) -> Vec<String> {
    files_in(out, "devices")
}

#[test]
fn shards_merged_equal_one_machine_byte_for_byte() {
    let cfg = lot();
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one");
    let r = run_into(&cfg, &one, 7, None, false, None);
    let Ok(LotOutcome::Complete {
        files,
        summary: whole,
    }) = r.outcome
    else {
        panic!("a whole lot completes: {:?}", r.outcome);
    };
    assert_eq!(files.len(), 5, "the four lot files and the manifest");
    assert_eq!(whole.devices, 7);
    assert_eq!(r.computed, 7);
    let m = json(&one.join("manifest.json"));
    assert_eq!(
        (m["kind"].as_str(), m["status"].as_str()),
        (Some("montecarlo"), Some("complete"))
    );

    let split = dir.path().join("split");
    for s in ["2/3", "0/3"] {
        let r = run_into(&cfg, &split, 7, Some(s), false, None);
        assert!(
            matches!(r.outcome, Ok(LotOutcome::ShardComplete { .. })),
            "{s}"
        );
    }
    let e = merge(&split, &Quiet).unwrap_err();
    assert!(e.to_string().contains("shard 1/3"), "{e}");
    run_into(&cfg, &split, 7, Some("1/3"), false, None)
        .outcome
        .unwrap();
    assert_eq!(
        json(&split.join("shard-1-of-3.json"))["points"],
        serde_json::json!([1, 4])
    );
    let merged = merge(&split, &Quiet).unwrap();
    assert_eq!(merged.files.len(), 5);
    // The merge's figures are the one machine's.
    assert_eq!(merged.lot, Some(whole));
    assert_same_files(&one, &split);
    assert_eq!(json(&split.join("manifest.json"))["kind"], "montecarlo");
}

#[test]
fn an_interrupted_lot_resumes_to_byte_identical_files() {
    let cfg = lot();
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("ref");
    run_into(&cfg, &reference, 5, None, false, None)
        .outcome
        .unwrap();
    let out = dir.path().join("out");
    let r = run_into(&cfg, &out, 5, None, false, Some(2));
    assert!(
        matches!(&r.outcome, Err(RunError::Interrupted(m)) if m.contains("rerun the same command")),
        "{:?}",
        r.outcome
    );
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "interrupted");
    assert_eq!(m["points_done"], serde_json::json!([0, 1]));
    assert_eq!(m["points_missing"], serde_json::json!([2, 3, 4]));
    assert_eq!(device_files(&out), ["device-0.json", "device-1.json"]);
    for f in LOT_FILES {
        assert!(!out.join(f).exists(), "{f} written by an interrupted lot");
    }
    let saved = std::fs::read(out.join("devices/device-1.json")).unwrap();
    let r = run_into(&cfg, &out, 5, None, false, None);
    assert!(r.outcome.is_ok() && r.computed == 3, "{}", r.notes);
    assert!(
        r.notes.contains("resuming: 2 already computed"),
        "{}",
        r.notes
    );
    assert_eq!(
        std::fs::read(out.join("devices/device-1.json")).unwrap(),
        saved
    );
    assert_same_files(&reference, &out);
    // Once more: everything reused.
    let r = run_into(&cfg, &out, 5, None, false, None);
    assert!(r.outcome.is_ok() && r.computed == 0);
    assert!(r.notes.contains("all already computed"), "{}", r.notes);
}

#[test]
fn a_device_is_the_same_in_a_lot_of_any_size_and_a_new_spec_reuses_every_device() {
    let cfg = lot();
    let dir = tempfile::tempdir().unwrap();
    let small = dir.path().join("small");
    run_into(&cfg, &small, 3, None, false, None)
        .outcome
        .unwrap();
    let rows = |p: &Path| -> Vec<String> {
        std::fs::read_to_string(p.join("devices.csv"))
            .unwrap()
            .lines()
            .map(String::from)
            .collect()
    };
    let small_rows = rows(&small);
    // The same folder grown to 5 devices: 2 run, and it equals a fresh lot of 5.
    let r = run_into(&cfg, &small, 5, None, false, None);
    assert!(r.outcome.is_ok() && r.computed == 2, "{}", r.notes);
    let fresh = dir.path().join("fresh");
    run_into(&cfg, &fresh, 5, None, false, None)
        .outcome
        .unwrap();
    assert_same_files(&fresh, &small);
    assert_eq!(rows(&fresh)[..4], small_rows[..]);
    // Shrunk back to 3: nothing runs, the files equal the first lot's (devices 3, 4 stay).
    let r = run_into(&cfg, &small, 3, None, false, None);
    assert!(r.outcome.is_ok() && r.computed == 0);
    assert_eq!(rows(&small), small_rows);
    assert_eq!(device_files(&small).len(), 5);

    // A spec nothing passes: every device reused, every row now fails, the yield is 0.
    let mut strict = cfg.clone();
    strict.montecarlo.as_mut().unwrap().spec_abs_relative_error = 1e-12;
    let r = run_into(&strict, &small, 3, None, false, None);
    assert!(r.outcome.is_ok() && r.computed == 0, "{}", r.notes);
    let strict_rows = rows(&small);
    for (a, b) in strict_rows.iter().zip(&small_rows).skip(1) {
        assert!(a.ends_with("false,"), "{a}");
        assert_eq!(a.rsplitn(3, ',').last(), b.rsplitn(3, ',').last());
    }
    let y = &json(&small.join("montecarlo.json"))["yield"];
    assert_eq!(
        (y["passed"].as_u64(), y["devices"].as_u64()),
        (Some(0), Some(3))
    );
}

#[test]
fn a_folder_of_another_kind_is_refused_naming_both_unless_forced() {
    let lot_cfg = lot();
    let mut sweep = lot();
    sweep.montecarlo = None;
    sweep.noise = None;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    let run_sweep = |force: bool| {
        let req = RunRequest {
            config: &sweep,
            out,
            shard: None,
            force,
            cancel: Arc::new(AtomicBool::new(false)),
            on_saved: None,
        };
        run(&req, &Quiet)
    };
    assert!(matches!(run_sweep(false), Ok(RunOutcome::Complete(_))));
    let r = run_into(&lot_cfg, out, 2, None, false, None);
    let e = r.outcome.unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, RunError::BadInput(_)), "{m}");
    for needle in [
        "a sweep of `gyroemu run`",
        "not a lot of `gyroemu montecarlo`",
        "--force",
    ] {
        assert!(m.contains(needle), "`{needle}` missing from: {m}");
    }
    let r = run_into(&lot_cfg, out, 2, None, true, None);
    assert!(r.outcome.is_ok() && r.computed == 2, "{}", r.notes);
    assert!(!out.join("points").exists() && !out.join("results.csv").exists());
    // And the reverse.
    let m = run_sweep(false).unwrap_err().to_string();
    assert!(
        m.contains("holds a lot of `gyroemu montecarlo`") && m.contains("not a sweep of"),
        "{m}"
    );
    assert!(run_sweep(true).is_ok());
    assert!(!out.join("devices").exists() && !out.join("montecarlo.json").exists());
}

#[test]
fn merge_refuses_shards_run_with_another_spec_or_lot_size() {
    let cfg = lot();
    let mut other = cfg.clone();
    other.montecarlo.as_mut().unwrap().spec_abs_relative_error = 0.05;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("spec");
    run_into(&cfg, &d, 4, Some("0/2"), false, None)
        .outcome
        .unwrap();
    run_into(&other, &d, 4, Some("1/2"), false, None)
        .outcome
        .unwrap();
    let m = merge(&d, &Quiet).unwrap_err().to_string();
    assert!(
        m.contains("montecarlo.spec_abs_relative_error: 0.02 -> 0.05"),
        "{m}"
    );
    let d = dir.path().join("size");
    run_into(&cfg, &d, 4, Some("0/2"), false, None)
        .outcome
        .unwrap();
    run_into(&cfg, &d, 6, Some("1/2"), false, None)
        .outcome
        .unwrap();
    let m = merge(&d, &Quiet).unwrap_err().to_string();
    assert!(m.contains("same --devices"), "{m}");
}

#[test]
fn device_files_of_another_version_are_computed_again_with_one_warning() {
    let cfg = lot();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run_into(&cfg, &out, 3, None, false, None).outcome.unwrap();
    let csv = std::fs::read(out.join("devices.csv")).unwrap();
    // Two files as an older version would have written them: a column fewer, no checksum.
    for i in [0, 2] {
        let p = out.join(format!("devices/device-{i}.json"));
        let mut v: Value = json(&p);
        v["values"].as_object_mut().unwrap().remove("q");
        v.as_object_mut().unwrap().remove("sha256");
        std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
    }
    let r = run_into(&cfg, &out, 3, None, false, None);
    assert!(r.outcome.is_ok() && r.computed == 2, "{}", r.notes);
    assert_eq!(
        r.notes.matches("another gyroemu version").count(),
        1,
        "{}",
        r.notes
    );
    assert!(r.notes.contains("and 1 more device files"), "{}", r.notes);
    assert_eq!(std::fs::read(out.join("devices.csv")).unwrap(), csv);
}

#[test]
fn untrusted_devices_leave_the_manifest_failed_in_a_lot_and_in_its_merge() {
    // A 2-bit ADC over 0.1 V reads every device's signal as zeros: each device's phases are
    // refused, the lot and the merge of its shards write their files, then fail, and their
    // manifests must say so.
    let mut cfg = lot();
    cfg.board.adc_bits = Some(2);
    cfg.board.adc_full_scale_v = 0.1;
    cfg.validate().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one");
    let r = run_into(&cfg, &one, 2, None, false, None);
    let e = r.outcome.unwrap_err();
    assert!(e.to_string().contains("cannot be trusted"), "{e}");
    let RunError::Refused { files, lot, .. } = &e else {
        panic!("{e:?}")
    };
    assert!(files.contains(&one.join("devices.csv")) && files.contains(&one.join("manifest.json")));
    // The lot's figures come with the refusal (the command prints them as a completed lot
    // does; it had printed nothing on stdout): the two devices, as montecarlo.json holds.
    let json: Value = json(&one.join("montecarlo.json"));
    let lot = lot.as_ref().expect("the lot's summary");
    assert_eq!(lot.devices, 2);
    assert_eq!(json["devices"].as_u64(), Some(2));
    assert_failed(&one, &["devices_unreliable", "--force"]);

    let split = dir.path().join("split");
    for s in ["0/2", "1/2"] {
        let r = run_into(&cfg, &split, 2, Some(s), false, None);
        assert!(
            matches!(r.outcome, Ok(LotOutcome::ShardComplete { .. })),
            "{s}"
        );
    }
    let e = merge(&split, &Quiet).unwrap_err();
    assert!(e.to_string().contains("cannot be trusted"), "{e}");
    assert!(
        matches!(&e, RunError::Refused { lot: Some(_), .. }),
        "{e:?}"
    );
    assert!(split.join("devices.csv").is_file());
    assert_failed(&split, &["every shard with --force"]);
}

#[test]
fn merge_refuses_shards_a_grown_lot_was_written_over() {
    // Two shards of 4 devices merged, then the lot grown to 6 on the merged folder without
    // --shard: merging again rewrote the 4-device lot over it with exit 0.
    let cfg = lot();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("grown");
    for s in ["0/2", "1/2"] {
        run_into(&cfg, &d, 4, Some(s), false, None).outcome.unwrap();
    }
    merge(&d, &Quiet).unwrap();
    run_into(&cfg, &d, 6, None, false, None).outcome.unwrap();
    let csv = std::fs::read(d.join("devices.csv")).unwrap();
    let m = merge(&d, &Quiet).unwrap_err().to_string();
    assert!(m.contains("6 devices") && m.contains("4 devices"), "{m}");
    assert_eq!(std::fs::read(d.join("devices.csv")).unwrap(), csv);
}
