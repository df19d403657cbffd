//! Long runs end to end: a run interrupted by a real SIGINT exits 130 with a manifest marked
//! interrupted and resumes to outputs byte-identical to an uninterrupted run (the library's
//! own tests, crates/runs/tests, interrupt after an exact number of points);
//! four shards (three by `--shard`, one by Slurm's array variables) and three Kubernetes-style
//! shards merged equal the one-machine run byte for byte; merge refuses a missing shard, a
//! duplicated point, a missing point file, an unfinished shard and a shard of another config;
//! a run refuses an output folder holding another config's results unless `--force`; a machine
//! running lane groups of eight (AVX-512) writes the bytes one running groups of four writes,
//! whole runs, point files and shards merged across the two.

mod common;

use common::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Output;

/// A rotating sweep: each point's window is a different whole number of half periods, so
/// the lane groups mix window lengths.
const ROTATING: &str = r#"
[device]
f0_hz = 15000.0
q = 1000.0
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
[board]
fs_hz = 240000.0
lpf_cutoff_hz = 200.0
decimation = 100
[experiment]
kind = "rotating"
rates_dps = [200.0, 250.0, 300.0, 350.0, 400.0, 450.0, 500.0]
average_s = 1.1
settle_s = 0.05
"#;

const OUTPUTS: [&str; 3] = ["results.csv", "summary.json", "plot.png"];

/// `gyroemu [--threads t] run CFG --out OUT EXTRA...` with `env`.
fn run(cfg: &Path, out: &Path, threads: &str, extra: &[&str], env: &[(&str, &str)]) -> Output {
    let mut args = vec!["--threads", threads, "run", s(cfg), "--out", s(out)];
    args.extend(extra);
    gyroemu(&args, env)
}

fn assert_same_outputs(a: &Path, b: &Path) {
    assert_same_files(a, b, &OUTPUTS);
}

fn indices(v: &Value) -> Vec<u64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect()
}

fn point_files(out: &Path) -> usize {
    std::fs::read_dir(out.join("points")).map_or(0, |d| d.count())
}

/// The checks common to an interrupted run: exit 130, a resume hint, an interrupted manifest
/// whose done points are exactly the saved files, and no final outputs.
fn assert_interrupted(o: &Output, out: &Path, n_points: u64) {
    assert_eq!(o.status.code(), Some(130), "{}", stderr(o));
    assert!(
        stderr(o).contains("rerun the same command"),
        "{}",
        stderr(o)
    );
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "interrupted");
    let (done, missing) = (indices(&m["points_done"]), indices(&m["points_missing"]));
    assert!(!done.is_empty() && !missing.is_empty(), "{m}");
    assert_eq!(done.len() as u64 + missing.len() as u64, n_points);
    assert_eq!(point_files(out), done.len());
    for i in &done {
        assert!(out.join(format!("points/point-{i}.json")).exists());
    }
    for f in OUTPUTS {
        assert!(!out.join(f).exists(), "{f} written by an interrupted run");
    }
}

#[test]
fn sigint_saves_finished_points_and_the_rerun_completes() {
    // Long enough (about 0.5 s per lane group on one thread) to be interrupted mid-run.
    let text = NOISY.replace("average_s = 0.2", "average_s = 30.0");
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "c.toml", &text);
    let out = dir.path().join("out");
    let args = ["--threads", "1", "run", s(&cfg), "--out", s(&out)];
    let o = interrupted(&args, || point_files(&out) > 0);
    assert_interrupted(&o, &out, 10);
    ok(run(&cfg, &out, "2", &[], &[]));
    let reference = dir.path().join("ref");
    ok(run(&cfg, &reference, "2", &[], &[]));
    assert_same_outputs(&reference, &out);
}

/// Runs every shard of an `n`-way split into `out`, the last one through `last_env` (or
/// `--shard` when empty), checking that merge refuses while one is missing.
fn run_shards(cfg: &Path, out: &Path, n: usize, last_env: &[(&str, &str)]) {
    for i in 0..n - 1 {
        let shard = format!("{i}/{n}");
        ok(run(cfg, out, "1", &["--shard", &shard], &[]));
    }
    let o = gyroemu(&["merge", s(out)], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("shard {}/{n}", n - 1)),
        "{}",
        stderr(&o)
    );
    assert!(!out.join("results.csv").exists());
    let last = format!("{}/{n}", n - 1);
    let extra: Vec<&str> = if last_env.is_empty() {
        vec!["--shard", &last]
    } else {
        vec![]
    };
    let o = ok(run(cfg, out, "2", &extra, last_env));
    assert!(stderr(&o).contains("gyroemu merge"), "{}", stderr(&o));
}

