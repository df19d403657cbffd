//! `gyroemu sweep` end to end: the three files with the documented columns and keys, fits
//! that give back the configured device, the summary line, identical files on 1 and 2
//! threads, and bad `[sweep]` keys refused (exit 2) before anything is written.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A small device (Q 1000 and 800, 2 Hz apart): a sweep of 21 frequencies in a fraction of a
/// second.
const DEVICE: &str = r#"
[device]
f0_hz = 15000.0
q = 1000.0
angular_gain = 1.0
mode2_f0_offset_hz = 2.0
q_mode2 = 800.0
[drive]
f1 = 1.0
[board]
fs_hz = 240000.0
lpf_cutoff_hz = 200.0
decimation = 100
[experiment]
kind = "coriolis"
rates_dps = [25.0]
average_s = 1.0
[sweep]
points = 21
"#;

fn gyroemu(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gyroemu"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn config(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("sweep.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn writes_the_response_and_fits_that_give_back_the_device() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), DEVICE);
    let out = dir.path().join("out");
    let o = gyroemu(&["sweep", s(&cfg), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    assert!(stdout.starts_with("sweep: mode 1: f0 15000.0"), "{stdout}");
    for f in ["sweep.csv", "sweep.json", "bode.png"] {
        assert!(out.join(f).exists(), "{f}");
    }
    assert!(!out.join("gyroemu.lock").exists());

    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sweep.json")).unwrap()).unwrap();
    let mut models = Vec::new();
    for (k, (f0, q)) in [(15000.0, 1000.0), (15002.0, 800.0)]
        .into_iter()
        .enumerate()
    {
        let m = &summary["modes"][k];
        let num = |key: &str| m[key].as_f64().unwrap_or_else(|| panic!("{key}: {m}"));
        assert_eq!((num("configured_f0_hz"), num("configured_q")), (f0, q));
        // Within 1e-4 half-bandwidths and 1e-5 of Q (the hold's bias is ten times smaller).
        let hb = f0 / (2.0 * q);
        assert!((num("f0_hz") - f0).abs() < 1e-4 * hb, "{m}");
        assert!((num("q") / q - 1.0).abs() < 1e-5, "{m}");
        // (serde_json's default parser may be an ulp off the written text.)
        assert!((num("f0_minus_configured_hz") - (num("f0_hz") - f0)).abs() < 1e-9);
        assert!(num("f0_sigma_hz") > 0.0 && num("q_sigma") > 0.0);
        models.push((num("f0_hz"), num("q"), num("gain_re"), num("gain_im")));
    }
    let split = summary["mode_split_hz"].as_f64().unwrap();
    assert!((split - 2.0).abs() < 1e-3, "{split}");
    assert_eq!(summary["configured_mode_split_hz"].as_f64(), Some(2.0));
    assert_eq!(summary["frequencies"].as_u64(), Some(21));
    assert_eq!(summary["problems"].as_array().map(Vec::len), Some(0));
    let mx = &summary["matrix_fit"];
    assert!(
        (mx["f0_hz"][1].as_f64().unwrap() - 15002.0).abs() < 1e-3,
        "{mx}"
    );

    // The CSV: the documented columns, one row per frequency, and its fitted columns are the
    // JSON's model g j w / (w0^2 - w^2 + j w w0 / Q), written out here on its own.
    let text = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        [
            "freq_hz",
            "mag_mode1_db",
            "phase_mode1_deg",
            "mag_mode2_db",
            "phase_mode2_deg",
            "cross_mag_1to2_db",
            "cross_phase_1to2_deg",
            "cross_mag_2to1_db",
            "cross_phase_2to1_deg",
            "fit_mag_mode1_db",
            "fit_phase_mode1_deg",
            "fit_mag_mode2_db",
            "fit_phase_mode2_deg",
        ]
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 21);
    assert!(rows.windows(2).all(|w| w[1][0] > w[0][0]));
    let tau = std::f64::consts::TAU;
    for r in &rows {
        for (k, &(f0, q, gr, gi)) in models.iter().enumerate() {
            let (w0, w) = (tau * f0, tau * r[0]);
            // g j w / (a + j b) with a = w0^2 - w^2, b = w w0 / Q.
            let (a, b) = (w0 * w0 - w * w, w * w0 / q);
            let (nr, ni) = (-gi * w, gr * w);
            let d = a * a + b * b;
            let (re, im) = ((nr * a + ni * b) / d, (ni * a - nr * b) / d);
            let mag_db = 10.0 * (re * re + im * im).log10();
            assert!((r[9 + 2 * k] - mag_db).abs() < 1e-6, "{r:?}");
            assert!(
                (r[10 + 2 * k] - im.atan2(re).to_degrees()).abs() < 1e-6,
                "{r:?}"
            );
            // The measurement sits on its fit (a noiseless board; the hold's images, 1e-5 of
            // the peak at Q = 1000, show most on the skirts: 0.002 dB at 12 half-bandwidths).
            assert!((r[1 + 2 * k] - r[9 + 2 * k]).abs() < 1e-2, "{r:?}");
            assert!((r[2 + 2 * k] - r[10 + 2 * k]).abs() < 1e-2, "{r:?}");
        }
        // No quadrature coupling: no cross response at all (-inf dB, no phase).
        assert!(r[5] == f64::NEG_INFINITY && r[6].is_nan(), "{r:?}");
    }
}

