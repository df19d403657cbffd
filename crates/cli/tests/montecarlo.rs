//! `gyroemu montecarlo` end to end: the preset is listed; a lot's shards (by `--shard` and by
//! Kubernetes' index) merged equal one machine byte for byte; `--print-device I` prints a
//! config on which `gyroemu selfcal` finds the lot's error of device I; a real SIGINT exits
//! 130 keeping the finished devices and the rerun equals an uninterrupted lot; bad input
//! (no [montecarlo], a bad key, no devices, an impossible drawn device, a lot above the work
//! cap) exits 2 before any sample is computed.

mod common;

use common::*;
use std::path::Path;
use std::process::Output;

const OUTPUTS: [&str; 4] = [
    "devices.csv",
    "montecarlo.json",
    "histogram.png",
    "percentiles.png",
];

/// The preset's text with `(from, to)` replaced (each must occur).
fn preset_with(edits: &[(&str, &str)]) -> String {
    let o = ok(gyroemu(&["config", "--preset", "m2tfg-montecarlo"], &[]));
    let mut t = String::from_utf8(o.stdout).unwrap();
    for (from, to) in edits {
        assert!(t.contains(from), "`{from}` not in the preset");
        t = t.replacen(from, to, 1);
    }
    t
}

/// The lot preset made small: Q = 200, three rates whose half periods divide 0.2 s.
fn tiny() -> String {
    preset_with(&[
        ("q = 2000.0", "q = 200.0"),
        (
            "rates_dps = [120.0, 160.0, 200.0, 240.0, 280.0, 320.0, 360.0]",
            "rates_dps = [900.0, 1800.0, 2700.0]",
        ),
        ("average_s = 1.5", "average_s = 0.2"),
        ("settle_s = 0.8", "settle_s = 0.1"),
    ])
}

fn lot(cfg: &Path, out: &Path, threads: &str, extra: &[&str], env: &[(&str, &str)]) -> Output {
    let mut args = vec!["--threads", threads, "montecarlo", s(cfg), "--out", s(out)];
    args.extend(extra);
    gyroemu(&args, env)
}

fn assert_same_outputs(a: &Path, b: &Path) {
    assert_same_files(a, b, &OUTPUTS);
}

fn device_files(out: &Path) -> usize {
    std::fs::read_dir(out.join("devices")).map_or(0, |d| d.count())
}

#[test]
fn the_preset_is_listed() {
    let o = ok(gyroemu(&["config", "--list"], &[]));
    assert!(String::from_utf8_lossy(&o.stdout).contains("m2tfg-montecarlo"));
}

#[test]
fn shards_by_flag_and_by_kubernetes_index_merge_to_the_one_machine_lot() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "lot.toml", &tiny());
    let one = dir.path().join("one");
    let o = ok(lot(&cfg, &one, "2", &["--devices", "6"], &[]));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("lot of 6 devices") && out.contains("yield within"),
        "{out}"
    );
    // Every file written is listed, the device files as `devices/ (6 device files)`.
    let (files, devices) = written_list(&o);
    assert_eq!((files, devices.clone()), files_on_disk(&one));
    assert_eq!(devices["devices"], 6);
    let split = dir.path().join("split");
    for i in 0..2 {
        let sh = format!("{i}/3");
        let o = ok(lot(
            &cfg,
            &split,
            "1",
            &["--devices", "6", "--shard", &sh],
            &[],
        ));
        assert!(stderr(&o).contains("gyroemu merge"), "{}", stderr(&o));
        let (files, devices) = written_list(&o);
        assert!(files.contains(&format!("shard-{i}-of-3.json")), "{files:?}");
        assert_eq!(devices["devices"], 2, "{}", stderr(&o));
        if i == 0 {
            assert_eq!((files, devices), files_on_disk(&split));
        }
    }
    let env = [("JOB_COMPLETION_INDEX", "2"), ("GYROEMU_SHARD_COUNT", "3")];
    ok(lot(&cfg, &split, "1", &["--devices", "6"], &env));
    let merged = ok(gyroemu(&["merge", s(&split)], &[]));
    assert_same_outputs(&one, &split);
    // The merge prints the lot's figures as the one machine did.
    assert_eq!(
        String::from_utf8_lossy(&merged.stdout),
        String::from_utf8_lossy(&o.stdout)
    );
    let m = json(&split.join("manifest.json"));
    assert_eq!(
        (m["kind"].as_str(), m["status"].as_str()),
        (Some("montecarlo"), Some("complete"))
    );
}