#[test]
fn four_shards_merged_equal_the_one_machine_run() {
    for (name, text) in [("noisy", NOISY), ("rotating", ROTATING)] {
        let dir = tempfile::tempdir().unwrap();
        let cfg = config(dir.path(), &format!("{name}.toml"), text);
        let reference = dir.path().join("ref");
        ok(run(&cfg, &reference, "2", &[], &[]));
        // Slurm array 1-4: task 4 is shard 3 of 4.
        let slurm = [
            ("SLURM_ARRAY_TASK_ID", "4"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_MAX", "4"),
        ];
        let out = dir.path().join("sharded");
        run_shards(&cfg, &out, 4, &slurm);
        assert!(out.join("shard-3-of-4.json").exists());
        ok(gyroemu(&["merge", s(&out)], &[]));
        assert_same_outputs(&reference, &out);
        assert_eq!(json(&out.join("manifest.json"))["status"], "complete");
    }
}

#[test]
fn kubernetes_indexed_job_shards_merge_too() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "c.toml", NOISY);
    let reference = dir.path().join("ref");
    ok(run(&cfg, &reference, "1", &[], &[]));
    let out = dir.path().join("k8s");
    // The index alone does not say the count: refused.
    let o = run(&cfg, &out, "1", &[], &[("JOB_COMPLETION_INDEX", "0")]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--shard-count"), "{}", stderr(&o));
    ok(run(
        &cfg,
        &out,
        "1",
        &["--shard-count", "3"],
        &[("JOB_COMPLETION_INDEX", "0")],
    ));
    for i in ["1", "2"] {
        let env = [("JOB_COMPLETION_INDEX", i), ("GYROEMU_SHARD_COUNT", "3")];
        ok(run(&cfg, &out, "1", &[], &env));
    }
    ok(gyroemu(&["merge", s(&out)], &[]));
    assert_same_outputs(&reference, &out);
}