#[test]
fn the_files_do_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(
        dir.path(),
        &DEVICE.replace("[drive]", "quadrature_coupling_rad2_s2 = 1e5\n[drive]"),
    );
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    for (out, threads) in [(&a, "1"), (&b, "2")] {
        let o = gyroemu(&["--threads", threads, "sweep", s(&cfg), "--out", s(out)]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    for f in ["sweep.csv", "sweep.json"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
}

#[test]
fn bad_sweep_keys_are_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    for (edit, needles) in [
        (
            "points = 21\nstart = 1.0",
            &["sweep.start", "unknown key", "did you mean `start_hz`?"][..],
        ),
        ("points = 2", &["sweep.points", "= 2", "from 5"][..]),
        (
            "points = 21\nstart_hz = 15010.0\nstop_hz = 15005.0",
            &["sweep.stop_hz", "= 15005", "above sweep.start_hz"][..],
        ),
        (
            "points = 21\nspacing = \"octave\"",
            &["sweep.spacing", "\"octave\""][..],
        ),
        // Work above the cap names the sweep's own keys, not the experiment's.
        (
            "points = 21\naverage_s = 1e7",
            &[
                "above the cap",
                "lower sweep.points, sweep.settle_s or sweep.average_s",
                "--force",
            ][..],
        ),
    ] {
        let cfg = config(dir.path(), &DEVICE.replace("points = 21", edit));
        let out = dir.path().join("never");
        let o = gyroemu(&["sweep", s(&cfg), "--out", s(&out)]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{edit}: {err}");
        for n in needles {
            assert!(err.contains(n), "{edit}: `{n}` missing from {err}");
        }
        assert!(!out.exists(), "{edit}: wrote {}", out.display());
    }
}

#[test]
fn the_configs_warnings_reach_sweep_json() {
    // A settling far below 10.6 time constants: the validation's warning (stderr, before any
    // sample) is also in sweep.json, where a script reading the fit finds it.
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), &format!("{DEVICE}settle_s = 0.01\n"));
    let out = dir.path().join("out");
    let o = gyroemu(&["sweep", s(&cfg), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sweep.json")).unwrap()).unwrap();
    let w: Vec<&str> = summary["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert!(
        w.iter()
            .any(|w| w.contains("sweep.settle_s = 0.01 is shorter")),
        "{w:?}"
    );
    let told = stderr(&o);
    assert!(w.iter().all(|w| told.contains(w)), "{w:?} against {told}");
}
