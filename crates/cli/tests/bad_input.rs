//! `gyroemu run` on input it must refuse: each case exits with code 2, prints one `error:`
//! line naming the problem, and writes nothing into `--out` (the folder stays absent).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A valid, fast config (used where the config is not the bad input).
const GOOD: &str = r#"
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
kind = "coriolis"
rates_dps = [50.0]
average_s = 0.1
"#;

fn run(config: &Path, out: &Path) -> Output {
    run_with(&[], config, out)
}

/// `gyroemu FLAGS run CONFIG --out OUT` (global flags before the command).
fn run_with(flags: &[&str], config: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gyroemu"))
        .args(flags)
        .arg("run")
        .arg(config)
        .arg("--out")
        .arg(out)
        .output()
        .expect("binary runs")
}

/// Runs the case and checks exit code 2, a single `error:` line holding every needle, and
/// that `out` was not created.
fn refused(what: &str, config: &Path, out: &Path, needles: &[&str]) {
    refused_with(&[], what, config, out, needles);
}

/// [`refused`] with global flags before the command.
fn refused_with(flags: &[&str], what: &str, config: &Path, out: &Path, needles: &[&str]) {
    let o = run_with(flags, config, out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{what}: one message expected: {err}");
    assert!(lines[0].starts_with("error: "), "{what}: {err}");
    for n in needles {
        assert!(lines[0].contains(n), "{what}: `{n}` missing from: {err}");
    }
    assert!(o.stdout.is_empty(), "{what}: stdout not empty");
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn unreadable_configs_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.join("out");
    let cases: Vec<(&str, PathBuf, Vec<&str>)> = vec![
        (
            "empty file",
            write(d, "empty.toml", b""),
            vec!["empty.toml", "empty"],
        ),
        (
            "whitespace only",
            write(d, "blank.toml", b"  \n\n\t"),
            vec!["blank.toml", "empty"],
        ),
        (
            "non-UTF-8 file",
            write(d, "latin1.toml", b"[device]\nf0_hz = 15000.0 # \xe9t\xe9\n"),
            vec!["latin1.toml", "not UTF-8"],
        ),
        (
            "missing file",
            d.join("nope.toml"),
            vec!["nope.toml", "cannot read config"],
        ),
        ("a directory", d.to_path_buf(), vec!["cannot read config"]),
        // An endless stream is read up to the limit, not until memory runs out; a file of
        // exactly the limit is read (then refused as the blank text it is), one byte more not.
        (
            "an endless stream",
            PathBuf::from("/dev/zero"),
            vec!["/dev/zero", "larger than 16 MiB"],
        ),
        (
            "a file at the size limit",
            write(d, "limit.toml", &vec![b' '; 16 << 20]),
            vec!["limit.toml", "empty"],
        ),
        (
            "a file one byte above it",
            write(d, "above.toml", &vec![b' '; (16 << 20) + 1]),
            vec!["above.toml", "larger than 16 MiB"],
        ),
        (
            "bad value",
            write(
                d,
                "q.toml",
                GOOD.replace("q = 1000.0", "q = -1.0").as_bytes(),
            ),
            vec!["q.toml", "device.q", "-1", "> 0"],
        ),
        (
            "wrong type",
            write(
                d,
                "t.toml",
                GOOD.replace("q = 1000.0", "q = \"x\"").as_bytes(),
            ),
            vec![
                "t.toml",
                "line 4, column 5",
                "device.q",
                "expected a number",
            ],
        ),
        (
            "misspelt key",
            write(
                d,
                "k.toml",
                GOOD.replace("decimation", "decimaton").as_bytes(),
            ),
            vec![
                "k.toml",
                "board.decimaton",
                "unknown key",
                "did you mean `decimation`?",
            ],
        ),
        (
            "output-rate Nyquist",
            write(
                d,
                "c.toml",
                GOOD.replace("lpf_cutoff_hz = 200.0", "lpf_cutoff_hz = 1200.0")
                    .as_bytes(),
            ),
            vec!["c.toml", "board.lpf_cutoff_hz", "1200", "Nyquist"],
        ),
    ];
    for (what, config, needles) in cases {
        refused(what, &config, &out, &needles);
        assert!(!out.exists(), "{what}: --out was created");
    }
}

/// Runs the case and checks exit code 2, one `error:` message listing every problem (a count,
/// then one indented line each holding its needles, in order), and that `out` was not created.
fn refused_all(what: &str, config: &Path, out: &Path, problems: &[&[&str]]) {
    let o = run(config, out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1 + problems.len(), "{what}: {err}");
    assert!(
        lines[0].starts_with("error: ")
            && lines[0].ends_with(&format!("config error: {} problems:", problems.len())),
        "{what}: {err}"
    );
    for (line, needles) in lines[1..].iter().zip(problems) {
        assert!(line.starts_with("  "), "{what}: {err}");
        for n in *needles {
            assert!(line.contains(n), "{what}: `{n}` missing from: {line}");
        }
    }
    assert!(!out.exists(), "{what}: --out was created");
}

#[test]
fn every_problem_of_a_config_is_refused_in_one_message() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.join("out");
    // Parsing: a wrong type, a misspelt key and a missing section.
    let text = GOOD
        .replace("q = 1000.0", "q = \"x\"")
        .replace("decimation", "decimaton")
        .replace("[drive]\nf1 = 1.0\nf2 = 1.0\n", "");
    let parse = write(d, "parse.toml", text.as_bytes());
    refused_all(
        "parse problems",
        &parse,
        &out,
        &[
            &[
                "line 4, column 5",
                "device.q",
                "= \"x\"",
                "expected a number",
            ],
            &["line 9, column 1", "board.decimaton", "unknown key"],
            // A missing section has no line: it closes the list, named as itself.
            &["  key `drive` is missing: the config requires the section [drive]"],
        ],
    );
    // Validation: three values out of range, each at its line.
    let text = GOOD
        .replace("q = 1000.0", "q = -1.0")
        .replace("f1 = 1.0", "f1 = 0.0")
        .replace("average_s = 0.1", "average_s = -3.0");
    let invalid = write(d, "invalid.toml", text.as_bytes());
    refused_all(
        "invalid values",
        &invalid,
        &out,
        &[
            &["line 4, column 5", "key `device.q` = -1: ", "> 0"],
            &["line 7, column 6", "key `drive.f1` = 0: ", "> 0"],
            &[
                "line 16, column 13",
                "key `experiment.average_s` = -3: ",
                "> 0",
            ],
        ],
    );
}

