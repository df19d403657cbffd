//! SigMF recordings checked against independent truths: bytes decoded by hand, JSON parsed by
//! serde_json, SHA-512 recomputed with sha2 on the file as read back, FIPS known answers.

mod common;
use common::entries;
use gyroemu_io::{write_sigmf, IoError, SigmfMeta, SignalRecorder};
use serde_json::Value;
use sha2::{Digest, Sha512};
use std::path::Path;

/// Deterministic f64 bit patterns of every kind: signed zeros, subnormals, infinities, NaN
/// payloads, extremes, then xorshift bit patterns.
fn weird_floats(n: usize) -> Vec<f64> {
    let mut out = vec![
        0.0,
        -0.0,
        5e-324,
        -2.2e-308,
        f64::MAX,
        f64::MIN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::from_bits(0x7ff8_0000_0000_0001),
        f64::from_bits(0xfff4_0000_0000_dead),
        0.1,
    ];
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    while out.len() < n {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        out.push(f64::from_bits(s));
    }
    out.truncate(n);
    out
}

/// Little-endian f64 words of a file, decoded without the writer's code.
fn read_f64_le(path: &Path) -> Vec<u64> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(bytes.len() % 8, 0, "data file is not whole f64 words");
    bytes
        .chunks_exact(8)
        .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn read_meta(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn data_file_is_bit_exact_interleaved_input() {
    let dir = tempfile::tempdir().unwrap();
    let a = weird_floats(2000);
    let b: Vec<f64> = weird_floats(2001)[1..].to_vec();
    let meta = SigmfMeta::new(48_000.0, &[("a", "V"), ("b", "")]);
    let files = write_sigmf(dir.path(), "rec", &meta, &[&a, &b]).unwrap();
    let words = read_f64_le(&files.data_path);
    assert_eq!(words.len(), 2 * a.len());
    for i in 0..a.len() {
        assert_eq!(words[2 * i], a[i].to_bits(), "a[{i}]");
        assert_eq!(words[2 * i + 1], b[i].to_bits(), "b[{i}]");
    }
}

#[test]
fn three_channels_interleave_frame_by_frame() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, c) = ([1.0, 2.0], [10.0, 20.0], [100.0, 200.0]);
    let meta = SigmfMeta::new(1.0, &[("a", ""), ("b", ""), ("c", "")]);
    let files = write_sigmf(dir.path(), "x", &meta, &[&a, &b, &c]).unwrap();
    let expected: Vec<u8> = [1.0f64, 10.0, 100.0, 2.0, 20.0, 200.0]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    assert_eq!(std::fs::read(&files.data_path).unwrap(), expected);
    assert_eq!(entries(dir.path()), ["x.sigmf-data", "x.sigmf-meta"]);
}

#[test]
fn meta_has_the_required_sigmf_fields() {
    let dir = tempfile::tempdir().unwrap();
    let x = [0.5, -0.25, 3.0];
    let mut meta = SigmfMeta::new(1234.5678, &[("q1_m", "m"), ("v1_m_s", "m/s"), ("n", "")]);
    meta.description = "unit test".into();
    meta.global_index = 77;
    meta.t0_s = 1.5e-3;
    let files = write_sigmf(dir.path(), "m", &meta, &[&x, &x, &x]).unwrap();
    let m = read_meta(&files.meta_path);
    let g = &m["global"];
    assert_eq!(g["core:datatype"], "rf64_le");
    assert_eq!(g["core:version"], "1.2.0");
    assert_eq!(g["core:sample_rate"].as_f64(), Some(1234.5678));
    assert_eq!(g["core:num_channels"], 3);
    assert_eq!(g["core:recorder"], "gyroemu");
    assert_eq!(g["core:description"], "unit test");
    assert!(g["core:hw"].as_str().unwrap().contains("gyroemu"));
    let ext = g["core:extensions"].as_array().unwrap();
    assert_eq!(ext.len(), 1);
    assert_eq!(ext[0]["name"], "gyroemu");
    assert_eq!(ext[0]["optional"], true);
    assert!(ext[0]["version"].is_string());
    let ch = g["gyroemu:channels"].as_array().unwrap();
    let pairs: Vec<(&str, &str)> = ch
        .iter()
        .map(|c| (c["name"].as_str().unwrap(), c["unit"].as_str().unwrap()))
        .collect();
    assert_eq!(pairs, [("q1_m", "m"), ("v1_m_s", "m/s"), ("n", "")]);
    assert_eq!(g["gyroemu:t0_s"].as_f64(), Some(1.5e-3));
    let caps = m["captures"].as_array().unwrap();
    assert_eq!(caps.len(), 1);
    assert_eq!(caps[0]["core:sample_start"], 0);
    assert_eq!(caps[0]["core:global_index"], 77);
    assert_eq!(m["annotations"], serde_json::json!([]));
    // Determinism: no wall-clock field anywhere.
    let text = std::fs::read_to_string(&files.meta_path).unwrap();
    assert!(!text.contains("datetime"), "{text}");
}

