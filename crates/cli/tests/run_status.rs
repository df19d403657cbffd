//! What `run` tells the user about its work: the closing `wrote` list names every file a
//! whole run or a shard wrote (dumps, manifests, and the point files as `points/ (N point
//! files)`), and a resumed run states the work it has left beside the whole plan.

mod common;

use common::*;
use std::path::Path;
use std::process::Output;

/// A Coriolis sweep with a dump: four listed rates plus the implicit zero, equal windows.
const DUMPED: &str = r#"
[experiment]
kind = "coriolis"
rates_dps = [25.0, 50.0, 75.0, 100.0]
average_s = 0.1
settle_s = 0.05
[dump]
"#;

fn run(cfg: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["--threads", "2", "run", s(cfg), "--out", s(out)];
    args.extend(extra);
    ok(gyroemu(&args, &[]))
}

#[test]
fn every_file_a_run_or_a_shard_writes_is_in_its_wrote_list() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "c.toml", &small_board(DUMPED));
    let mut dumped = 0;
    for i in 0..2 {
        // A fresh folder per shard: what is on disk is what the shard wrote.
        let out = dir.path().join(format!("shard{i}"));
        let o = run(&cfg, &out, &["--shard", &format!("{i}/2")]);
        assert!(stderr(&o).contains("shard complete; "), "{}", stderr(&o));
        let (files, folders) = written_list(&o);
        assert_eq!(
            (files.clone(), folders),
            files_on_disk(&out),
            "{}",
            stderr(&o)
        );
        assert!(files.contains(&format!("shard-{i}-of-2.json")), "{files:?}");
        dumped += usize::from(files.contains("dump_fullrate.sigmf-meta"));
    }
    assert_eq!(dumped, 1, "one shard records the dump and lists it");

    let out = dir.path().join("whole");
    let o = run(&cfg, &out, &[]);
    let (files, folders) = written_list(&o);
    assert_eq!((files.clone(), folders.clone()), files_on_disk(&out));
    assert_eq!(folders["points"], 5, "{}", stderr(&o));
    for f in ["results.csv", "manifest.json", "dump_decimated.wav"] {
        assert!(files.contains(f), "{f}: {files:?}");
    }
}

/// The number after `key` in `line` (`key` ends where the number starts).
fn number_after(line: &str, key: &str) -> f64 {
    let at = line
        .find(key)
        .unwrap_or_else(|| panic!("`{key}` not in {line}"))
        + key.len();
    line[at..]
        .split([' ', ','])
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn a_resumed_run_states_the_work_it_has_left() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "c.toml", &small_board(DUMPED));
    let out = dir.path().join("out");
    run(&cfg, &out, &["--shard", "0/2"]);
    // The whole run now resumes from shard 0's three points.
    let o = run(&cfg, &out, &[]);
    let err = stderr(&o);
    let plan = err.lines().find(|l| l.starts_with("plan: ")).unwrap();
    assert_eq!(number_after(plan, "plan: "), 5.0, "the whole plan: {plan}");
    let resume = err.lines().find(|l| l.contains("resuming, ")).unwrap();
    assert_eq!(number_after(resume, "resuming, "), 3.0, "{resume}");
    let left = &resume[resume
        .find("; left to run: ")
        .unwrap_or_else(|| panic!("no work left stated: {err}"))..];
    assert_eq!(number_after(left, "left to run: "), 2.0, "{left}");
    assert!(left.contains(" s at the "), "a time estimate: {left}");
    // Its point-samples are those the run then reports.
    let ran = err.lines().find(|l| l.starts_with("run: ")).unwrap();
    let ps = number_after(left, "operating points, ");
    assert_eq!(
        format!("{ps:.3e}"),
        format!("{:.3e}", number_after(ran, "run: ")),
        "{err}"
    );
    // Only the two points computed now are listed as written.
    assert_eq!(written_list(&o).1["points"], 2, "{err}");
}
