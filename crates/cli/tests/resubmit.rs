//! Splits end to end, as a scheduler runs them: a Slurm index resubmitted alone (`sbatch
//! --array=5`, the advice of docs/cluster.md) is refused (exit 2) before anything is written,
//! naming both splits and the `--shard` to give, and given that it completes the split, which
//! merges to the one-machine bytes; a refused `run` (work cap, shard count, lone task) leaves
//! no output folder behind; `merge` into a folder it cannot write is bad input (exit 2) naming
//! the folder, the system's reason said once.

mod common;

use common::*;
use std::path::Path;
use std::process::Output;

/// `gyroemu --threads 1 run CFG --out OUT EXTRA...` with `env`.
fn run(cfg: &Path, out: &Path, extra: &[&str], env: &[(&str, &str)]) -> Output {
    let mut args = vec!["--threads", "1", "run", s(cfg), "--out", s(out)];
    args.extend(extra);
    gyroemu(&args, env)
}

/// The variables of task `id` of a Slurm array `min`-`max`.
fn slurm<'a>(id: &'a str, min: &'a str, max: &'a str, count: &'a str) -> [(&'a str, &'a str); 5] {
    [
        ("SLURM_ARRAY_TASK_ID", id),
        ("SLURM_ARRAY_TASK_MIN", min),
        ("SLURM_ARRAY_TASK_MAX", max),
        ("SLURM_ARRAY_TASK_COUNT", count),
        ("SLURM_ARRAY_TASK_STEP", "1"),
    ]
}

/// Exit 2 with every needle in the message.
fn refused(o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` missing from: {err}");
    }
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_slurm_index_resubmitted_alone_is_refused_and_runs_given_its_shard() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "c.toml", NOISY);
    let whole = dir.path().join("whole");
    ok(run(&cfg, &whole, &[], &[]));
    let out = dir.path().join("sl");
    for i in ["0", "1", "2", "3", "4", "6", "7"] {
        ok(run(&cfg, &out, &[], &slurm(i, "0", "7", "8")));
    }
    let before = names(&out);
    let points = names(&out.join("points"));
    // Before, it ran as shard 0/1 (every point) and merge refused the two splits.
    let o = run(&cfg, &out, &[], &slurm("5", "5", "5", "1"));
    refused(
        &o,
        &[
            "shard 0/1",
            "split into 8",
            "not complete there: 5/8",
            "--shard 5/8",
        ],
    );
    // With the count given, its place in the one-task array is still not its shard.
    let o = run(
        &cfg,
        &out,
        &["--shard-count", "8"],
        &slurm("5", "5", "5", "1"),
    );
    refused(
        &o,
        &["--shard-count = 8", "array of 1 task ", "--shard 5/8"],
    );
    assert_eq!(names(&out), before, "a refused task wrote a manifest");
    assert_eq!(names(&out.join("points")), points);

    // The job script of docs/cluster.md: the split written out, the index from Slurm.
    ok(run(
        &cfg,
        &out,
        &["--shard", "5/8"],
        &slurm("5", "5", "5", "1"),
    ));
    ok(gyroemu(&["merge", s(&out)], &[]));
    assert_same_files(&whole, &out, &["results.csv", "summary.json", "plot.png"]);
}

/// A config text, the extra arguments, the environment and what the refusal says.
type Case<'a> = (&'a str, &'a [&'a str], &'a [(&'a str, &'a str)], &'a str);

#[test]
fn a_refused_run_leaves_no_output_folder() {
    let dir = tempfile::tempdir().unwrap();
    let long = NOISY.replace("average_s = 0.2", "average_s = 1000000.0");
    let cases: [Case; 3] = [
        (&long, &[], &[], "above the cap"),
        (
            NOISY,
            &["--shard", "1/1000000"],
            &[],
            "1000000 shards of 10 points",
        ),
        (
            NOISY,
            &[],
            &slurm("5", "5", "5", "1"),
            "only task of its job array",
        ),
    ];
    for (i, (text, extra, env, needle)) in cases.into_iter().enumerate() {
        let cfg = config(dir.path(), &format!("c{i}.toml"), text);
        let out = dir.path().join(format!("out{i}"));
        refused(&run(&cfg, &out, extra, env), &[needle]);
        assert!(!out.exists(), "case {i}: `{}` created", out.display());
    }
}

#[test]
fn merge_into_a_folder_it_cannot_write_is_bad_input_said_once() {
    // A folder no one can create a file in, whoever runs the test (root ignores permission
    // bits): Linux's /proc/self.
    let dir = Path::new("/proc/self");
    if !dir.is_dir() {
        eprintln!("no /proc here: skipped");
        return;
    }
    let o = gyroemu(&["merge", s(dir)], &[]);
    refused(&o, &["output folder `/proc/self`", "gyroemu.lock"]);
    // Before, exit 1 with the system's reason twice (in the message and as its source).
    assert_eq!(stderr(&o).matches("os error").count(), 1, "{}", stderr(&o));
}

#[test]
fn a_refused_lot_leaves_no_output_folder() {
    // The lot's shard count and split are checked before its folder is created, as `run`'s.
    let dir = tempfile::tempdir().unwrap();
    let preset = gyroemu(&["config", "--preset", "m2tfg-montecarlo"], &[]);
    let cfg = config(
        dir.path(),
        "lot.toml",
        &String::from_utf8_lossy(&preset.stdout),
    );
    let lot = |out: &Path, extra: &[&str], env: &[(&str, &str)]| {
        let mut args = vec!["--threads", "1", "montecarlo", s(&cfg), "--devices", "10"];
        args.extend(["--out", s(out)]);
        args.extend(extra);
        gyroemu(&args, env)
    };
    let out = dir.path().join("huge");
    refused(
        &lot(&out, &["--shard", "0/5000"], &[]),
        &["5000 shards of 10 devices"],
    );
    assert!(!out.exists(), "`{}` created", out.display());
    let out = dir.path().join("lone");
    refused(
        &lot(&out, &[], &slurm("5", "5", "5", "1")),
        &["only task of its job array"],
    );
    assert!(!out.exists(), "`{}` created", out.display());
}
