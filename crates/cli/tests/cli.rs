//! The `gyroemu` binary end to end: presets round-trip, bad input exits 2 naming the key and
//! writing nothing, a run writes its files, and results are byte-identical across reruns and
//! thread counts.

use gyroemu_config::parse_config;
use std::path::Path;
use std::process::{Command, Output};

fn gyroemu(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gyroemu"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const SMALL: &str = r#"
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
rates_dps = [50.0, 100.0, 150.0, 175.0, 25.0]
average_s = 0.1
"#;

#[test]
fn every_preset_prints_a_config_that_parses_and_validates() {
    let list = gyroemu(&["config", "--list"]);
    assert!(list.status.success());
    let names: Vec<String> = String::from_utf8_lossy(&list.stdout)
        .lines()
        .map(|l| l.split_whitespace().next().unwrap().to_string())
        .collect();
    assert!(names.len() >= 4, "{names:?}");
    for name in names {
        let o = gyroemu(&["config", "--preset", &name]);
        assert!(o.status.success(), "{name}");
        let cfg = parse_config(&String::from_utf8_lossy(&o.stdout))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        cfg.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    assert_eq!(
        gyroemu(&["config", "--preset", "nope"]).status.code(),
        Some(2)
    );
    // With --list the preset was ignored, an unknown one included (exit 0).
    assert_eq!(
        gyroemu(&["config", "--preset", "nope", "--list"])
            .status
            .code(),
        Some(2)
    );
}

fn run_config(text: &str, dir: &Path, extra: &[&str]) -> Output {
    let cfg = dir.join("c.toml");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.join("out");
    let mut args = extra.to_vec();
    let (c, o) = (
        cfg.to_str().unwrap().to_string(),
        out.to_str().unwrap().to_string(),
    );
    args.extend(["run", c.as_str(), "--out", o.as_str()]);
    gyroemu(&args)
}

#[test]
fn bad_configs_exit_2_naming_key_value_and_rule_and_write_nothing() {
    let cases = [
        (
            SMALL.replace("q = 1000.0", "q = -1.0"),
            vec!["device.q", "-1", "> 0"],
        ),
        (
            SMALL.replace("q = 1000.0", "q = nan"),
            vec!["device.q", "NaN"],
        ),
        (
            SMALL.replace("fs_hz = 240000.0", "fs_hz = 20000.0"),
            vec!["board.fs_hz", "2*f0"],
        ),
        (
            SMALL.replace("decimation = 100", "decimation = 0"),
            vec!["board.decimation", ">= 1"],
        ),
        (
            SMALL.replace("lpf_cutoff_hz = 200.0", "lpf_cutoff_hz = 5000.0"),
            vec!["board.lpf_cutoff_hz", "Nyquist"],
        ),
        (
            SMALL.replace("q = 1000.0", "q = 1000.0\nqq = 3"),
            vec!["line 5", "qq"],
        ),
        (
            SMALL.replace("q = 1000.0", "q = \"high\""),
            vec!["line 4", "expected a number"],
        ),
        (
            SMALL.replace("angular_gain = 1.0\n", ""),
            vec!["angular_gain"],
        ),
        (
            SMALL.replace("kind = \"coriolis\"", "kind = \"spinning\""),
            vec!["spinning"],
        ),
        (String::new(), vec!["empty"]),
    ];
    for (text, needles) in cases {
        let dir = tempfile::tempdir().unwrap();
        let o = run_config(&text, dir.path(), &[]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        for n in needles {
            assert!(err.contains(n), "`{n}` missing from: {err}");
        }
        assert!(
            !dir.path().join("out").exists(),
            "nothing may be written on bad input"
        );
    }
}

#[test]
fn the_configs_warnings_reach_summary_json_beside_the_runs() {
    // A 12-bit ADC with no noise: the validation's warning on its rounding (stderr, before any
    // sample) is also in summary.json, where a script reading the results finds it.
    let dir = tempfile::tempdir().unwrap();
    let text = SMALL.replace("decimation = 100\n", "decimation = 100\nadc_bits = 12\n");
    let o = run_config(&text, dir.path(), &["--threads", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let told = stderr(&o);
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out/summary.json")).unwrap(),
    )
    .unwrap();
    let w: Vec<&str> = summary["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(
        w.iter().filter(|w| w.contains("rounding error")).count(),
        2,
        "{w:?}"
    );
    for w in w {
        assert!(told.contains(w), "{w} not in the log: {told}");
    }
}

#[test]
fn run_writes_results_and_is_deterministic_across_threads() {
    let dir = tempfile::tempdir().unwrap();
    let o = run_config(SMALL, dir.path(), &["--threads", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = dir.path().join("out");
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    for col in [
        "rate_dps",
        "phase_mode1_deg",
        "phase_mode2_deg",
        "theory_mode1_deg",
        "theory_mode2_deg",
    ] {
        assert!(
            header.split(',').any(|h| h == col),
            "{col} missing in {header}"
        );
    }
    assert_eq!(csv.lines().count(), 1 + 5);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(summary["mode1"]["slope_deg_per_dps"].as_f64().unwrap() > 0.0);
    assert!(out.join("plot.png").metadata().unwrap().len() > 1000);

    let dir2 = tempfile::tempdir().unwrap();
    assert!(run_config(SMALL, dir2.path(), &["--threads", "2"])
        .status
        .success());
    let out2 = dir2.path().join("out");
    for f in ["results.csv", "summary.json"] {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(out2.join(f)).unwrap(),
            "{f} differs"
        );
    }
}

#[test]
fn reproduce_quick_writes_every_figure_and_the_slope_ratio() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = gyroemu(&["reproduce", "--quick", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in [
        "fig4.png",
        "fig5.png",
        "fig6.png",
        "fig8.png",
        "fig9.png",
        "fig_ratetable.png",
        "fig_bandwidth.png",
    ] {
        assert!(out.join(f).metadata().unwrap().len() > 1000, "{f}");
    }
    // A figure that is its experiment's own plot has its bytes (drawn once, written twice);
    // the rotating figures add the paper-style estimate, so they differ from theirs.
    let bytes = |p: &str| std::fs::read(out.join(p)).unwrap();
    for (fig, plot, same) in [
        ("fig8.png", "m2tfg-coriolis/plot.png", true),
        ("fig4.png", "baw-coriolis/plot.png", true),
        ("fig_ratetable.png", "m2tfg-ratetable/plot.png", true),
        ("fig9.png", "m2tfg-rotating/plot.png", false),
        ("fig5.png", "baw-rotating/plot.png", false),
    ] {
        assert_eq!(bytes(fig) == bytes(plot), same, "{fig} against {plot}");
    }
    // Every file on disk is in the closing list, and each experiment has its small dump of
    // every node and the two figures drawn from it.
    let listed: std::collections::BTreeSet<String> = stderr(&o)
        .lines()
        .skip_while(|l| !l.starts_with("wrote "))
        .skip(1)
        .map(|l| l.trim().to_string())
        .collect();
    let mut on_disk = std::collections::BTreeSet::new();
    for e in std::fs::read_dir(&out).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            for f in std::fs::read_dir(&p).unwrap() {
                let f = f.unwrap().file_name().to_string_lossy().into_owned();
                on_disk.insert(format!("{name}/{f}"));
            }
        } else {
            on_disk.insert(name);
        }
    }
    assert_eq!(listed, on_disk, "{}", stderr(&o));
    for d in [
        "m2tfg-coriolis",
        "m2tfg-rotating",
        "baw-coriolis",
        "baw-rotating",
        "m2tfg-ratetable",
    ] {
        assert!(out.join(d).join("results.csv").exists(), "{d}");
        let mut dump_bytes = 0;
        for stem in ["dump_fullrate", "dump_decimated"] {
            for ext in ["csv", "wav", "sigmf-data", "sigmf-meta"] {
                let p = out.join(d).join(format!("{stem}.{ext}"));
                dump_bytes += p.metadata().unwrap_or_else(|_| panic!("{p:?}")).len();
            }
        }
        assert!(dump_bytes < 4_000_000, "{d}: dump of {dump_bytes} bytes");
        for f in ["signals.png", "spectrum.png"] {
            assert!(
                out.join(d).join(f).metadata().unwrap().len() > 10_000,
                "{d}/{f}"
            );
        }
    }
    // Emulation and writing are reported apart.
    assert!(stderr(&o).contains("; writing dumps: "), "{}", stderr(&o));
    // The closing line counts every point-sample emulated: the five sweeps' (their
    // summaries') and the bandwidth sweep's, as the plan announced them.
    let count = |prefix: &str| -> f64 {
        let line = stderr(&o)
            .lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` line"))
            .to_string();
        let n = line[prefix.len()..]
            .split(" point-samples")
            .next()
            .unwrap()
            .rsplit(' ')
            .next()
            .unwrap()
            .parse::<f64>();
        n.unwrap_or_else(|e| panic!("{line}: {e}"))
    };
    let (planned, emulated) = (count("plan: "), count("reproduce: "));
    assert!(
        (planned / emulated - 1.0).abs() < 1e-3,
        "{planned} {emulated}"
    );
    let swept: f64 = [
        "m2tfg-coriolis",
        "m2tfg-rotating",
        "baw-coriolis",
        "baw-rotating",
        "m2tfg-ratetable",
    ]
    .iter()
    .map(|d| {
        let s: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join(d).join("summary.json")).unwrap(),
        )
        .unwrap();
        s["point_samples_emulated"].as_f64().unwrap()
    })
    .sum();
    // The bandwidth sweep: nine table points of 12.2 s of settling plus max(2/f, 4) s.
    let bandwidth = emulated - swept;
    assert!((4.9e7..5.1e7).contains(&bandwidth), "{bandwidth:e}");
    // inspect reads a dump back: the Coriolis drive is F1 cos(w0 t) with F1 = 1, a tone of
    // -3.01 dB re 1 m/s^2 rms at f0 = 15 kHz.
    let o = gyroemu(&[
        "inspect",
        out.join("m2tfg-coriolis").to_str().unwrap(),
        "--out",
        dir.path().join("insp").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    let drive = text
        .lines()
        .find(|l| l.trim_start().starts_with("drive1"))
        .unwrap();
    assert!(drive.contains("15000.0: -3.0 dB re 1 m/s²"), "{drive}");
    assert!(dir.path().join("insp").join("spectrum.png").exists());
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    // Fig. 6: the Coriolis slope over the rotating slope is lambda.
    for pair in ["fig8_fig9", "fig4_fig5"] {
        let e = s[pair]["ratio_relative_error"].as_f64().unwrap();
        assert!(e.abs() < 1e-4, "{pair}: {e}");
    }
    for fig in ["fig4", "fig5", "fig8", "fig9"] {
        assert!(
            s["max_abs_error_mdeg"][fig].as_f64().unwrap() < 1.0,
            "{fig}"
        );
    }
}

#[test]
fn inspect_refuses_missing_or_damaged_dumps_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nothing.sigmf-meta");
    let o = gyroemu(&["inspect", missing.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("nothing.sigmf-meta"), "{}", stderr(&o));
    let bad = dir.path().join("bad.sigmf-meta");
    std::fs::write(
        &bad,
        r#"{"global": {"core:datatype": "rf64_le", "core:sample_rate": -1}}"#,
    )
    .unwrap();
    let o = gyroemu(&["inspect", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("core:sample_rate = -1"),
        "{}",
        stderr(&o)
    );
    let o = gyroemu(&["inspect", dir.path().to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no dump there"), "{}", stderr(&o));
    // Nothing was rendered.
    let pngs = std::fs::read_dir(dir.path())
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "png")
        })
        .count();
    assert_eq!(pngs, 0);
}

/// `bench` measures the whole chain, noiseless, with noise and with flicker too, in the lanes a run uses here and
/// in each lane type the CPU runs, the noisy chain's normal generator, and every stage, on 1 and on all threads (the figures are
/// timing, so only their presence and sign are checked), and refuses repeats and samples out of range.
#[test]
fn bench_prints_the_chain_and_every_stage_for_one_and_all_threads() {
    let o = gyroemu(&[
        "--threads",
        "2",
        "bench",
        "--samples",
        "20000",
        "--repeats",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    // The figures' CPU first, as the kernel names it (vendor, family and model; the
    // threads), and eight lanes exactly where its flags list AVX-512 F, VL, DQ and BW.
    let first = stderr(&o).lines().next().unwrap_or_default().to_string();
    assert!(
        first.starts_with("cpu: ") && first.contains("; 2 threads; "),
        "{first}"
    );
    if let Ok(info) = std::fs::read_to_string("/proc/cpuinfo") {
        let field = |key: &str| {
            info.lines()
                .find(|l| l.split(':').next().map(str::trim) == Some(key))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
                .unwrap_or_else(|| panic!("no `{key}` in /proc/cpuinfo"))
        };
        let id = format!(
            "{} family {} model {}",
            field("vendor_id"),
            field("cpu family"),
            field("model")
        );
        assert!(first.contains(&id), "{first} against {id}");
        let flags = field("flags");
        let has = |f: &str| flags.split_whitespace().any(|x| x == f);
        let eight = ["avx512f", "avx512vl", "avx512dq", "avx512bw"]
            .iter()
            .all(|f| has(f));
        assert_eq!(first.contains("up to eight lanes"), eight, "{first}");
        assert_eq!(
            first.contains("generator: AVX-512F"),
            has("avx512f"),
            "{first}"
        );
    }
    // Groups of eight exist on a CPU with AVX-512 only; the rows without a lane type are the
    // figures of the type a run of that chain uses, which the header names per chain: the
    // widest, except four for the noiseless rotating chain (the default preset's) where the
    // CPU splits 512-bit operations (`halves_512`, which the board crate's tests check
    // against /proc/cpuinfo).
    let eight = gyroemu(&["--lanes", "8", "config"]).status.success();
    let widest = if eight { "f64x8" } else { "f64x4" };
    let natives = |err: &str| -> Vec<String> {
        let at = err
            .find("with noise and flicker): ")
            .unwrap_or_else(|| panic!("{err}"));
        let list = err[at..].split(": ").nth(1).unwrap();
        let list = list.split(" per group").next().unwrap();
        list.split(" / ")
            .map(|w| w.rsplit(' ').next().unwrap().to_string())
            .collect()
    };
    let native = natives(&stderr(&o));
    assert_eq!(native.len(), 3, "{}", stderr(&o));
    let want = if gyroemu_board::halves_512() {
        "f64x4"
    } else {
        widest
    };
    assert_eq!(native[0], want, "{native:?}");
    assert_eq!(native[1..], [widest, widest], "{}", stderr(&o));
    // `--lanes 8` runs every chain in eight lanes, `--lanes 4` in four.
    let short = ["bench", "--samples", "20000", "--repeats", "1"];
    for (lanes, t) in [("4", "f64x4"), ("8", "f64x8")]
        .iter()
        .take(if eight { 2 } else { 1 })
    {
        let forced = gyroemu(&[&["--threads", "1", "--lanes", lanes][..], &short[..]].concat());
        assert!(forced.status.success(), "{}", stderr(&forced));
        assert_eq!(natives(&stderr(&forced)), [*t; 3], "{}", stderr(&forced));
        // The CPU line states the process's widest group, not only the CPU's.
        let widest = if *lanes == "4" { "four" } else { "eight" };
        let first = stderr(&forced)
            .lines()
            .next()
            .unwrap_or_default()
            .to_string();
        assert!(
            first.contains(&format!("groups of up to {widest} lanes")),
            "{first}"
        );
    }
    let mut names = vec![
        "whole chain".to_string(),
        "whole chain with noise".to_string(),
        "whole chain with noise and flicker".to_string(),
        "resonator (decoupled step)".to_string(),
        "low-pass bank (I1, Q1, I2, Q2)".to_string(),
        "tia".to_string(),
    ];
    // The noisy chain's normals alone, in its lanes (the widest).
    names.push(format!("normal generator (4 per point-sample, {widest})"));
    for t in ["f64x4", "f64x8"].iter().take(if eight { 2 } else { 1 }) {
        names.push(format!("whole chain ({t})"));
        names.push(format!("whole chain with noise ({t})"));
        names.push(format!("whole chain with noise and flicker ({t})"));
    }
    let figures = |name: &str, threads: &str| -> Vec<f64> {
        let row = text
            .lines()
            .find(|l| {
                // The label is the text left of the three figures.
                let words: Vec<&str> = l.split_whitespace().collect();
                words.len() > 3
                    && words[..words.len() - 3].join(" ") == name
                    && words[words.len() - 3] == threads
            })
            .unwrap_or_else(|| panic!("no `{name}` row on {threads} threads:\n{text}"));
        row.split_whitespace()
            .rev()
            .take(2)
            .map(|x| x.parse().unwrap())
            .collect()
    };
    for name in &names {
        for threads in ["1", "2"] {
            let v = figures(name, threads);
            // Best (second from the right) is at least the median (rightmost), both positive.
            assert!(v[0] > 0.0 && v[1] >= v[0], "{name}: {v:?}");
        }
    }
    for (label, native) in [
        "whole chain",
        "whole chain with noise",
        "whole chain with noise and flicker",
    ]
    .iter()
    .zip(&native)
    {
        let typed = format!("{label} ({native})");
        assert_eq!(figures(label, "1"), figures(&typed, "1"), "{label}");
    }
    assert!(!text.contains("(f64x8)") || eight, "{text}");
    // Refused before any measurement: u64::MAX repeats panicked on a capacity overflow, and
    // 2^64 samples would have run for ever.
    for (args, needle) in [
        (["--repeats", "0"], "--repeats = 0: must be from 1 to 1000"),
        (
            ["--repeats", "18446744073709551615"],
            "--repeats = 18446744073709551615: must be from 1 to 1000",
        ),
        (["--samples", "18446744073709551615"], "at most 2^40"),
    ] {
        let bad = gyroemu(&["bench", args[0], args[1]]);
        assert_eq!(bad.status.code(), Some(2), "{args:?}");
        assert!(stderr(&bad).contains(needle), "{}", stderr(&bad));
        assert!(bad.stdout.is_empty(), "{args:?}");
    }
}

/// `config --resolved` fills in every derived key with its rule, and what it prints is a config
/// that parses to the same complete config (nothing is derived twice or lost).
#[test]
fn config_resolved_prints_the_complete_config_with_its_rules() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("min.toml");
    std::fs::write(
        &path,
        "[device]\nf0_hz = 15000.0\nq = 2000.0\nangular_gain = 1.0\n[drive]\nf1 = 1.0\n\
         [experiment]\nkind = \"rotating\"\nrates_dps = [25.0, 100.0, 175.0]\naverage_s = 8.0\n",
    )
    .unwrap();
    let o = gyroemu(&["config", "--resolved", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    for rule in [
        "#   drive.f2 = 1.0: equal to drive.f1",
        "#   board.fs_hz = 240000.0: 16 samples per period",
        "#   board.lpf_cutoff_hz = 150.0:",
        "#   board.decimation = 76:",
        "#   drive.carrier_hz = 15000.0:",
    ] {
        assert!(text.contains(rule), "{rule} missing from:\n{text}");
    }
    let printed = gyroemu_config::parse_config(&text).unwrap();
    let direct = gyroemu_config::parse_config(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert_eq!(printed, direct);
    // A refused file is refused here too, with exit 2.
    std::fs::write(&path, "[device]\nf0_hz = -1.0\n").unwrap();
    let o = gyroemu(&["config", "--resolved", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // It reads a config as `run` does: bounded, UTF-8.
    for (bytes, needle) in [
        (&b"q = \xe9"[..], "not UTF-8"),
        (&vec![b' '; (16 << 20) + 1][..], "larger than 16 MiB"),
    ] {
        std::fs::write(&path, bytes).unwrap();
        let o = gyroemu(&["config", "--resolved", path.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(needle), "{}", stderr(&o));
    }
}

#[test]
fn reproduce_refuses_preset_folders_it_cannot_own_before_any_sample() {
    // A file where a preset's folder goes: named, exit 2, and no folder made (it exited 1
    // after making three).
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("baw-rotating"), "x").unwrap();
    let o = gyroemu(&["reproduce", "--quick", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("baw-rotating` is a file"),
        "{}",
        stderr(&o)
    );
    let mut left: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left, ["baw-rotating"]);
    // A preset folder locked by a live gyroemu (this test's own pid, this host): refused, its
    // files untouched (reproduce wrote into it).
    let out = dir.path().join("locked");
    let preset = out.join("m2tfg-rotating");
    std::fs::create_dir_all(&preset).unwrap();
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap_or_default();
    let lock = format!(
        r#"{{"pid": {}, "host": "{}", "command": "gyroemu run x.toml", "since_unix_s": 0, "since_utc": "1970-01-01 00:00:00 UTC"}}"#,
        std::process::id(),
        host.trim()
    );
    std::fs::write(preset.join("gyroemu.lock"), &lock).unwrap();
    let o = gyroemu(&["reproduce", "--quick", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("in use by another gyroemu"),
        "{}",
        stderr(&o)
    );
    let mut left: Vec<_> = std::fs::read_dir(&preset)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left, ["gyroemu.lock"]);
}
