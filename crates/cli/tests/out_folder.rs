//! Output folders end to end: a second command on a folder in use exits 2 naming the holder
//! (pid, command, since when) and changes nothing; a stale lock is taken over; the lock goes
//! on every exit (success, refusal, Ctrl-C); a double SIGINT still leaves the manifest
//! `interrupted`; a failed write of the results exits 1 with the manifest `failed`; `selfcal`
//! deletes the analysis files of an earlier run that it does not write.

use serde_json::Value;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Nine listed rates plus the implicit zero: three lane groups, each long enough on one
/// thread (about 0.5 s) to be interrupted mid-run.
const LONG: &str = r#"
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
adc_bits = 14
adc_full_scale_v = 0.1
[experiment]
kind = "coriolis"
rates_dps = [25.0, 50.0, 75.0, 100.0, 125.0, 150.0, 175.0, 200.0, 225.0]
average_s = 30.0
settle_s = 0.05
"#;

/// Three distinct rates (selfcal's minimum), short windows.
const SHORT: &str = r#"
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
kind = "rotating"
rates_dps = [200.0, 300.0, 400.0]
average_s = 0.9
settle_s = 0.05
"#;

const LOCK: &str = "gyroemu.lock";

fn command(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_gyroemu"));
    for v in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"] {
        c.env_remove(v);
    }
    c.args(args);
    c
}

fn gyroemu(args: &[&str]) -> Output {
    command(args).output().expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn config(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn point_files(out: &Path) -> usize {
    std::fs::read_dir(out.join("points")).map_or(0, |d| d.count())
}

/// A lock file naming `pid` as its holder, as another process on this host would write it.
fn plant_lock(out: &Path, pid: u32) {
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .unwrap_or_default();
    let text = serde_json::json!({
        "pid": pid,
        "host": host,
        "command": "gyroemu run other.toml --out shared",
        "since_unix_s": 1_700_000_000u64,
        "since_utc": "2023-11-14 22:13:20 UTC",
    });
    std::fs::create_dir_all(out).unwrap();
    std::fs::write(out.join(LOCK), text.to_string()).unwrap();
}

/// Starts a long `run` on one thread, its stderr read line by line; returns once its first
/// lane group (four points) is saved.
fn start_long_run(cfg: &Path, out: &Path) -> (Child, mpsc::Receiver<String>) {
    let mut child = command(&["--threads", "1", "run", s(cfg), "--out", s(out)])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let err = BufReader::new(child.stderr.take().unwrap());
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in err.lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let t0 = Instant::now();
    while point_files(out) < 4 {
        assert!(t0.elapsed().as_secs() < 120, "no lane group was saved");
        assert!(child.try_wait().unwrap().is_none(), "the run ended early");
        std::thread::sleep(Duration::from_millis(2));
    }
    (child, rx)
}

fn sigint(child: &Child) {
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
}

/// Waits for a stderr line containing `needle`; returns every line read.
fn wait_for(rx: &mpsc::Receiver<String>, needle: &str) -> Vec<String> {
    let mut seen = Vec::new();
    while let Ok(line) = rx.recv_timeout(Duration::from_secs(60)) {
        let hit = line.contains(needle);
        seen.push(line);
        if hit {
            return seen;
        }
    }
    panic!("`{needle}` never came: {seen:?}");
}

#[test]
fn every_writing_command_refuses_a_folder_in_use_naming_the_holder() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "short.toml", SHORT);
    let out = dir.path().join("shared");
    let mut holder = Command::new("sleep").arg("60").spawn().unwrap();
    plant_lock(&out, holder.id());
    let lock_before = std::fs::read(out.join(LOCK)).unwrap();
    let commands: [Vec<&str>; 5] = [
        vec!["run", s(&cfg), "--out", s(&out)],
        vec!["selfcal", s(&cfg), "--out", s(&out)],
        vec!["sweep", s(&cfg), "--out", s(&out)],
        vec!["merge", s(&out)],
        vec!["reproduce", "--quick", "--out", s(&out)],
    ];
    for args in &commands {
        let o = gyroemu(args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        for needle in [
            &format!("pid {} ", holder.id()),
            "`gyroemu run other.toml --out shared`",
            "since 2023-11-14 22:13:20 UTC",
            "gyroemu.lock",
        ] {
            assert!(
                err.contains(needle),
                "{args:?}: `{needle}` missing from: {err}"
            );
        }
        let left: Vec<_> = std::fs::read_dir(&out).unwrap().collect();
        assert_eq!(left.len(), 1, "{args:?} wrote into a folder in use");
        assert_eq!(std::fs::read(out.join(LOCK)).unwrap(), lock_before);
    }
    holder.kill().unwrap();
    holder.wait().unwrap();

    // Its holder gone, the lock is stale: taken over with a warning, and released.
    let o = gyroemu(&["run", s(&cfg), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("stale lock"), "{}", stderr(&o));
    assert!(
        !out.join(LOCK).exists(),
        "the lock outlived a successful run"
    );
    // A refusal after the lock was taken releases it too.
    let other = config(
        dir.path(),
        "other.toml",
        &SHORT.replace("q = 1000.0", "q = 900.0"),
    );
    let o = gyroemu(&["run", s(&other), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("device.q: 1000.0 -> 900.0"),
        "{}",
        stderr(&o)
    );
    assert!(!out.join(LOCK).exists(), "the lock outlived a refusal");
}

#[test]
fn a_second_run_on_a_running_folder_exits_2_and_ctrl_c_releases_the_lock() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "long.toml", LONG);
    let out = dir.path().join("out");
    let (mut first, _rx) = start_long_run(&cfg, &out);
    let o = gyroemu(&["--threads", "1", "run", s(&cfg), "--out", s(&out)]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(&format!("pid {} ", first.id())), "{err}");
    assert!(err.contains(" run ") && err.contains("since "), "{err}");
    assert_eq!(json(&out.join("manifest.json"))["status"], "running");
    sigint(&first);
    let status = first.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert_eq!(json(&out.join("manifest.json"))["status"], "interrupted");
    assert!(!out.join(LOCK).exists(), "the lock outlived Ctrl-C");
}

#[test]
fn a_double_sigint_still_leaves_the_manifest_interrupted() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "long.toml", LONG);
    let out = dir.path().join("out");
    let (mut child, rx) = start_long_run(&cfg, &out);
    sigint(&child);
    // The second once the first is being handled, before the run has stopped.
    wait_for(&rx, "interrupt:");
    sigint(&child);
    let status = child.wait().unwrap();
    let err: Vec<String> = rx.try_iter().collect();
    assert_eq!(status.code(), Some(130), "{err:?}");
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "interrupted", "{m}\n{err:?}");
    // Those saved before the abort (a file being renamed into place may be left out; the
    // rerun finds it).
    let done = m["points_done"].as_array().unwrap();
    assert!(!done.is_empty(), "{m}");
    for i in done {
        assert!(out.join(format!("points/point-{i}.json")).exists(), "{i}");
    }
    assert!(
        !out.join(LOCK).exists(),
        "the lock outlived a double Ctrl-C"
    );
    // The rerun resumes from what the manifest and the points say.
    let o = gyroemu(&["run", s(&cfg), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("resuming"), "{}", stderr(&o));
}