#[test]
fn meta_sha512_equals_an_independent_hash_of_the_file() {
    let dir = tempfile::tempdir().unwrap();
    // 3 x 5000 samples = 120 000 bytes: many internal blocks plus a partial one.
    let a = weird_floats(5000);
    let meta = SigmfMeta::new(10.0, &[("a", ""), ("b", ""), ("c", "")]);
    let files = write_sigmf(dir.path(), "h", &meta, &[&a, &a, &a]).unwrap();
    let truth = hex(&Sha512::digest(std::fs::read(&files.data_path).unwrap()));
    let m = read_meta(&files.meta_path);
    assert_eq!(m["global"]["core:sha512"], truth.as_str());
    assert_eq!(files.sha512_hex, truth);
}

#[test]
fn zero_frames_give_an_empty_file_with_the_fips_empty_hash() {
    let dir = tempfile::tempdir().unwrap();
    let empty: [f64; 0] = [];
    let meta = SigmfMeta::new(1.0, &[("a", "")]);
    let files = write_sigmf(dir.path(), "e", &meta, &[&empty]).unwrap();
    assert!(std::fs::read(&files.data_path).unwrap().is_empty());
    // SHA-512 of the empty message (FIPS 180-2 / NIST example values).
    assert_eq!(
        files.sha512_hex,
        "cf83e1357eefb8bdf1542850d66d8007d620e4050b5715dc83f4a921d36ce9ce\
         47d0d13c5d85f2b0ff8318d2877eec2f63b931bd47417a81a538327af927da3e"
    );
}

#[test]
fn equal_inputs_give_byte_identical_files() {
    let (d1, d2) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let a = weird_floats(300);
    let meta = SigmfMeta::new(2.5e6, &[("a", "V")]);
    write_sigmf(d1.path(), "r", &meta, &[&a]).unwrap();
    write_sigmf(d2.path(), "r", &meta, &[&a]).unwrap();
    for f in ["r.sigmf-data", "r.sigmf-meta"] {
        assert_eq!(
            std::fs::read(d1.path().join(f)).unwrap(),
            std::fs::read(d2.path().join(f)).unwrap(),
            "{f}"
        );
    }
}

/// Asserts `r` is a SigmfInvalid whose message contains `needle`, and nothing was written.
fn assert_invalid<T: std::fmt::Debug>(r: Result<T, IoError>, needle: &str, dir: &Path) {
    let err = r.unwrap_err();
    assert!(matches!(err, IoError::SigmfInvalid { .. }), "{err}");
    let msg = err.to_string();
    assert!(msg.contains(needle), "{msg:?} lacks {needle:?}");
    assert!(msg.contains(".sigmf-data"), "{msg}");
    assert!(entries(dir).is_empty(), "{:?}", entries(dir));
}

#[test]
fn malformed_requests_are_clear_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let one = SigmfMeta::new(1.0, &[("a", "")]);
    let two = SigmfMeta::new(1.0, &[("a", ""), ("b", "")]);
    let zero = SigmfMeta::new(1.0, &[]);
    assert_invalid(write_sigmf(d, "s", &zero, &[]), "no channels", d);
    assert_invalid(
        write_sigmf(d, "s", &two, &[&[1.0, 2.0], &[1.0]]),
        "channel 1 has 1 samples but channel 0 has 2",
        d,
    );
    assert_invalid(write_sigmf(d, "s", &one, &[&[1.0], &[2.0]]), "names 1", d);
    for fs in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let mut m = one.clone();
        m.sample_rate_hz = fs;
        assert_invalid(write_sigmf(d, "s", &m, &[&[1.0]]), "sample_rate_hz", d);
    }
    let mut m = one.clone();
    m.t0_s = f64::NAN;
    assert_invalid(write_sigmf(d, "s", &m, &[&[1.0]]), "t0_s", d);
}

#[test]
fn missing_directory_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let gone = dir.path().join("absent");
    let meta = SigmfMeta::new(1.0, &[("a", "")]);
    let err = write_sigmf(&gone, "s", &meta, &[&[1.0]]).unwrap_err();
    assert!(matches!(err, IoError::TempCreate { .. }), "{err}");
    assert!(entries(dir.path()).is_empty());
}