/// A lot reads its config as selfcal does: rate 0 beside the preset's rotating `kind`, and a
/// `[dump]` at a rate it does not list, neither refuse it, nor its merge (which validated the
/// config as `run` would, and refused a lot its shards had run).
#[test]
fn a_lot_with_parts_selfcal_ignores_runs_and_merges() {
    let dir = tempfile::tempdir().unwrap();
    let text = tiny().replacen(
        "rates_dps = [900.0, 1800.0, 2700.0]",
        "rates_dps = [0.0, 900.0, 1800.0, 2700.0]",
        1,
    ) + "\n[dump]\nrate_dps = 60.0\n";
    let cfg = config(dir.path(), "lot.toml", &text);
    let one = dir.path().join("one");
    ok(lot(&cfg, &one, "2", &["--devices", "2"], &[]));
    let split = dir.path().join("split");
    for sh in ["0/2", "1/2"] {
        ok(lot(
            &cfg,
            &split,
            "1",
            &["--devices", "2", "--shard", sh],
            &[],
        ));
    }
    ok(gyroemu(&["merge", s(&split)], &[]));
    assert_same_outputs(&one, &split);
    // `run` does refuse that config (exit 2).
    let o = gyroemu(&["run", s(&cfg), "--out", s(&dir.path().join("run"))], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// What validation warned of on stderr (the config's rules, and the drawn devices' grouped by
/// text) is in `montecarlo.json` too: a lot read later had only the run's own warnings.
#[test]
fn the_validation_warnings_are_in_the_lots_json() {
    let dir = tempfile::tempdir().unwrap();
    let text = tiny().replacen("settle_s = 0.1", "settle_s = 0.02", 1);
    let cfg = config(dir.path(), "lot.toml", &text);
    let out = dir.path().join("out");
    let o = ok(lot(&cfg, &out, "2", &["--devices", "3"], &[]));
    let err = stderr(&o);
    let said = config_warnings(&err, &cfg);
    assert!(said.iter().any(|w| w.contains("settle_s")), "{said:?}");
    let m = json(&out.join("montecarlo.json"));
    let kept = strings(&m["warnings"]);
    for w in &said {
        assert!(kept.contains(w), "{w} not in {kept:?}");
    }
}

#[test]
fn a_printed_device_self_calibrates_to_the_lots_error() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "lot.toml", &tiny());
    let out = dir.path().join("lot");
    ok(lot(&cfg, &out, "2", &["--devices", "5"], &[]));
    let csv = std::fs::read_to_string(out.join("devices.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let row: Vec<&str> = csv.lines().nth(5).unwrap().split(',').collect();
    let col = |name: &str| -> f64 {
        row[header.iter().position(|h| *h == name).unwrap()]
            .parse()
            .unwrap()
    };
    let o = ok(gyroemu(
        &["montecarlo", s(&cfg), "--print-device", "4"],
        &[],
    ));
    let dev = config(
        dir.path(),
        "device4.toml",
        &String::from_utf8(o.stdout).unwrap(),
    );
    let sc = dir.path().join("sc");
    ok(gyroemu(&["selfcal", s(&dev), "--out", s(&sc)], &[]));
    let j = json(&sc.join("selfcal.json"));
    for k in 0..2 {
        let got = j["modes"][k]["relative_error"].as_f64().unwrap();
        let want = col(&format!("board_relative_error_mode{}", k + 1));
        // serde_json's float parser is not correctly rounded: one ulp.
        assert!(
            (got - want).abs() <= 1e-15 * want.abs().max(1e-3),
            "{got} vs {want}"
        );
    }
}

#[test]
fn sigint_keeps_the_finished_devices_and_the_rerun_completes() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "lot.toml", &tiny());
    let out = dir.path().join("out");
    let args = [
        "--threads",
        "1",
        "montecarlo",
        s(&cfg),
        "--devices",
        "120",
        "--out",
        s(&out),
    ];
    let o = interrupted(&args, || device_files(&out) > 0);
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    let m = json(&out.join("manifest.json"));
    assert_eq!(m["status"], "interrupted");
    let done = m["points_done"].as_array().unwrap().len();
    assert!(done > 0 && done < 120, "{m}");
    assert_eq!(device_files(&out), done);
    for f in OUTPUTS {
        assert!(!out.join(f).exists(), "{f} written by an interrupted lot");
    }
    let o = ok(lot(&cfg, &out, "2", &["--devices", "120"], &[]));
    assert!(
        stderr(&o).contains(&format!("resuming: {done} already computed")),
        "{}",
        stderr(&o)
    );
    let reference = dir.path().join("ref");
    ok(lot(&cfg, &reference, "2", &["--devices", "120"], &[]));
    assert_same_outputs(&reference, &out);
}

