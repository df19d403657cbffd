//! Splits as a library: a scheduler's split that the output folder contradicts (a Slurm task
//! resubmitted alone, an array of another size) is refused before anything is computed or
//! written, naming both splits and the `--shard` to give, and the shard given that way merges
//! to the one-machine bytes; a shard count far past the items is refused; merge lists a huge
//! split's missing shards briefly; a point file with a damaged value is recomputed by its own
//! shard and blocks no other, while merge refuses it naming that shard; a folder the lock
//! cannot be created in is refused as bad input naming the folder.

mod common;

use common::*;
use gyroemu_config::presets::preset;
use gyroemu_config::{parse_config, Config};
use gyroemu_experiment::Quiet;
use gyroemu_runs::shard::parse_shard;
use gyroemu_runs::{
    lock_out, merge, prepare_out, resolve_shard, run, run_lot, LockScope, RunError, RunOutcome,
    RunRequest, Shard,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Runs `cfg` (shard `shard`) into `out`; returns the outcome and what the run reported.
fn run_shard(
    cfg: &Config,
    out: &Path,
    shard: Option<Shard>,
) -> (Result<RunOutcome, RunError>, String) {
    prepare_out(out).unwrap();
    let req = RunRequest {
        config: cfg,
        out,
        shard,
        force: false,
        cancel: Arc::new(AtomicBool::new(false)),
        on_saved: None,
    };
    let rec = Record::default();
    let r = run(&req, &rec);
    (r, rec.0.into_inner().unwrap().join("\n"))
}

/// Runs every shard of a split of `count` of `cfg` into `out`, each to completion.
fn run_shards(cfg: &Config, out: &Path, count: usize) {
    for i in 0..count {
        let shard = parse_shard(&format!("{i}/{count}")).unwrap();
        run_shard(cfg, out, Some(shard)).0.unwrap();
    }
}

/// The shard a Slurm array task gets from its variables (no `--shard`).
fn slurm(id: &str, min: &str, max: &str, count: &str) -> Shard {
    let vars: BTreeMap<&str, &str> = [
        ("SLURM_ARRAY_TASK_ID", id),
        ("SLURM_ARRAY_TASK_MIN", min),
        ("SLURM_ARRAY_TASK_MAX", max),
        ("SLURM_ARRAY_TASK_COUNT", count),
        ("SLURM_ARRAY_TASK_STEP", "1"),
    ]
    .into();
    let env = |k: &str| vars.get(k).map(|v| v.to_string());
    resolve_shard(None, None, &env).unwrap().unwrap()
}

fn refusal(r: Result<RunOutcome, RunError>) -> String {
    match r {
        Err(RunError::BadInput(m)) => m,
        other => panic!("not refused: {other:?}"),
    }
}

/// Every file of a folder with its bytes, by path inside it.
fn tree(out: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut dirs = vec![out.to_path_buf()];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else {
                files.insert(
                    p.strip_prefix(out).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    files
}

fn assert_same_results(a: &Path, b: &Path) {
    for f in gyroemu_report::RUN_FILES {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(x == y, "{f} differs");
    }
}

#[test]
fn a_resubmitted_slurm_task_is_refused_and_its_shard_given_merges() {
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    run_shard(&cfg, &whole, None).0.unwrap();
    // An array 0-3 whose task 2 did not finish.
    let out = dir.path().join("sl");
    for id in ["0", "1", "3"] {
        run_shard(&cfg, &out, Some(slurm(id, "0", "3", "4")))
            .0
            .unwrap();
    }
    let before = tree(&out);

    // `sbatch --array=2`: before, shard 0/1 of the same points, unmergeable beside the rest.
    let m = refusal(run_shard(&cfg, &out, Some(slurm("2", "2", "2", "1"))).0);
    for needle in [
        "SLURM_ARRAY_TASK_ID = 2",
        "shard 0/1",
        "split into 4",
        "not complete there: 2/4",
        "--shard 2/4",
    ] {
        assert!(m.contains(needle), "`{needle}` missing from: {m}");
    }
    // A resubmitted pair (`--array=2,3`) is a whole array of 2: it contradicts the folder.
    let m = refusal(run_shard(&cfg, &out, Some(slurm("2", "2", "3", "2"))).0);
    for needle in [
        "shard 0/2",
        "split into 4",
        "--shard 2/4",
        "delete the shard-I-of-N.json",
    ] {
        assert!(m.contains(needle), "`{needle}` missing from: {m}");
    }
    assert!(tree(&out) == before, "a refused task wrote into the folder");

    // Given as the refusal says, it runs its own shard and the split merges.
    run_shard(&cfg, &out, Some(parse_shard("2/4").unwrap()))
        .0
        .unwrap();
    merge(&out, &Quiet).unwrap();
    assert_same_results(&whole, &out);

    // A `--shard` the user wrote is obeyed, with a warning that merge needs one split.
    let (r, notes) = run_shard(&cfg, &out, Some(parse_shard("0/3").unwrap()));
    r.unwrap();
    assert!(
        notes.contains("warning: ") && notes.contains("split into 4"),
        "{notes}"
    );

    // A lone Slurm task in a folder without a split is refused too: it would run every point
    // as a split of one.
    let fresh = dir.path().join("fresh");
    let m = refusal(run_shard(&cfg, &fresh, Some(slurm("5", "5", "5", "1"))).0);
    assert!(
        m.contains("only task of its job array") && m.contains("--shard 5/N"),
        "{m}"
    );
    assert!(tree(&fresh).is_empty());
}

#[test]
fn a_lot_checks_its_split_against_the_folder_too() {
    let mut cfg = preset("m2tfg-montecarlo").unwrap();
    cfg.device.q = 200.0;
    cfg.experiment.rates_dps = vec![900.0, 1800.0, 2700.0];
    cfg.experiment.average_s = 0.2;
    cfg.experiment.settle_s = Some(0.1);
    cfg.validate().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lot");
    prepare_out(&out).unwrap();
    let lot = |shard: Shard| {
        let req = RunRequest {
            config: &cfg,
            out: &out,
            shard: Some(shard),
            force: false,
            cancel: Arc::new(AtomicBool::new(false)),
            on_saved: None,
        };
        run_lot(&req, 4, &Quiet)
    };
    lot(parse_shard("1/3").unwrap()).unwrap();
    let before = tree(&out);
    let Err(RunError::BadInput(m)) = lot(slurm("2", "2", "2", "1")) else {
        panic!("a lone task of a lot accepted");
    };
    assert!(
        m.contains("split into 3") && m.contains("--shard 2/3"),
        "{m}"
    );
    let Err(RunError::BadInput(m)) = lot(parse_shard("0/2000").unwrap()) else {
        panic!("2000 shards of 4 devices accepted");
    };
    assert!(m.contains("2000 shards of 4 devices"), "{m}");
    assert!(tree(&out) == before, "a refused lot wrote into the folder");
    // A shard with no device says so, not that its devices were computed.
    let sparse = dir.path().join("sparse");
    prepare_out(&sparse).unwrap();
    let req = RunRequest {
        config: &cfg,
        out: &sparse,
        shard: Some(parse_shard("5/8").unwrap()),
        force: false,
        cancel: Arc::new(AtomicBool::new(false)),
        on_saved: None,
    };
    let rec = Record::default();
    run_lot(&req, 4, &rec).unwrap();
    let notes = rec.0.into_inner().unwrap().join("\n");
    assert!(notes.contains("none falls to this shard"), "{notes}");
    assert!(!notes.contains("already computed"), "{notes}");
}

#[test]
fn a_shard_count_far_past_the_points_is_refused_before_anything() {
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("huge");
    for text in ["1/1000000", "0/9223372036854775807"] {
        let m = refusal(run_shard(&cfg, &out, Some(parse_shard(text).unwrap())).0);
        assert!(m.contains(text) && m.contains("of 10 points"), "{m}");
    }
    assert!(tree(&out).is_empty());
    // A uniform array larger than the sweep: its empty shards merge.
    let sparse = dir.path().join("sparse");
    for i in 0..12 {
        let (r, notes) = run_shard(
            &cfg,
            &sparse,
            Some(parse_shard(&format!("{i}/12")).unwrap()),
        );
        r.unwrap();
        // Shards 10 and 11 hold no point: they say so, not that their points were computed.
        let empty = notes.contains("none falls to this shard");
        assert_eq!(empty, i >= 10, "shard {i}: {notes}");
        assert!(!notes.contains("already computed"), "shard {i}: {notes}");
    }
    merge(&sparse, &Quiet).unwrap();
}

/// Merge's refusal of `dir`.
fn merge_refusal(dir: &Path) -> String {
    match merge(dir, &Quiet) {
        Err(RunError::BadInput(m)) => m,
        other => panic!("merge not refused: {other:?}"),
    }
}

#[test]
fn merge_lists_the_missing_shards_of_a_huge_split_briefly() {
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("two");
    run_shards(&cfg, &out, 2);
    // A manifest edited (or written by an older gyroemu) to claim a huge split: before, merge
    // built a line naming each of its missing shards (16 MB for a million; without end for
    // the largest).
    let shard1 = json(&out.join("shard-1-of-2.json"));
    std::fs::remove_file(out.join("shard-0-of-2.json")).unwrap();
    std::fs::remove_file(out.join("shard-1-of-2.json")).unwrap();
    for count in [1_000_000u64, u64::MAX] {
        let mut m = shard1.clone();
        m["shard"]["count"] = count.into();
        let name = out.join(format!("shard-1-of-{count}.json"));
        std::fs::write(&name, serde_json::to_string(&m).unwrap()).unwrap();
        let e = merge_refusal(&out);
        assert!(e.len() < 600, "{} bytes", e.len());
        let more = format!("and {} more", count - 6);
        assert!(
            e.contains(&format!("0/{count}, 2/{count}")) && e.contains(&more),
            "{e}"
        );
        std::fs::remove_file(&name).unwrap();
    }
    // An index at or past its count.
    let mut m = shard1.clone();
    m["shard"]["index"] = 5.into();
    std::fs::write(
        out.join("shard-5-of-2.json"),
        serde_json::to_string(&m).unwrap(),
    )
    .unwrap();
    let e = merge_refusal(&out);
    assert!(
        e.contains("shard-5-of-2.json") && e.contains("below its count"),
        "{e}"
    );
}

#[test]
fn a_damaged_point_file_is_recomputed_by_its_shard_and_blocks_no_other() {
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    run_shard(&cfg, &whole, None).0.unwrap();
    let out = dir.path().join("c2");
    run_shards(&cfg, &out, 2);
    let p3 = out.join("points/point-3.json");
    let mut f = json(&p3);
    f["z"][0] = "xyz".into();
    std::fs::write(&p3, serde_json::to_string_pretty(&f).unwrap()).unwrap();
    let damaged = std::fs::read(&p3).unwrap();

    // Shard 0 does not own point 3: before, it was refused over it.
    let (r, notes) = run_shard(&cfg, &out, Some(parse_shard("0/2").unwrap()));
    r.unwrap();
    // Its checksum no longer matches (before checksums, the bad hex itself was named).
    assert!(
        notes.contains("point-3.json") && notes.contains("do not match its sha256"),
        "{notes}"
    );
    assert_eq!(
        std::fs::read(&p3).unwrap(),
        damaged,
        "not shard 0's to rewrite"
    );

    let e = merge_refusal(&out);
    assert!(
        e.contains("point-3.json") && e.contains("--shard 1/2"),
        "{e}"
    );

    // Its own shard computes it again; then the split merges to the one-machine bytes.
    let (r, notes) = run_shard(&cfg, &out, Some(parse_shard("1/2").unwrap()));
    r.unwrap();
    assert!(notes.contains("point-3.json"), "{notes}");
    assert_eq!(
        std::fs::read(&p3).unwrap(),
        std::fs::read(whole.join("points/point-3.json")).unwrap()
    );
    merge(&out, &Quiet).unwrap();
    assert_same_results(&whole, &out);
}

#[test]
fn a_folder_the_lock_cannot_be_created_in_is_bad_input_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    std::fs::create_dir(&out).unwrap();
    // The lock is first written under this temporary name: a folder there makes the write
    // fail whoever runs the test (root ignores permission bits).
    let tmp = out.join(format!(".gyroemu.lock.{}.tmp", std::process::id()));
    std::fs::create_dir(&tmp).unwrap();
    match lock_out(&out, "gyroemu merge o", LockScope::Folder, &Quiet) {
        Err(RunError::BadInput(m)) => {
            assert!(
                m.contains(&format!("output folder `{}`", out.display())),
                "{m}"
            );
            assert!(m.contains("gyroemu.lock"), "{m}");
        }
        other => panic!("not bad input: {other:?}"),
    }
}

#[test]
fn merge_refuses_shards_of_different_dumps() {
    // `[dump]` changes no result, hence not the hash; but the folder holds one dump, and a
    // shard of another [dump] had replaced it while the merged manifest described the first.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("dumps");
    let with_dump = |rate: f64| {
        let text = format!(
            "{NOISY}\n[dump]\nrate_dps = {rate}\nstart_s = 0.1\nduration_s = 0.002\nnodes = [\"tia\"]\n"
        );
        let c = parse_config(&text).unwrap();
        c.validate().unwrap();
        c
    };
    let shard = |i: usize| Some(parse_shard(&format!("{i}/2")).unwrap());
    assert!(run_shard(&with_dump(25.0), &out, shard(0)).0.is_ok());
    assert!(run_shard(&with_dump(50.0), &out, shard(1)).0.is_ok());
    let why = merge_refusal(&out);
    assert!(why.contains("different [dump] sections"), "{why}");
    // One sentence, not a source line's indentation carried into it.
    assert!(!why.contains("  "), "{why}");
    // One [dump] for both: the merge goes through.
    assert!(run_shard(&with_dump(25.0), &out, shard(1)).0.is_ok());
    merge(&out, &Quiet).unwrap();
}

#[test]
fn merge_refuses_shards_a_whole_run_of_another_dump_was_written_over() {
    // Shards merged, then a whole run of the same sweep with another [dump] (which rewrites
    // the dump): merging again put the shards' [dump] back into manifest.json and
    // summary.json with exit 0, and a later run of the first [dump] then reused the wrong dump
    // files.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("over");
    let with_dump = |rate: f64| {
        let text = format!(
            "{NOISY}\n[dump]\nrate_dps = {rate}\nstart_s = 0.1\nduration_s = 0.002\nnodes = [\"tia\"]\n"
        );
        parse_config(&text).unwrap()
    };
    for i in 0..2 {
        let s = Some(parse_shard(&format!("{i}/2")).unwrap());
        assert!(run_shard(&with_dump(25.0), &out, s).0.is_ok());
    }
    merge(&out, &Quiet).unwrap();
    // Merging again, with nothing newer in the folder, is allowed (the same result).
    merge(&out, &Quiet).unwrap();
    assert!(run_shard(&with_dump(50.0), &out, None).0.is_ok());
    let why = merge_refusal(&out);
    assert!(
        why.contains("manifest.json") && why.contains("without --shard"),
        "{why}"
    );
    assert!(!why.contains("  "), "{why}");
}

/// Rewrites the `build` of the manifest at `path` as another build's.
fn as_other_build(path: &Path) {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let other = if gyroemu_runs::manifest::BUILD.starts_with("fused") {
        "unfused multiply-add"
    } else {
        "fused multiply-add"
    };
    v["build"] = other.into();
    std::fs::write(path, serde_json::to_string(&v).unwrap()).unwrap();
}

#[test]
fn results_of_another_build_are_neither_resumed_nor_merged() {
    // The portable build (no fused multiply-adds) gives other bits, 1e-13 to 2.8e-8 relative: a
    // shard of each merged with exit 0 into results that matched neither build's run.
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("split");
    run_shards(&cfg, &out, 2);
    as_other_build(&out.join("shard-1-of-2.json"));
    let why = merge_refusal(&out);
    assert!(
        why.contains("build") && why.contains("shard-1-of-2.json"),
        "{why}"
    );
    // Resuming a shard beside another build's is refused too, naming the build.
    let why = refusal(run_shard(&cfg, &out, Some(parse_shard("0/2").unwrap())).0);
    assert!(
        why.contains("multiply-add") && why.contains("--force"),
        "{why}"
    );
    // And a whole run's folder.
    let whole = dir.path().join("whole");
    run_shard(&cfg, &whole, None).0.unwrap();
    as_other_build(&whole.join("manifest.json"));
    let why = refusal(run_shard(&cfg, &whole, None).0);
    assert!(why.contains("computed by a gyroemu build"), "{why}");
}

#[test]
fn a_point_file_edited_by_one_bit_is_caught_by_its_checksum() {
    // One hex digit of a lane average changed: it decodes, so before checksums the merge used
    // it (a phase moved in its ninth digit, exit 0) and a resume kept it.
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bit");
    run_shards(&cfg, &out, 2);
    let p4 = out.join("points/point-4.json");
    let mut f = json(&p4);
    let z = f["z"][0].as_str().unwrap().to_string();
    let last = if z.ends_with('0') { '1' } else { '0' };
    f["z"][0] = format!("{}{last}", &z[..15]).into();
    std::fs::write(&p4, serde_json::to_string_pretty(&f).unwrap()).unwrap();
    let e = merge_refusal(&out);
    assert!(
        e.contains("point-4.json") && e.contains("sha256") && e.contains("--shard 0/2"),
        "{e}"
    );
    // Its shard computes it again, and the merge then goes through.
    let (r, notes) = run_shard(&cfg, &out, Some(parse_shard("0/2").unwrap()));
    r.unwrap();
    assert!(notes.contains("point-4.json"), "{notes}");
    assert_eq!(json(&p4)["z"][0].as_str().unwrap(), z);
    merge(&out, &Quiet).unwrap();
}

#[test]
fn force_on_one_shard_leaves_a_running_shards_folder_alone() {
    // Shard 0 holds its lock (a live process) while shard 1 of another config runs with
    // --force: it had deleted shard 0's files as it ran, leaving a folder of two seeds.
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("busy");
    run_shard(&cfg, &out, Some(parse_shard("0/2").unwrap()))
        .0
        .unwrap();
    let mut holder = std::process::Command::new("sleep")
        .arg("30")
        .spawn()
        .unwrap();
    let info = gyroemu_runs::LockInfo {
        pid: holder.id(),
        host: std::fs::read_to_string("/proc/sys/kernel/hostname")
            .map(|h| h.trim().to_string())
            .unwrap_or_default(),
        command: "gyroemu run a.toml --shard 0/2".into(),
        since_unix_s: 0,
        since_utc: String::new(),
        pid_ns: std::fs::read_link("/proc/self/ns/pid")
            .map(|p| p.to_string_lossy().into_owned())
            .unwrap_or_default(),
    };
    std::fs::write(
        out.join("gyroemu-shard-0-of-2.lock"),
        serde_json::to_string(&info).unwrap(),
    )
    .unwrap();
    let mut other = cfg.clone();
    other.experiment.average_s *= 2.0;
    let req = RunRequest {
        config: &other,
        out: &out,
        shard: Some(parse_shard("1/2").unwrap()),
        force: true,
        cancel: Arc::new(AtomicBool::new(false)),
        on_saved: None,
    };
    let r = run(&req, &Quiet);
    holder.kill().unwrap();
    holder.wait().unwrap();
    match r {
        Err(RunError::Locked(m)) => assert!(m.contains("--force would delete"), "{m}"),
        other => panic!("not refused: {other:?}"),
    }
    assert!(
        out.join("shard-0-of-2.json").exists(),
        "shard 0's manifest deleted"
    );
}

#[test]
fn merge_refuses_shards_whose_configs_differ_in_sections_the_hash_leaves_out() {
    // A [selfcal] section changes no result of a sweep, hence not the hash; but summary.json
    // records one config, and it had silently been shard 0's.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sections");
    let plain = parse_config(NOISY).unwrap();
    let with = parse_config(&format!("{NOISY}\n[selfcal]\nallan_record_s = 60.0\n")).unwrap();
    run_shard(&plain, &out, Some(parse_shard("0/2").unwrap()))
        .0
        .unwrap();
    run_shard(&with, &out, Some(parse_shard("1/2").unwrap()))
        .0
        .unwrap();
    let why = merge_refusal(&out);
    assert!(
        why.contains("differ in [selfcal], which the hash leaves out"),
        "{why}"
    );
    // A section the hash covers edited into a shard's config text (its hash kept): not said
    // to be one the hash leaves out, but an edit after the run.
    let p = out.join("shard-1-of-2.json");
    let kept = std::fs::read(&p).unwrap();
    let mut m = json(&p);
    let text = m["config_toml"]
        .as_str()
        .unwrap()
        .replace("q = 1000.0", "q = 1100.0");
    assert!(text.contains("q = 1100.0"));
    m["config_toml"] = text.into();
    std::fs::write(&p, serde_json::to_string(&m).unwrap()).unwrap();
    let why = merge_refusal(&out);
    assert!(
        why.contains("differ in [device], which the hash covers"),
        "{why}"
    );
    assert!(why.contains("edited after its run"), "{why}");
    std::fs::write(&p, kept).unwrap();
    // One config for both: merged.
    run_shard(&plain, &out, Some(parse_shard("1/2").unwrap()))
        .0
        .unwrap();
    merge(&out, &Quiet).unwrap();
}

#[test]
fn point_files_of_rates_the_json_parser_reads_an_ulp_off_keep_their_checksum() {
    // serde_json (without float_roundtrip) reads some decimals one ulp from their nearest
    // double: a checksum of the exact values refused such a point as edited on every rerun,
    // and its shard's merge failed however often it was rerun. Rates drawn at random over
    // 1..170 deg/s hit such a value within a few dozen.
    let rates: Vec<f64> = (0..40u64)
        .map(|i| {
            1.0 + 169.0 * ((i * 2_654_435_761) % 1_000_003) as f64 / 1_000_003.0 + 1e-9 * i as f64
        })
        .collect();
    let misread = rates.iter().any(|&r| {
        let text = serde_json::to_string(&r).unwrap();
        serde_json::from_str::<f64>(&text).unwrap().to_bits() != r.to_bits()
    });
    assert!(
        misread,
        "no rate of the list is misread: the test would not test"
    );
    let mut cfg = config();
    cfg.experiment.rates_dps = rates;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ulp");
    run_shard(&cfg, &out, None).0.unwrap();
    let (r, notes) = run_shard(&cfg, &out, None);
    r.unwrap();
    assert!(!notes.contains("do not match"), "{notes}");
    assert!(notes.contains("all already computed"), "{notes}");
}

#[test]
fn a_hash_edited_into_non_ascii_is_refused_not_a_panic() {
    // Messages name a hash by its first 12 characters; a byte slice of "a" followed by
    // two-byte characters split one and panicked.
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("utf8");
    run_shards(&cfg, &out, 2);
    let p = out.join("shard-1-of-2.json");
    let mut m = json(&p);
    m["config_sha256"] = "a\u{e9}\u{e9}\u{e9}\u{e9}\u{e9}\u{e9}\u{e9}\u{e9}\u{e9}\u{e9}".into();
    std::fs::write(&p, serde_json::to_string(&m).unwrap()).unwrap();
    let why = merge_refusal(&out);
    assert!(why.contains("ran another config"), "{why}");
}

/// A split run of a `[pll]` config merges at the carrier its shards locked: merge locks again
/// (the same deterministic run), and says so with the lock's size before it starts, since the
/// lock is as long as the user's pll.lock_s. The merged results are a one-machine run's.
#[test]
fn merge_says_it_locks_the_carrier_again_and_how_long() {
    // Runs `cfg` as two shards into `out`, merges them, and returns what merge said.
    let split_and_merge = |cfg: &Config, out: &Path| {
        run_shards(cfg, out, 2);
        let rec = Record::default();
        merge(out, &rec).unwrap();
        rec.0.into_inner().unwrap()
    };
    let cfg = pll_config();
    let dir = tempfile::tempdir().unwrap();
    let (split, whole) = (dir.path().join("split"), dir.path().join("whole"));
    let notes = split_and_merge(&cfg, &split);
    // 5 s at 2400 outputs/s: 12000 blocks of 100 input samples.
    let said = notes
        .iter()
        .position(|n| {
            n.starts_with("merge: the shards ran at the carrier their [pll] locked")
                && n.contains("1.200e6 input samples")
                && n.contains("s on one thread")
        })
        .unwrap_or_else(|| panic!("{notes:?}"));
    let locked = notes
        .iter()
        .position(|n| n.starts_with("pll: locked the carrier"))
        .unwrap_or_else(|| panic!("{notes:?}"));
    assert!(said < locked, "{notes:?}");
    run_shard(&cfg, &whole, None).0.unwrap();
    let csv = |d: &Path| std::fs::read(d.join("results.csv")).unwrap();
    assert!(csv(&split) == csv(&whole));
    // Without a [pll], nothing is locked and nothing said of it.
    let mut open = cfg.clone();
    open.pll = None;
    let notes = split_and_merge(&open, &dir.path().join("plain"));
    assert!(!notes.iter().any(|n| n.contains("lock")), "{notes:?}");
}

/// What stands under a point file's name may not be a file: a symlink to /dev/zero was read
/// until memory ran out, and a FIFO blocked `merge` and `run` forever. Merge refuses either,
/// naming the shard to rerun, and that shard's rerun computes the point again.
#[cfg(unix)]
#[test]
fn a_point_file_that_is_a_device_or_a_fifo_is_refused_not_read() {
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run_shards(&cfg, &out, 2);
    let p4 = out.join("points").join("point-4.json");
    let fifo = |p: &Path| {
        let made = std::process::Command::new("mkfifo").arg(p).status();
        assert!(
            made.is_ok_and(|s| s.success()),
            "mkfifo (coreutils) made no FIFO"
        );
    };
    let zero = |p: &Path| std::os::unix::fs::symlink("/dev/zero", p).unwrap();
    for (what, make) in [("/dev/zero", &zero as &dyn Fn(&Path)), ("a FIFO", &fifo)] {
        std::fs::remove_file(&p4).unwrap();
        make(&p4);
        let why = merge_refusal(&out);
        assert!(
            why.contains("point-4.json") && why.contains("not a regular file"),
            "{what}: {why}"
        );
        let owner = why
            .split("--shard ")
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .unwrap_or_else(|| panic!("{what}: no shard named in {why}"));
        run_shard(&cfg, &out, Some(parse_shard(owner).unwrap()))
            .0
            .unwrap();
        assert!(std::fs::metadata(&p4).unwrap().is_file(), "{what}");
        merge(&out, &Quiet).unwrap();
    }
}

/// An unreadable manifest stops a merge with what to do (it gave only the parser's words): a
/// folder's whole manifest (an earlier merge's, or a run's written over the shards), and a
/// shard's, whose name says which shard to rerun.
#[test]
fn an_unreadable_manifest_stops_merge_saying_what_to_do() {
    let cfg = config();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run_shards(&cfg, &out, 2);
    merge(&out, &Quiet).unwrap();
    std::fs::write(out.join("manifest.json"), "{\"format\": \"gyro").unwrap();
    let why = merge_refusal(&out);
    assert!(why.contains("manifest.json` cannot be read"), "{why}");
    assert!(why.contains("delete it and merge again"), "{why}");
    std::fs::remove_file(out.join("manifest.json")).unwrap();
    merge(&out, &Quiet).unwrap();
    std::fs::write(out.join("shard-1-of-2.json"), "x").unwrap();
    let why = merge_refusal(&out);
    assert!(why.contains("rerun its shard with --shard 1/2"), "{why}");
    run_shard(&cfg, &out, Some(parse_shard("1/2").unwrap()))
        .0
        .unwrap();
    merge(&out, &Quiet).unwrap();
}

/// The shard of the dumped point records the dump into the shared folder: a file of it lost
/// since is refused by merge naming that shard (it merged with exit 0, the folder's [dump]
/// without its files), whose rerun records it again.
#[test]
fn merge_refuses_a_dump_with_a_file_lost_naming_its_shard() {
    let cfg = parse_config(&format!(
        "{NOISY}\n[dump]\nrate_dps = 200.0\nnodes = [\"tia\", \"stage2\"]\n"
    ))
    .unwrap();
    cfg.validate().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run_shards(&cfg, &out, 3);
    merge(&out, &Quiet).unwrap();
    // Shard k of 3 holds the points k, k + 3, ...
    let i = cfg
        .emulated_rates_dps()
        .iter()
        .position(|&r| r == 200.0)
        .unwrap();
    let own = i % 3;
    std::fs::remove_file(out.join("dump_decimated.csv")).unwrap();
    let why = merge_refusal(&out);
    assert!(
        why.contains("lacks dump_decimated.csv") && why.contains(&format!("--shard {own}/3")),
        "{why}"
    );
    let (r, notes) = run_shard(&cfg, &out, Some(parse_shard(&format!("{own}/3")).unwrap()));
    r.unwrap();
    assert!(notes.contains(&format!("recomputing point {i}")), "{notes}");
    merge(&out, &Quiet).unwrap();
    assert!(out.join("dump_decimated.csv").is_file());
}
