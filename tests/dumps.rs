//! Signal dumps: the window holds exactly the requested samples, and the recorded drive equals
//! its closed form F1 cos(w0 t), F2 sin(w0 t) at the sample instants.

mod common;
use gyroemu::config::parse_config;
use gyroemu::experiment::run_sweep;
use std::f64::consts::PI;

fn read_csv(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn coriolis_dump_window_and_drive_closed_form() {
    let (f0, fs, f1, f2) = (15e3, 240e3, 1.0, 0.5);
    let text = format!(
        r#"
[device]
f0_hz = {f0}
q = 2000.0
angular_gain = 1.0
[drive]
f1 = {f1}
f2 = {f2}
[board]
fs_hz = {fs}
lpf_cutoff_hz = 200.0
decimation = 100
[experiment]
kind = "coriolis"
rates_dps = [50.0]
settle_s = 0.1
average_s = 0.1
[dump]
rate_dps = 50.0
start_s = 0.05
duration_s = 0.01
nodes = ["drive", "velocity", "tia", "stage1", "lowpass", "stage2"]
"#
    );
    let cfg = parse_config(&text).unwrap();
    cfg.validate().unwrap();
    let dir = tempfile::tempdir().unwrap();
    run_sweep(&cfg, &|_, _| {}, Some(dir.path())).unwrap();
    let (h, rows) = read_csv(&dir.path().join("dump_fullrate.csv"));
    assert_eq!(&h[..4], &["sample", "time_s", "drive1", "drive2"]);
    assert!(
        h.contains(&"v1_m_s".to_string())
            && h.contains(&"tia2_v".to_string())
            && h.contains(&"mix1_q2".to_string())
    );
    assert_eq!(rows.len(), (0.01 * fs) as usize);
    let start = (0.05 * fs) as u64;
    for (i, r) in rows.iter().enumerate() {
        let n = start + i as u64;
        assert_eq!(r[0], n as f64);
        assert!((r[1] - n as f64 / fs).abs() < 1e-15);
        let ph = 2.0 * PI * ((n % 16) as f64) / 16.0; // f0 = fs/16 exactly
        assert!((r[2] - f1 * ph.cos()).abs() < 1e-14, "drive1 at {n}");
        assert!((r[3] - f2 * ph.sin()).abs() < 1e-14, "drive2 at {n}");
    }
    let (hd, rows_d) = read_csv(&dir.path().join("dump_decimated.csv"));
    assert!(hd.contains(&"lp_i1".to_string()) && hd.contains(&"c2_q".to_string()));
    assert_eq!(rows_d.len(), (0.01 * fs / 100.0) as usize);
    // Decimated sample k is formed at input sample kM + M - 1.
    for r in &rows_d {
        let expect = (r[0] * 100.0 + 99.0) / fs;
        assert!((r[1] - expect).abs() < 1e-12, "time_s {} vs {expect}", r[1]);
    }
    for stem in ["dump_fullrate.wav", "dump_decimated.wav"] {
        assert!(dir.path().join(stem).metadata().unwrap().len() > 44);
    }
}

#[test]
fn dumps_of_points_not_emulated_or_past_their_run_are_refused() {
    let base = |rate: f64, start: f64, dur: f64| {
        format!(
            r#"
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
kind = "rotating"
rates_dps = [100.0, 150.0]
settle_s = 0.5
average_s = 2.0
[dump]
rate_dps = {rate}
start_s = {start}
duration_s = {dur}
nodes = ["drive"]
"#
        )
    };
    // 0 is not emulated in a rotating sweep.
    let e = parse_config(&base(0.0, 0.1, 0.01))
        .unwrap()
        .validate()
        .unwrap_err()
        .to_string();
    assert!(e.contains("dump.rate_dps"), "{e}");
    // At 100 deg/s a half modulation period is 1.8 s, so of the 2 s asked one half period
    // (1.8 s) is averaged and the point's run ends at 0.5 + 1.8 = 2.3 s.
    let e = parse_config(&base(100.0, 2.35, 0.01))
        .unwrap()
        .validate()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`dump.start_s` = 2.35") && e.contains("run"),
        "{e}"
    );
    // A start inside the run whose window ends past it: the duration is at fault.
    let e = parse_config(&base(100.0, 2.25, 0.1))
        .unwrap()
        .validate()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`dump.duration_s` = 0.1") && e.contains("run"),
        "{e}"
    );
    parse_config(&base(100.0, 2.2, 0.01))
        .unwrap()
        .validate()
        .unwrap();
}

#[test]
fn a_dump_whose_output_rate_no_wav_holds_is_warned_and_written_without_wav() {
    // Decimation by 600000 puts the output at 0.4 Hz, which rounds to no WAV rate: the
    // validation says so before any sample, and the run writes the CSV and SigMF (the WAV
    // refusal used to come after the whole emulation, losing every result).
    let text = r#"
[device]
f0_hz = 15000.0
q = 2000.0
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
[board]
fs_hz = 240000.0
lpf_cutoff_hz = 0.1
decimation = 600000
[experiment]
kind = "coriolis"
rates_dps = [100.0]
settle_s = 10.0
average_s = 5.0
[dump]
rate_dps = 100.0
start_s = 0.0
duration_s = 12.0
nodes = ["lowpass"]
"#;
    let cfg = parse_config(text).unwrap();
    let w = cfg.validate().unwrap();
    assert!(
        w.iter()
            .any(|w| w.contains("decimated recording gets no WAV")
                && w.contains("sample rate 0.4 Hz")),
        "{w:?}"
    );
    let dir = tempfile::tempdir().unwrap();
    run_sweep(&cfg, &|_, _| {}, Some(dir.path())).unwrap();
    let (h, rows) = read_csv(&dir.path().join("dump_decimated.csv"));
    assert!(h.contains(&"lp_i1".to_string()));
    assert_eq!(rows.len(), (12.0f64 * 0.4).round() as usize);
    assert!(dir.path().join("dump_decimated.sigmf-data").exists());
    assert!(!dir.path().join("dump_decimated.wav").exists());
}
