//! Round trips through independent readers (csv crate, serde_json, hound).

mod common;
use common::entries;
use gyroemu_io::{write_csv, write_json, write_wav_f32, CsvCell, CsvTable, IoError};
use serde::{Deserialize, Serialize};

/// Deterministic stream of arbitrary finite f64 bit patterns (all exponents, subnormals).
fn weird_floats(n: usize) -> Vec<f64> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut out = vec![
        0.0,
        -0.0,
        1.0,
        0.1,
        1e-5,
        1e16,
        5e-324,
        f64::MAX,
        f64::MIN_POSITIVE,
    ];
    while out.len() < n {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let x = f64::from_bits(s);
        if x.is_finite() {
            out.push(x);
        }
    }
    out
}

#[test]
fn csv_rereads_bit_exact_with_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    let xs = weird_floats(2000);
    let table = CsvTable {
        headers: vec!["i".into(), "x_v".into(), "note".into()],
        rows: xs
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                vec![
                    CsvCell::Int(i as i64 - 7),
                    CsvCell::F64(x),
                    CsvCell::Text(format!("a,\"b\" {i}")),
                ]
            })
            .collect(),
    };
    write_csv(&path, &table).unwrap();

    let mut rd = csv::Reader::from_path(&path).unwrap();
    let hdr: Vec<String> = rd.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(hdr, table.headers);
    let mut n = 0;
    for (i, rec) in rd.records().enumerate() {
        let rec = rec.unwrap();
        assert_eq!(rec[0].parse::<i64>().unwrap(), i as i64 - 7);
        let x: f64 = rec[1].parse().unwrap();
        assert_eq!(
            x.to_bits(),
            xs[i].to_bits(),
            "row {i}: {} vs {:e}",
            &rec[1],
            xs[i]
        );
        assert_eq!(&rec[2], format!("a,\"b\" {i}"));
        n += 1;
    }
    assert_eq!(n, xs.len());
    assert_eq!(entries(dir.path()), vec!["t.csv"]);
}

#[test]
fn csv_wrong_row_width_is_refused_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.csv");
    let table = CsvTable {
        headers: vec!["a".into(), "b".into()],
        rows: vec![vec![CsvCell::Int(1)]],
    };
    let err = write_csv(&path, &table).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::CsvShape {
                row: 0,
                got: 1,
                expected: 2,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("bad.csv"));
    assert!(entries(dir.path()).is_empty());
}

#[derive(Serialize, Deserialize, Debug, PartialEq)]
struct Run {
    name: String,
    f0_hz: f64,
    gains: Vec<f64>,
    nested: Option<Box<Run>>,
}

#[test]
fn json_round_trips_pretty_with_newline() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.json");
    let inner = Run {
        name: "inner".into(),
        f0_hz: 0.1,
        gains: vec![],
        nested: None,
    };
    let v = Run {
        name: "x \"q\"".into(),
        f0_hz: 20_123.456_789,
        gains: weird_floats(50),
        nested: Some(Box::new(inner)),
    };
    write_json(&path, &v).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.ends_with("}\n"));
    assert!(text.contains("\n  \"f0_hz\""), "not pretty: {text}");
    // serde_json's own parser (without `float_roundtrip`) can be 1 ulp off on extreme exponents,
    // so the structure is checked with it and the float text with std's correctly rounded parser.
    let back: Run = serde_json::from_str(&text).unwrap();
    assert_eq!(back.name, v.name);
    assert_eq!(back.nested, v.nested);
    assert_eq!(back.gains.len(), v.gains.len());
    let start = text.find("\"gains\": [").unwrap() + "\"gains\": [".len();
    let body = &text[start..start + text[start..].find(']').unwrap()];
    let parsed: Vec<f64> = body.split(',').map(|t| t.trim().parse().unwrap()).collect();
    let bits = |xs: &[f64]| xs.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&parsed), bits(&v.gains));
    let f0_hz: f64 = serde_json::from_str::<serde_json::Value>(&text).unwrap()["f0_hz"]
        .as_f64()
        .unwrap();
    assert_eq!(f0_hz, v.f0_hz);
}