/// `gyroemu montecarlo` on `text` with `--devices n` exits 2 naming every needle, computing
/// nothing.
fn refused(text: &str, n: &str, needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "lot.toml", text);
    let out = dir.path().join("out");
    let o = lot(&cfg, &out, "1", &["--devices", n], &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` missing from: {err}");
    }
    assert!(!out.join("devices").exists(), "computed despite: {err}");
}

#[test]
fn bad_input_is_refused_before_any_sample() {
    let t = tiny();
    let plain = t[..t.find("\n[montecarlo]").unwrap()].to_string();
    refused(
        &plain,
        "50",
        &["no [montecarlo] section", "m2tfg-montecarlo"],
    );
    refused(
        &t.replace("lambda_sigma_rel", "lambda_sigma"),
        "50",
        &[
            "montecarlo.lambda_sigma",
            "did you mean `lambda_sigma_rel`?",
        ],
    );
    refused(
        &t.replace("q_sigma_rel = 0.05", "q_sigma_rel = 0.3"),
        "50",
        &["montecarlo.q_sigma_rel", "Q <= 0"],
    );
    refused(&t, "0", &["at least 1 device"]);
    // Refused at once: these allocated the lot's indices first (u64::MAX: a capacity
    // overflow panic; 1e9: aborted out of memory).
    refused(&t, "1000001", &["--devices = 1000001", "at most 1000000"]);
    refused(&t, "18446744073709551615", &["at most 1000000"]);
    // A lot far above the work cap is refused once the devices validated so far pass it
    // (validating all 1e6 first took 2.5 minutes on 2 cores).
    refused(
        &t.replace("average_s = 0.2", "average_s = 200.0"),
        "1000000",
        &[
            "of these 1000000 devices alone run",
            "above the cap",
            "--force",
        ],
    );
    // A phase-shifter spread of 50 degrees passes the section's own rules, but the devices
    // drawn beyond 90 degrees are not valid boards: each refused device is named.
    refused(
        &t.replace(
            "phase_shifter_sigma_deg = 0.05",
            "phase_shifter_sigma_deg = 50.0",
        ),
        "50",
        &[
            "board.phase_shifter_error_deg",
            "(device ",
            " of the lot, drawn from [montecarlo])",
        ],
    );
}

#[test]
fn merge_refuses_a_manifest_claiming_an_oversized_lot() {
    // A hand-edited shard manifest is input too: its lot size lists every device index, so
    // 1e12 would run out of memory instead of being refused.
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "lot.toml", &tiny());
    let split = dir.path().join("split");
    for i in 0..2 {
        let sh = format!("{i}/2");
        ok(lot(
            &cfg,
            &split,
            "1",
            &["--devices", "2", "--shard", &sh],
            &[],
        ));
    }
    let mut edited = 0;
    for e in std::fs::read_dir(&split).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if name.starts_with("shard-") && name.ends_with(".json") {
            let t = std::fs::read_to_string(&p).unwrap();
            let t2 = t.replace("\"points_total\": 2", "\"points_total\": 1000000000000");
            assert_ne!(t, t2, "{name}: {t}");
            std::fs::write(&p, t2).unwrap();
            edited += 1;
        }
    }
    assert_eq!(edited, 2);
    let o = gyroemu(&["merge", s(&split)], &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("at most 1000000 devices"), "{err}");
}

#[test]
fn a_lot_with_untrusted_devices_still_prints_its_figures() {
    // A 2-bit ADC over 0.1 V reads every device as zeros: the lot fails (exit 1) after
    // writing its files, and its figures (every device untrusted: none counted) are printed
    // on stdout as a completed lot's are; stdout had been empty.
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("lot.toml");
    let text = tiny()
        .replacen("adc_bits = 16 ", "adc_bits = 2 ", 1)
        .replacen("adc_full_scale_v = 0.05 ", "adc_full_scale_v = 0.1 ", 1);
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("out");
    let o = lot(&cfg, &out, "2", &["--devices", "2"], &[]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("lot of 2 devices"), "{stdout}");
    assert!(stdout.contains("yield within"), "{stdout}");
}
