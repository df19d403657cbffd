//! Shared helpers of the CLI tests that run the binary as a scheduler would: the binary with
//! the scheduler's variables cleared, and the outputs compared byte for byte.
#![allow(dead_code)]

use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Scheduler variables that must not leak into the children from the test's environment.
pub const SCHED_VARS: [&str; 8] = [
    "SLURM_ARRAY_TASK_STEP",
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_COUNT",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_MAX",
    "JOB_COMPLETION_INDEX",
    "GYROEMU_SHARD_COUNT",
    "RAYON_NUM_THREADS",
];

/// `gyroemu ARGS` with `env` added and the scheduler's variables cleared.
pub fn command(args: &[&str], env: &[(&str, &str)]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_gyroemu"));
    for v in SCHED_VARS {
        c.env_remove(v);
    }
    c.args(args).envs(env.iter().copied());
    c
}

pub fn gyroemu(args: &[&str], env: &[(&str, &str)]) -> Output {
    command(args, env).output().expect("binary runs")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", stderr(&o));
    o
}

pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Writes the config into `dir` and returns its path.
pub fn config(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

pub fn json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// A JSON array of strings, such as a file's `warnings`.
pub fn strings(v: &Value) -> Vec<&str> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect()
}

/// The warnings a command gave on stderr for its config file `cfg`
/// (`warning: CFG: ...`), in order.
pub fn config_warnings<'a>(err: &'a str, cfg: &Path) -> Vec<&'a str> {
    let prefix = format!("warning: {}: ", cfg.display());
    err.lines()
        .filter_map(|l| l.strip_prefix(&prefix))
        .collect()
}

/// Every file of `names` exists in both folders with the same bytes.
pub fn assert_same_files(a: &Path, b: &Path, names: &[&str]) {
    for f in names {
        let (x, y) = (std::fs::read(a.join(f)), std::fs::read(b.join(f)));
        assert!(x.is_ok() && y.is_ok(), "{f} missing in {a:?} or {b:?}");
        assert!(x.unwrap() == y.unwrap(), "{f} differs: {a:?} vs {b:?}");
    }
}

/// Runs `gyroemu ARGS`, sends it SIGINT as soon as `started()` (its first result file
/// appeared) or it ended, and returns its output.
pub fn interrupted(args: &[&str], started: impl Fn() -> bool) -> Output {
    let mut child = command(args, &[])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    while !started() {
        assert!(t0.elapsed().as_secs() < 60, "no result file appeared");
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    child.wait_with_output().unwrap()
}

/// A small ideal device (Q 1000 at 15 kHz) on a 240 kHz board with a 200 Hz low-pass and
/// decimation 100, then `rest` (its `[experiment]` and any other section): a sweep of a
/// few points in a fraction of a second.
pub fn small_board(rest: &str) -> String {
    format!("{SMALL_BOARD}{rest}")
}

const SMALL_BOARD: &str = r#"[device]
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
"#;

/// A Coriolis sweep with every noise source (so each point's random stream matters): nine
/// listed rates plus the implicit zero, three lane groups.
pub const NOISY: &str = r#"
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
adc_bits = 14
adc_full_scale_v = 0.1
[experiment]
kind = "coriolis"
rates_dps = [25.0, 50.0, 75.0, 100.0, 125.0, 150.0, 175.0, 200.0, 225.0]
average_s = 0.2
settle_s = 0.05
[noise]
seed = 7
effective_mass_kg = 1e-9
tia_current_noise_a_per_rthz = 1e-13
tia_voltage_noise_v_per_rthz = 2e-8
"#;

/// What a command's closing `wrote N files in ...` list names: the files, and the per-item
/// folders it summarises as `points/ (3 point files)` with their counts. Checks that N is
/// their total.
pub fn written_list(o: &Output) -> (BTreeSet<String>, BTreeMap<String, usize>) {
    let err = stderr(o);
    let lines: Vec<&str> = err.lines().collect();
    let head = lines
        .iter()
        .rposition(|l| l.starts_with("wrote "))
        .unwrap_or_else(|| panic!("no `wrote` list:\n{err}"));
    let total: usize = lines[head]["wrote ".len()..]
        .split(' ')
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{}", lines[head]));
    let (mut files, mut folders) = (BTreeSet::new(), BTreeMap::new());
    for l in lines[head + 1..].iter().take_while(|l| l.starts_with("  ")) {
        let entry = l.trim();
        match entry.split_once("/ (") {
            Some((dir, rest)) => {
                let n = rest.split(' ').next().unwrap().parse().unwrap();
                folders.insert(dir.to_string(), n);
            }
            None => {
                files.insert(entry.to_string());
            }
        }
    }
    assert_eq!(
        total,
        files.len() + folders.values().sum::<usize>(),
        "{err}"
    );
    (files, folders)
}

/// The files in `out` and, for each folder in it, how many files it holds: what
/// [`written_list`] returns for a command that wrote all of them.
pub fn files_on_disk(out: &Path) -> (BTreeSet<String>, BTreeMap<String, usize>) {
    let (mut files, mut folders) = (BTreeSet::new(), BTreeMap::new());
    for e in std::fs::read_dir(out).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            folders.insert(name, std::fs::read_dir(&p).unwrap().count());
        } else {
            files.insert(name);
        }
    }
    (files, folders)
}