#[test]
fn recorder_writes_sigmf_beside_csv_and_leaves_out_a_wav_float32_cannot_hold() {
    let dir = tempfile::tempdir().unwrap();
    let names = vec!["tia1_v".to_string(), "q1_m".into(), "mix1_i1".into()];
    let fs_hz = 12_345.678;
    let mut r = SignalRecorder::new(names, fs_hz, 100, 50).with_time_origin(2e-4);
    let x = weird_floats(600);
    for n in 0..200u64 {
        // Skip index 120: the recorder fills that frame with NaN.
        if n != 120 {
            let k = 3 * n as usize;
            r.record(n, &x[k..k + 3]);
        }
    }
    r.write(dir.path(), "dump").unwrap();
    // Values float32 cannot hold (f64::MAX, subnormals) leave out the WAV copy only.
    assert!(r.wav_range_problem().is_some());
    assert_eq!(
        entries(dir.path()),
        ["dump.csv", "dump.sigmf-data", "dump.sigmf-meta"]
    );
    let words = read_f64_le(&dir.path().join("dump.sigmf-data"));
    assert_eq!(words.len(), 3 * 50);
    for i in 0..50usize {
        let n = 100 + i;
        for k in 0..3 {
            let got = f64::from_bits(words[3 * i + k]);
            if n == 120 {
                assert!(got.is_nan(), "gap frame must be NaN");
            } else {
                assert_eq!(words[3 * i + k], x[3 * n + k].to_bits(), "n={n} k={k}");
            }
        }
    }
    let m = read_meta(&dir.path().join("dump.sigmf-meta"));
    let g = &m["global"];
    assert_eq!(g["core:sample_rate"].as_f64(), Some(fs_hz));
    assert_eq!(g["core:num_channels"], 3);
    assert_eq!(g["gyroemu:t0_s"].as_f64(), Some(2e-4));
    assert_eq!(m["captures"][0]["core:global_index"], 100);
    let units: Vec<&str> = g["gyroemu:channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["unit"].as_str().unwrap())
        .collect();
    assert_eq!(units, ["V", "m", ""]);
    let truth = hex(&Sha512::digest(
        std::fs::read(dir.path().join("dump.sigmf-data")).unwrap(),
    ));
    assert_eq!(g["core:sha512"], truth.as_str());
}

#[test]
fn recorder_units_given_for_unsuffixed_names_reach_the_sigmf_meta() {
    // A drive's name carries no unit to read: the caller gives it, and the meta keeps it.
    let dir = tempfile::tempdir().unwrap();
    let mut r = SignalRecorder::new(vec!["drive1".into(), "tia1_v".into()], 1000.0, 0, 4)
        .with_units(&["m/s²", "V"]);
    for n in 0..4 {
        r.record(n, &[1.0, 2.0]);
    }
    assert_eq!(r.units(), ["m/s²", "V"]);
    r.write(dir.path(), "d").unwrap();
    let m = read_meta(&dir.path().join("d.sigmf-meta"));
    let units: Vec<&str> = m["global"]["gyroemu:channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["unit"].as_str().unwrap())
        .collect();
    assert_eq!(units, ["m/s²", "V"]);
    // The reader gives them back.
    let d = gyroemu_io::read_sigmf(&dir.path().join("d.sigmf-meta")).unwrap();
    let read: Vec<&str> = d.channels.iter().map(|c| c.unit.as_str()).collect();
    assert_eq!(read, ["m/s²", "V"]);
}

#[test]
fn recorder_with_no_channels_fails_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let r = SignalRecorder::new(vec![], 1000.0, 0, 10);
    assert!(r.write(dir.path(), "none").is_err());
    assert!(entries(dir.path()).is_empty());
}

/// A rate a WAV header cannot hold (below 0.5 Hz, or a byte rate past 2^32) loses only the
/// WAV: the CSV and SigMF carry any rate, and the paths returned say what was written. Before,
/// the refusal came after the whole emulation and every result was lost.
#[test]
fn a_rate_no_wav_can_hold_writes_the_csv_and_sigmf_only() {
    use gyroemu_io::wav_f32_rate_problem;
    // 0.4 Hz rounds to 0; 1.5 Hz to 2 (a third off: every frequency read from the file
    // would be); 1e8 Hz x 12 channels x 4 bytes is 4.8e9 > 2^32 - 1.
    for (fs_hz, ch) in [(0.4, 2usize), (1.5, 1), (1e8, 12)] {
        let why = wav_f32_rate_problem(fs_hz, ch as u64).expect("no WAV rate");
        assert!(why.contains("WAV"), "{why}");
        let dir = tempfile::tempdir().unwrap();
        let names = (0..ch).map(|k| format!("lp_i{k}")).collect();
        let mut r = SignalRecorder::new(names, fs_hz, 0, 8);
        for n in 0..8u64 {
            r.record(n, &vec![n as f64; ch]);
        }
        let files = r.write(dir.path(), "d").unwrap();
        assert_eq!(
            entries(dir.path()),
            ["d.csv", "d.sigmf-data", "d.sigmf-meta"],
            "{fs_hz} Hz"
        );
        assert_eq!(files.len(), 3);
        let meta: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("d.sigmf-meta")).unwrap())
                .unwrap();
        assert_eq!(meta["global"]["core:sample_rate"].as_f64(), Some(fs_hz));
    }
    // The edges: a whole-Hz rate within 1e-4 (0.5 Hz at 5 kHz), so 5000.5 Hz but not 4999.5;
    // 240 kHz / 76 (3.3e-5 off); 4 channels of 4 bytes fit up to (2^32 - 1)/16 Hz.
    assert_eq!(wav_f32_rate_problem(5000.5, 1), None);
    assert!(wav_f32_rate_problem(4999.5, 1).is_some());
    assert_eq!(wav_f32_rate_problem(240_000.0 / 76.0, 4), None);
    assert_eq!(wav_f32_rate_problem(268_435_455.0, 4), None);
    assert!(wav_f32_rate_problem(268_435_456.0, 4).is_some());
}