#[test]
fn an_output_folder_that_cannot_be_created_exits_2_before_any_sample() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let config = write(d, "good.toml", GOOD.as_bytes());
    // A path under a regular file: no permission bits involved, so it fails as root too.
    let file = write(d, "plain", b"keep");
    let out = file.join("out");
    refused(
        "out under a file",
        &config,
        &out,
        &["output folder", "cannot be created"],
    );
    assert_eq!(std::fs::read(&file).unwrap(), b"keep");
    refused(
        "out is a file",
        &config,
        &file,
        &["output folder", "is a file, not a folder"],
    );
    assert_eq!(std::fs::read(&file).unwrap(), b"keep");
    // Nothing else appeared beside the inputs.
    let mut names: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["good.toml", "plain"]);
}

#[test]
fn a_bad_config_leaves_an_existing_output_folder_empty() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.join("out");
    std::fs::create_dir(&out).unwrap();
    let config = write(
        d,
        "z.toml",
        GOOD.replace("decimation = 100", "decimation = 0")
            .as_bytes(),
    );
    refused(
        "decimation 0",
        &config,
        &out,
        &["board.decimation", "= 0", ">= 1"],
    );
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 0);
}

#[test]
fn global_flags_out_of_range_exit_2_before_any_thread_or_sample() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "good.toml", GOOD.as_bytes());
    let out = dir.path().join("out");
    for (flags, needles) in [
        (["--threads", "0"], ["--threads = 0", "from 1 to 1024"]),
        // Would start 100 000 OS threads (more than 20 s) before the refusal.
        (
            ["--threads", "100000"],
            ["--threads = 100000", "from 1 to 1024"],
        ),
        (["--lanes", "3"], ["lanes", "3"]),
    ] {
        refused_with(&flags, &flags.join(" "), &cfg, &out, &needles);
        assert!(!out.exists(), "{flags:?}: {out:?} created");
    }
}

