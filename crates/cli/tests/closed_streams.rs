//! A run whose stderr or stdout has no reader (`2>&-`, `| head -1`) still finishes, writes its
//! files and exits 0: a failed write of a message is not a failure of the run (it was a
//! panic's exit 101 after every file had been written). A full stdout and a dangling --out
//! link are named in their errors.

mod common;

use common::*;
use std::process::Stdio;

const TINY: &str = r#"
[device]
f0_hz = 15000.0
q = 200.0
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
[experiment]
kind = "coriolis"
rates_dps = [25.0, 50.0]
average_s = 0.05
settle_s = 0.05
"#;

#[test]
fn a_run_with_no_reader_on_stderr_or_stdout_finishes_and_exits_0() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "tiny.toml", TINY);
    for (k, closed_stderr) in [true, false].into_iter().enumerate() {
        let out = dir.path().join(format!("out{k}"));
        // A pipe whose reader is gone: every write to it fails (EPIPE).
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let mut c = command(&["--threads", "1", "run", s(&cfg), "--out", s(&out)], &[]);
        if closed_stderr {
            c.stderr(writer).stdout(Stdio::null());
        } else {
            c.stdout(writer).stderr(Stdio::null());
        }
        let status = c.status().unwrap();
        assert_eq!(status.code(), Some(0), "stderr closed: {closed_stderr}");
        assert!(out.join("results.csv").is_file());
    }
}

#[test]
fn a_full_standard_output_and_a_dangling_out_link_are_named() {
    // stdout on a full device: the error names the standard output (it said only "No space
    // left on device").
    if let Ok(full) = std::fs::File::create("/dev/full") {
        let o = command(&["config", "--list"], &[])
            .stdout(full)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1));
        assert!(stderr(&o).contains("standard output"), "{}", stderr(&o));
    }
    // --out a symbolic link to nothing: named as such, exit 2 (it said "File exists").
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "tiny.toml", TINY);
    let link = dir.path().join("out");
    std::os::unix::fs::symlink(dir.path().join("nowhere/x"), &link).unwrap();
    let o = command(&["run", s(&cfg), "--out", s(&link)], &[])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("symbolic link to nothing"),
        "{}",
        stderr(&o)
    );
}

/// `selfcal` prints its headline on stdout: a stdout that fails (a full device) is the
/// command's failure, exit 1 naming the standard output, as for `config` (it exited 0 and the
/// two lines were lost); a reader gone (`| head -1`) still ends quietly with exit 0.
#[test]
fn selfcal_headline_lost_to_a_full_stdout_is_an_error_but_not_to_a_closed_pipe() {
    // Three distinct rates (selfcal's minimum), short windows.
    let text = small_board(
        "[experiment]\nkind = \"rotating\"\nrates_dps = [200.0, 300.0, 400.0]\naverage_s = 0.9\nsettle_s = 0.05\n",
    );
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "sc.toml", &text);
    let full = std::fs::File::create("/dev/full").expect("Linux has /dev/full");
    let out = dir.path().join("full");
    let o = command(
        &["--threads", "1", "selfcal", s(&cfg), "--out", s(&out)],
        &[],
    )
    .stdout(full)
    .output()
    .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("standard output"), "{}", stderr(&o));
    assert!(out.join("selfcal.json").is_file(), "the files come first");
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = dir.path().join("pipe");
    let status = command(
        &["--threads", "1", "selfcal", s(&cfg), "--out", s(&out)],
        &[],
    )
    .stdout(writer)
    .stderr(Stdio::null())
    .status()
    .unwrap();
    assert_eq!(status.code(), Some(0));
}
