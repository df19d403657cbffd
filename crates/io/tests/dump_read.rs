//! Dumps read back: the samples bit for bit from SigMF and CSV, the rate, time origin, names,
//! units and operating point, and clear refusals of damaged files.

use gyroemu_io::{dump_source, read_dump, DumpSource, IoError, SignalRecorder};
use std::collections::BTreeMap;
use std::path::Path;

fn recorder() -> SignalRecorder {
    let names = vec!["drive1".to_string(), "tia1_v".into(), "v1_m_s".into()];
    let extra = BTreeMap::from([("f0_hz".to_string(), 15_000.0), ("omega_hz".into(), 0.25)]);
    let mut r = SignalRecorder::new(names, 2_400.0, 1_000, 300)
        .with_time_origin(99.0 / 240_000.0)
        .with_extra(extra);
    for n in 900..1_400u64 {
        let x = n as f64;
        r.record(n, &[(x * 0.1).sin(), 1e-7 * x.cos(), -x / 3.0]);
    }
    r
}

fn check_samples(d: &gyroemu_io::Dump, r: &SignalRecorder) {
    assert_eq!(d.channels.len(), 3);
    for k in 0..3 {
        let want = r.channel(k);
        assert_eq!(d.data[k].len(), 300);
        for (a, b) in d.data[k].iter().zip(&want) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }
    let names: Vec<&str> = d.channels.iter().map(|c| c.name.as_str()).collect();
    let units: Vec<&str> = d.channels.iter().map(|c| c.unit.as_str()).collect();
    assert_eq!(names, ["drive1", "tia1_v", "v1_m_s"]);
    assert_eq!(units, ["", "V", "m/s"]);
    assert_eq!(d.global_index, 1_000);
    assert_eq!(d.channel("tia1_v").map(<[f64]>::len), Some(300));
    // Frame k at t0 + (1000 + k)/fs.
    let t = 99.0 / 240_000.0 + 1_010.0 / 2_400.0;
    assert!((d.time_s(10) - t).abs() < 1e-12);
}

#[test]
fn sigmf_and_csv_read_back_bit_exact() {
    let dir = tempfile::tempdir().unwrap();
    let r = recorder();
    r.write(dir.path(), "dump_decimated").unwrap();
    let stem = dir.path().join("dump_decimated");
    for p in [
        stem.clone(),
        stem.with_extension("sigmf-meta"),
        stem.with_extension("sigmf-data"),
    ] {
        let d = read_dump(&p).unwrap();
        assert_eq!(d.sample_rate_hz, 2_400.0);
        assert_eq!(d.t0_s, 99.0 / 240_000.0);
        assert_eq!(d.extra.get("f0_hz"), Some(&15_000.0));
        assert_eq!(d.extra.get("omega_hz"), Some(&0.25));
        assert!(!d.extra.contains_key("t0_s"));
        check_samples(&d, &r);
    }
    let d = read_dump(&stem.with_extension("csv")).unwrap();
    // The rate from the sample and time columns: exact to the time stamps' rounding.
    assert!((d.sample_rate_hz / 2_400.0 - 1.0).abs() < 1e-9);
    assert!((d.t0_s - 99.0 / 240_000.0).abs() < 1e-9);
    assert!(d.extra.is_empty());
    check_samples(&d, &r);
}

#[test]
fn the_source_follows_the_extension_or_the_stem() {
    let dir = tempfile::tempdir().unwrap();
    let stem = dir.path().join("d");
    assert_eq!(
        dump_source(&stem.with_extension("sigmf-data")),
        DumpSource::Sigmf(stem.with_extension("sigmf-meta"))
    );
    assert_eq!(
        dump_source(&stem),
        DumpSource::Csv(stem.with_extension("csv"))
    );
    std::fs::write(stem.with_extension("sigmf-meta"), "{}").unwrap();
    assert_eq!(
        dump_source(&stem),
        DumpSource::Sigmf(stem.with_extension("sigmf-meta"))
    );
}

fn refused(path: &Path, needle: &str) {
    match read_dump(path) {
        Err(e @ IoError::Read { .. }) => {
            let m = e.to_string();
            assert!(m.contains(needle), "`{m}` lacks `{needle}`");
        }
        other => panic!("{path:?}: expected a read error, got {other:?}"),
    }
}

#[test]
fn damaged_dumps_are_refused_naming_the_file_and_the_rule() {
    let dir = tempfile::tempdir().unwrap();
    recorder().write(dir.path(), "x").unwrap();
    let p = |ext: &str| dir.path().join(format!("x.{ext}"));
    refused(&dir.path().join("missing.sigmf-meta"), "missing.sigmf-meta");
    refused(&dir.path().join("missing"), "missing.csv");
    // The data file changed after the metadata was written.
    let mut data = std::fs::read(p("sigmf-data")).unwrap();
    data[17] ^= 1;
    std::fs::write(p("sigmf-data"), &data).unwrap();
    refused(&p("sigmf-meta"), "SHA-512");
    data.truncate(data.len() - 8);
    std::fs::write(p("sigmf-data"), &data).unwrap();
    refused(&p("sigmf-meta"), "whole number of frames");
    let meta = std::fs::read_to_string(p("sigmf-meta")).unwrap();
    std::fs::write(p("sigmf-meta"), meta.replace("rf64_le", "cf32_le")).unwrap();
    refused(&p("sigmf-meta"), "core:datatype = `cf32_le`");
    // Optional fields present with a wrong value are refused, not read as their defaults.
    for (from, to, needle) in [
        (
            "\"core:num_channels\": 3",
            "\"core:num_channels\": 1e19",
            "core:num_channels = 1e+19: must be an integer 1..=65535",
        ),
        (
            "\"core:num_channels\": 3",
            "\"core:num_channels\": 0",
            "core:num_channels = 0",
        ),
        (
            "\"core:global_index\": 1000",
            "\"core:global_index\": -1",
            "core:global_index = -1: must be an integer >= 0",
        ),
        (
            "\"gyroemu:t0_s\": ",
            "\"gyroemu:t0_s\": \"soon\", \"x\": ",
            "gyroemu:t0_s = \"soon\": must be a finite number",
        ),
    ] {
        assert!(meta.contains(from), "`{from}` not in {meta}");
        std::fs::write(p("sigmf-meta"), meta.replacen(from, to, 1)).unwrap();
        refused(&p("sigmf-meta"), needle);
    }
    std::fs::write(p("sigmf-meta"), "{ not json").unwrap();
    refused(&p("sigmf-meta"), "not JSON");
    std::fs::write(p("csv"), "a,b\n1,2\n").unwrap();
    refused(&p("csv"), "sample,time_s");
    std::fs::write(p("csv"), "sample,time_s,x_v\n0,0,1\n1,0.5,oops\n").unwrap();
    refused(&p("csv"), "line 3, column `x_v`: `oops`");
    std::fs::write(p("csv"), "sample,time_s,x_v\n0,0,1\n").unwrap();
    refused(&p("csv"), "rate cannot be read");
}
