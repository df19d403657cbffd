//! `run` and `reproduce` write results under the same names (`results.csv`, `summary.json`,
//! `plot.png`): each refuses a folder holding the other's results (exit 2, before any
//! sample, nothing changed), where each had written over them with exit 0. `run --force`
//! writes over a foreign summary.

mod common;

use common::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One Coriolis point of 0.1 s on the small board.
fn good() -> String {
    small_board("[experiment]\nkind = \"coriolis\"\nrates_dps = [50.0]\naverage_s = 0.1\n")
}

/// Every file below `dir` and its bytes.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut t = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                t.insert(p.clone(), std::fs::read(&p).unwrap());
            }
        }
    }
    t
}

fn refused(o: &std::process::Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` missing from: {err}");
    }
}

#[test]
fn reproduce_refuses_a_folder_holding_a_run() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "good.toml", &good());
    // A run at the top, and one in a preset's folder.
    for out in [
        dir.path().join("top"),
        dir.path().join("sub/m2tfg-coriolis"),
    ] {
        ok(gyroemu(&["run", s(&cfg), "--out", s(&out)], &[]));
        let root = if out.ends_with("top") {
            out.clone()
        } else {
            out.parent().unwrap().to_path_buf()
        };
        let before = tree(&root);
        let o = gyroemu(
            &["--threads", "1", "reproduce", "--quick", "--out", s(&root)],
            &[],
        );
        refused(
            &o,
            &["holds the results of a `gyroemu run`", "manifest.json"],
        );
        assert!(tree(&root) == before, "{}", root.display());
    }
}

#[test]
fn run_refuses_a_summary_no_run_wrote_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "good.toml", &good());
    let out = dir.path().join("figs");
    std::fs::create_dir(&out).unwrap();
    // What reproduce writes at its top.
    let summary = r#"{"fig4_fig5": {}, "fig8_fig9": {}, "quick": true}"#;
    std::fs::write(out.join("summary.json"), summary).unwrap();
    let before = tree(&out);
    let o = gyroemu(&["run", s(&cfg), "--out", s(&out)], &[]);
    refused(
        &o,
        &[
            "holds a `summary.json` that no `gyroemu run` wrote",
            "--force",
        ],
    );
    assert!(tree(&out) == before);
    // Forced, the run writes its results over it.
    ok(gyroemu(&["run", s(&cfg), "--out", s(&out), "--force"], &[]));
    assert!(out.join("manifest.json").is_file());
    assert_ne!(
        std::fs::read_to_string(out.join("summary.json")).unwrap(),
        summary
    );
    // The run's own folder is its to rerun: no refusal.
    ok(gyroemu(&["run", s(&cfg), "--out", s(&out)], &[]));
}

/// `--force` deletes another config's results first; what it cannot delete (here a folder
/// where `results.csv` goes, which not even root deletes as a file) is an output folder that
/// cannot be written: exit 2 before any sample, naming it (it was exit 1, an I/O failure).
#[test]
fn what_force_cannot_delete_is_refused_as_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let a = config(dir.path(), "a.toml", &good());
    let b = config(
        dir.path(),
        "b.toml",
        &good().replace("q = 1000.0", "q = 1200.0"),
    );
    let out = dir.path().join("o");
    ok(gyroemu(&["run", s(&a), "--out", s(&out)], &[]));
    std::fs::remove_file(out.join("results.csv")).unwrap();
    std::fs::create_dir_all(out.join("results.csv/kept")).unwrap();
    let o = gyroemu(&["run", s(&b), "--out", s(&out), "--force"], &[]);
    refused(
        &o,
        &[
            "--force cannot delete",
            "results.csv",
            "choose another --out",
        ],
    );
}