/// Every file of a run's output folder, by path inside it.
fn tree(out: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
    let mut files = std::collections::BTreeMap::new();
    let mut dirs = vec![out.to_path_buf()];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else {
                let rel = p.strip_prefix(out).unwrap().to_path_buf();
                files.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    files
}

#[test]
fn eight_lane_and_four_lane_machines_write_the_same_bytes() {
    let eight = gyroemu(&["--lanes", "8", "config"], &[]).status.success();
    if !eight {
        eprintln!("no AVX-512 on this CPU: groups of eight are not run here");
        let o = gyroemu(&["--lanes", "8", "config"], &[]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains("AVX-512"), "{}", stderr(&o));
        return;
    }
    let o = gyroemu(&["--lanes", "5", "config"], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("must be 4 or 8"), "{}", stderr(&o));
    for (name, text) in [("noisy", NOISY), ("rotating", ROTATING)] {
        let dir = tempfile::tempdir().unwrap();
        let cfg = config(dir.path(), &format!("{name}.toml"), text);
        let lanes = |n: &str, out: &Path, extra: &[&str]| {
            let mut args = vec![
                "--lanes",
                n,
                "--threads",
                "1",
                "run",
                s(&cfg),
                "--out",
                s(out),
            ];
            args.extend(extra);
            let o = ok(gyroemu(&args, &[]));
            // The plan states the widest groups the run may use: as wide as allowed.
            let plan = format!("lane groups of up to {n}");
            assert!(stderr(&o).contains(&plan), "{}", stderr(&o));
        };
        let (four, wide) = (dir.path().join("four"), dir.path().join("eight"));
        lanes("4", &four, &[]);
        lanes("8", &wide, &[]);
        let files = tree(&four);
        assert!(files.keys().any(|p| p.starts_with("points")), "{files:?}");
        assert!(files == tree(&wide), "{name}: the outputs differ");
        // Two shards, one per kind of machine, merged.
        let mixed = dir.path().join("mixed");
        lanes("8", &mixed, &["--shard", "0/2"]);
        lanes("4", &mixed, &["--shard", "1/2"]);
        ok(gyroemu(&["merge", s(&mixed)], &[]));
        assert_same_outputs(&four, &mixed);
    }
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &to.join(e.file_name()));
        } else {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

/// Merge on `dir` exits 2 naming every needle, and writes no results.
fn refused(dir: &Path, needles: &[&str]) {
    let o = gyroemu(&["merge", s(dir)], &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` missing from: {err}");
    }
    assert!(!dir.join("results.csv").exists());
}

#[test]
fn merge_refuses_missing_duplicated_unfinished_and_foreign_shards() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "c.toml", NOISY);
    let good = dir.path().join("good");
    for i in 0..4 {
        ok(run(&cfg, &good, "1", &["--shard", &format!("{i}/4")], &[]));
    }
    let case = |name: &str| {
        let d = dir.path().join(name);
        copy_dir(&good, &d);
        d
    };

    let d = case("missing-shard");
    std::fs::remove_file(d.join("shard-2-of-4.json")).unwrap();
    refused(&d, &["shard 2/4", "missing", "--shard"]);

    let d = case("missing-point-file");
    std::fs::remove_file(d.join("points/point-6.json")).unwrap();
    refused(&d, &["point-6.json", "shard 2/4"]);

    // The same point under two file names.
    let d = case("duplicated-file");
    std::fs::copy(
        d.join("points/point-5.json"),
        d.join("points/point-05.json"),
    )
    .unwrap();
    refused(&d, &["point 5", "duplicated"]);

    // A shard that claims a point another shard ran.
    let d = case("duplicated-claim");
    let p = d.join("shard-1-of-4.json");
    let mut m = json(&p);
    m["points"].as_array_mut().unwrap().push(Value::from(0));
    std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    refused(&d, &["point 0", "duplicated", "0/4", "1/4"]);

    // Shards of two different splits.
    let d = case("mixed-splits");
    ok(run(&cfg, &d, "1", &["--shard", "0/3"], &[]));
    refused(&d, &["different splits"]);

    // A shard that was interrupted: its manifest as an interrupted run leaves it (what the
    // library's tests check it writes), its missing points' files absent.
    let d = case("interrupted");
    std::fs::remove_file(d.join("points/point-3.json")).unwrap();
    std::fs::remove_file(d.join("points/point-7.json")).unwrap();
    let p = d.join("shard-3-of-4.json");
    let mut m = json(&p);
    m["status"] = Value::from("interrupted");
    m["points_done"] = Value::from(Vec::<u64>::new());
    m["points_missing"] = Value::from(vec![3u64, 7]);
    std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    refused(&d, &["shard 3/4", "interrupted", "rerun"]);

    // Shard 2 run on another config (another seed), its files put in place of the original.
    let other = config(
        dir.path(),
        "other.toml",
        &NOISY.replace("seed = 7", "seed = 8"),
    );
    let foreign = dir.path().join("foreign-run");
    ok(run(&other, &foreign, "1", &["--shard", "2/4"], &[]));
    let d = case("foreign");
    for i in [2, 6] {
        let f = format!("points/point-{i}.json");
        std::fs::copy(foreign.join(&f), d.join(&f)).unwrap();
    }
    std::fs::copy(
        foreign.join("shard-2-of-4.json"),
        d.join("shard-2-of-4.json"),
    )
    .unwrap();
    refused(&d, &["shard-2-of-4.json", "another config"]);

    // The untouched copy still merges.
    let d = case("untouched");
    ok(gyroemu(&["merge", s(&d)], &[]));
}

#[test]
fn run_refuses_another_configs_results_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let a = config(dir.path(), "a.toml", NOISY);
    let b = config(
        dir.path(),
        "b.toml",
        &NOISY.replace("q = 1000.0", "q = 1200.0"),
    );
    let out = dir.path().join("out");
    ok(run(&a, &out, "1", &[], &[]));
    let before = std::fs::read(out.join("results.csv")).unwrap();
    let o = run(&b, &out, "1", &[], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--force"), "{}", stderr(&o));
    assert!(stderr(&o).contains("another config"), "{}", stderr(&o));
    assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), before);

    let o = ok(run(&b, &out, "1", &["--force"], &[]));
    assert!(stderr(&o).contains("deleting"), "{}", stderr(&o));
    let fresh = dir.path().join("fresh");
    ok(run(&b, &fresh, "2", &[], &[]));
    assert_same_outputs(&fresh, &out);
    assert_eq!(point_files(&out), 10);

    // Comments and key order do not change a config's identity: its results are reused.
    let b2 = config(
        dir.path(),
        "b2.toml",
        &format!(
            "# the same config\n{}",
            std::fs::read_to_string(&b).unwrap()
        ),
    );
    let o = ok(run(&b2, &out, "1", &[], &[]));
    assert!(stderr(&o).contains("reusing"), "{}", stderr(&o));
}