/// The text of `gyroemu config --preset NAME`.
fn preset(name: &str) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_gyroemu"))
        .args(["config", "--preset", name])
        .output()
        .expect("binary runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

/// The Coriolis preset with the line starting `key = ` replaced by `key = value`.
fn coriolis_with(key: &str, value: &str) -> String {
    let text = preset("m2tfg-coriolis");
    let start = format!("{key} = ");
    assert!(text.lines().any(|l| l.starts_with(&start)), "{key}");
    text.lines()
        .map(|l| {
            if l.starts_with(&start) {
                format!("{key} = {value}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

#[test]
fn a_tia_pole_whose_gain_rounds_to_zero_exits_2_naming_the_pole() {
    // It blamed board.tia_gain_ohm (1e-120, 1e-300), or ran and exited 1 (1e-12 .. 1e-90).
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    for pole in ["1e-300", "1e-120", "1e-90", "1e-12"] {
        let cfg = write(
            dir.path(),
            "pole.toml",
            coriolis_with("tia_pole_hz", pole).as_bytes(),
        );
        refused(
            pole,
            &cfg,
            &out,
            &[
                &format!("key `board.tia_pole_hz` = {pole}: "),
                "must be at least 2.12",
                "rounds to exactly 1",
            ],
        );
        assert!(!out.exists(), "{pole}: --out was created");
    }
}

#[test]
fn a_dump_starting_past_the_run_exits_2_naming_its_start() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let text = preset("m2tfg-coriolis")
        + "\n[dump]\nrate_dps = 100.0\nstart_s = 50.0\nduration_s = 0.002\nnodes = [\"tia\"]\n";
    let cfg = write(dir.path(), "dump.toml", text.as_bytes());
    refused(
        "dump start past the run",
        &cfg,
        &out,
        &[
            "key `dump.start_s` = 50: ",
            "must start within that point's run (2.71",
        ],
    );
    assert!(!out.exists());
}

#[test]
fn a_tia_noise_level_that_would_overflow_exits_2_naming_it() {
    // 1e200 spoke of flicker (with no corner); 1e160 failed at run time; 1e155 exited 1.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    for (key, v) in [
        ("tia_voltage_noise_v_per_rthz", "1e200"),
        ("tia_voltage_noise_v_per_rthz", "1e160"),
        ("tia_voltage_noise_v_per_rthz", "1e155"),
        ("tia_current_noise_a_per_rthz", "1e155"),
    ] {
        let text = preset("m2tfg-coriolis") + &format!("\n[noise]\n{key} = {v}\n");
        let cfg = write(dir.path(), "noise.toml", text.as_bytes());
        refused(
            v,
            &cfg,
            &out,
            &[
                &format!("key `noise.{key}` = {v}: "),
                "standard deviation",
                "must stay within 1e100",
            ],
        );
        let err = String::from_utf8_lossy(&run(&cfg, &out).stderr).into_owned();
        assert!(!err.contains("flicker"), "{key} = {v}: {err}");
        assert!(!out.exists());
    }
}

#[test]
fn integers_out_of_range_exit_2_echoed_as_written() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cases = [
        (
            coriolis_with("lpf_order", "9223372036854775807"),
            "key `board.lpf_order` = 9223372036854775807: must be an integer from 1 to 8",
        ),
        // Past the type's limit: the key's own range, not the type's (it said "at most
        // 18446744073709551615", and for dac_bits "at most 4294967295").
        (
            coriolis_with("lpf_order", "99999999999999999999"),
            "key `board.lpf_order` = 99999999999999999999: too large: must be an integer from 1 to 8",
        ),
        (
            preset("m2tfg-coriolis").replace("[board]\n", "[board]\ndac_bits = 4294967296\n"),
            "key `board.dac_bits` = 4294967296: too large: must be an integer from 2 to 32",
        ),
        (
            preset("m2tfg-coriolis") + "\n[noise]\nseed = 18446744073709551616\n",
            "key `noise.seed` = 18446744073709551616: too large: at most 18446744073709551615",
        ),
    ];
    for (text, needle) in cases {
        let cfg = write(dir.path(), "int.toml", text.as_bytes());
        refused(needle, &cfg, &out, &[needle]);
        assert!(!out.exists());
    }
}

/// Paths are bytes on Unix, not always UTF-8 (a Latin-1 file name): a config or an output
/// folder so named runs, and `merge` on such a folder reads it; none panics (the command
/// line kept in the folder's lock had been read as UTF-8, exit 101 after creating `--out`).
#[cfg(unix)]
#[test]
fn paths_that_are_not_utf8_run_without_a_panic() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "ok.toml", GOOD.as_bytes());
    let latin = dir.path().join(OsStr::from_bytes(b"caf\xe9.toml"));
    std::fs::copy(&cfg, &latin).unwrap();
    let out = dir.path().join(OsStr::from_bytes(b"r\xe9sultats"));
    let o = run(&latin, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("results.csv").is_file());
    // The folder is released: a second command takes it and reads its run.
    let o = Command::new(env!("CARGO_BIN_EXE_gyroemu"))
        .arg("merge")
        .arg(&out)
        .output()
        .unwrap();
    assert_ne!(
        o.status.code(),
        Some(101),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("panicked"));
}

/// An output folder whose path leaves no room below it for the files a run writes (near the
/// system's PATH_MAX) is refused before any sample: the folder could be made, so the run went
/// on and failed on its first file after the emulation (exit 1, dump files without their
/// siblings, no point saved). A path with room runs.
#[cfg(target_os = "linux")]
#[test]
fn an_output_path_too_long_for_its_files_is_refused_before_any_sample() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "ok.toml", GOOD.as_bytes());
    // A path of exactly `len` bytes below the temporary folder (components of at most 200
    // bytes: a name may not pass 255), its parent made.
    let path_of = |len: usize, c: &str| {
        let mut p = dir.path().to_path_buf();
        while p.as_os_str().len() + 1 + 200 + 1 + 50 <= len {
            p.push(c.repeat(200));
        }
        let rest = len - p.as_os_str().len() - 1;
        p.push(c.repeat(rest));
        assert_eq!(p.as_os_str().len(), len);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        p
    };
    // 4050 bytes: the folder could be made (PATH_MAX is 4096), its files could not.
    let out = path_of(4050, "d");
    let o = run(&cfg, &out);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("a path of 4050 bytes") && err.contains("shorter --out"),
        "{err}"
    );
    assert!(!out.exists(), "nothing is made");
    // 3900 bytes leave room for every file a run writes: it runs.
    let short = path_of(3900, "f");
    let o = run(&cfg, &short);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(short.join("points").is_dir());
}