#[test]
fn wav_rereads_with_hound() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.wav");
    let n = 1234;
    let a: Vec<f64> = (0..n).map(|i| (i as f64 * 0.01).sin() * 3.0).collect(); // exceeds +-1 on purpose
    let b: Vec<f64> = (0..n).map(|i| 1e-9 * i as f64).collect();
    let c: Vec<f64> = weird_floats(n)
        .into_iter()
        .map(|x| x.clamp(-1e30, 1e30))
        .collect();
    write_wav_f32(&path, 48_000, &[&a, &b, &c]).unwrap();

    let len = std::fs::metadata(&path).unwrap().len();
    assert_eq!(len, gyroemu_io::WAV_F32_HEADER_BYTES + 3 * 4 * n as u64);
    let mut rd = hound::WavReader::open(&path).unwrap();
    let spec = rd.spec();
    assert_eq!(
        (spec.channels, spec.sample_rate, spec.bits_per_sample),
        (3, 48_000, 32)
    );
    assert_eq!(spec.sample_format, hound::SampleFormat::Float);
    assert_eq!(rd.duration() as usize, n);
    let s: Vec<f32> = rd.samples::<f32>().map(Result::unwrap).collect();
    assert_eq!(s.len(), 3 * n);
    for i in 0..n {
        for (k, ch) in [&a, &b, &c].iter().enumerate() {
            assert_eq!(
                s[3 * i + k].to_bits(),
                (ch[i] as f32).to_bits(),
                "frame {i} channel {k}"
            );
        }
    }
}

#[test]
fn wav_refuses_bad_requests_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.wav");
    let a = [0.0; 4];
    let b = [0.0; 5];
    let e = write_wav_f32(&path, 1000, &[&a, &b]).unwrap_err();
    assert!(e.to_string().contains("channel 1 has 5"), "{e}");
    assert!(write_wav_f32(&path, 1000, &[]).is_err());
    assert!(write_wav_f32(&path, 0, &[&a]).is_err());
    assert!(entries(dir.path()).is_empty());
}

#[test]
fn recorder_csv_is_byte_for_byte_the_table_writers_csv() {
    // The dump's hand-laid text against the csv crate + std formatting path of write_csv.
    use gyroemu_io::SignalRecorder;
    let dir = tempfile::tempdir().unwrap();
    let names = vec!["a_v".to_string(), "b".to_string(), "q1_m".to_string()];
    let (fs, start) = (240_000.0, 12_345u64);
    let mut rec = SignalRecorder::new(names.clone(), fs, start, 500).with_time_origin(3.7e-4);
    let mut s: u64 = 0x1234_5678_9abc_def1;
    let mut table = CsvTable {
        headers: ["sample", "time_s"]
            .iter()
            .map(|h| h.to_string())
            .chain(names.iter().cloned())
            .collect(),
        rows: Vec::new(),
    };
    for n in start..start + 500 {
        let mut frame = [0.0; 3];
        for v in frame.iter_mut() {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            *v = match n % 7 {
                0 => f64::from_bits(s),
                1 => 0.0,
                _ => (s >> 11) as f64 * 1e-19 - 1e-3,
            };
        }
        rec.record(n, &frame);
        let mut row = vec![CsvCell::Int(n as i64), CsvCell::F64(3.7e-4 + n as f64 / fs)];
        row.extend(frame.iter().map(|&v| CsvCell::F64(v)));
        table.rows.push(row);
    }
    rec.write_csv(&dir.path().join("fast.csv")).unwrap();
    write_csv(&dir.path().join("ref.csv"), &table).unwrap();
    let fast = std::fs::read(dir.path().join("fast.csv")).unwrap();
    let reference = std::fs::read(dir.path().join("ref.csv")).unwrap();
    assert_eq!(
        String::from_utf8(fast).unwrap(),
        String::from_utf8(reference).unwrap()
    );
}