#[test]
fn a_failed_write_exits_1_with_the_manifest_failed() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "short.toml", SHORT);
    let out = dir.path().join("out");
    // A folder in place of results.csv: its atomic rename fails, also for root.
    std::fs::create_dir_all(out.join("results.csv/keep")).unwrap();
    let o = gyroemu(&["run", s(&cfg), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "failed");
    assert!(m["next"].as_str().unwrap().contains("results.csv"), "{m}");
    assert_eq!(m["points_missing"], serde_json::json!([]));
    assert!(!out.join(LOCK).exists());
}

#[test]
fn selfcal_deletes_the_analysis_files_it_does_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let with_drift = config(
        dir.path(),
        "drift.toml",
        &format!("{SHORT}[selfcal]\ndrift_delta_t_k = [5.0]\n"),
    );
    let plain = config(dir.path(), "plain.toml", SHORT);
    let out = dir.path().join("out");
    let o = gyroemu(&["selfcal", s(&with_drift), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("drift.csv").exists() && out.join("drift.png").exists());
    // An Allan file of some earlier run, too.
    std::fs::write(out.join("allan.csv"), "tau_s\n").unwrap();
    let o = gyroemu(&["selfcal", s(&plain), "--out", s(&out)]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let summary = json(&out.join("selfcal.json"));
    assert!(summary["drift"].is_null() && summary["allan"].is_null());
    for f in ["drift.csv", "drift.png", "allan.csv"] {
        assert!(
            !out.join(f).exists(),
            "{f} left beside a selfcal.json without it"
        );
        assert!(err.contains(f), "{f} not listed: {err}");
    }
    assert!(out.join("selfcal.csv").exists());
}