/// float32 holds 1.2e-38 .. 3.4e38 at full precision: a sample outside it would read inf, 0
/// or a subnormal of few digits in the WAV copy (a drive of 1e-60 was a silent WAV of zeros,
/// one of 1e45 a WAV of inf), so that recording gets no WAV and says why; 0 and ordinary
/// values keep it.
#[test]
fn a_sample_float32_cannot_hold_writes_no_wav_and_says_why() {
    let write = |x: f64| {
        let dir = tempfile::tempdir().unwrap();
        let mut r = SignalRecorder::new(vec!["a_v".into(), "b_v".into()], 1000.0, 0, 4);
        for n in 0..4u64 {
            r.record(n, &[0.0, if n == 2 { x } else { 1.0 }]);
        }
        r.write(dir.path(), "d").unwrap();
        (r.wav_range_problem(), entries(dir.path()))
    };
    for x in [1e-60, -1e45, 1e-39, f64::MAX] {
        let (why, files) = write(x);
        let why = why.unwrap_or_else(|| panic!("{x:e} passed"));
        assert!(
            why.contains("`b_v`") && why.contains(&format!("{x:e}")),
            "{why}"
        );
        assert_eq!(files, ["d.csv", "d.sigmf-data", "d.sigmf-meta"], "{x:e}");
    }
    for x in [0.0, -0.0, 1e-30, 3e38, f64::NAN, f64::INFINITY] {
        let (why, files) = write(x);
        assert_eq!(why, None, "{x:e}");
        assert_eq!(files.len(), 4, "{x:e}: {files:?}");
    }
}

/// The numbers under a recording's `gyroemu:` keys are read as written or refused, never
/// dropped: a clip count edited into a string had been dropped without a word, and the
/// clipped window then read clean; negative or fractional counts and a negative carrier were
/// taken. Each bad value is refused naming its key; the numbers as gyroemu writes them read.
#[test]
fn gyroemu_keys_that_are_not_their_numbers_are_refused_not_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let mut r = SignalRecorder::new(vec!["tia1_v".into()], 1000.0, 0, 4);
    for n in 0..4 {
        r.record(n, &[n as f64]);
    }
    r.write(dir.path(), "d").unwrap();
    let meta_path = dir.path().join("d.sigmf-meta");
    let written = read_meta(&meta_path);
    let with = |key: &str, v: Value| {
        let mut m = written.clone();
        m["global"][format!("gyroemu:{key}")] = v;
        std::fs::write(&meta_path, serde_json::to_vec(&m).unwrap()).unwrap();
        gyroemu_io::read_sigmf(&meta_path)
    };
    use serde_json::json;
    let good = with("adc_clipped_samples_mode1", json!(2800.0)).unwrap();
    assert_eq!(good.extra["adc_clipped_samples_mode1"], 2800.0);
    let good = with("carrier_hz", json!(15000.0)).unwrap();
    assert_eq!(good.extra["carrier_hz"], 15000.0);
    assert_eq!(
        with("rate_dps", json!(-25.0)).unwrap().extra["rate_dps"],
        -25.0
    );
    for (key, v, rule) in [
        (
            "adc_clipped_samples_mode1",
            json!("2800"),
            "a finite number",
        ),
        (
            "adc_clipped_samples_mode1",
            json!(-3.0),
            "a whole count >= 0",
        ),
        ("tia_railed_samples_mode2", json!(3.5), "a whole count >= 0"),
        ("events_counted_samples", json!(null), "a finite number"),
        ("carrier_hz", json!(-1.0), "a frequency > 0"),
        ("omega_hz", json!(-0.5), "a frequency >= 0"),
        ("decimation", json!(0.0), "a whole number >= 1"),
        ("rate_dps", json!([25.0]), "a finite number"),
    ] {
        let e = with(key, v.clone()).unwrap_err().to_string();
        assert!(
            e.contains(&format!("gyroemu:{key} = {v}: must be {rule}")),
            "{key} = {v}: {e}"
        );
    }
}
