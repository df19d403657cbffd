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
    // The operating point (and converter events) from the metadata beside it.
    assert_eq!(d.extra.get("f0_hz"), Some(&15_000.0));
    assert_eq!(d.extra.get("omega_hz"), Some(&0.25));
    assert_eq!(d.notes.len(), 1, "{:?}", d.notes);
    assert!(
        d.notes[0].contains("holds the same samples"),
        "{:?}",
        d.notes
    );
    check_samples(&d, &r);
}

/// A CSV read alone, or beside metadata of another recording, takes no events from it and
/// says that a clipped window would read clean.
#[test]
fn a_csv_takes_the_metadata_beside_it_only_for_the_same_samples() {
    let unknown = "a clipped window reads clean here";
    let check = |edit: &dyn Fn(&Path), needle: &str| {
        let dir = tempfile::tempdir().unwrap();
        recorder().write(dir.path(), "x").unwrap();
        edit(dir.path());
        let d = read_dump(&dir.path().join("x.csv")).unwrap();
        assert!(d.extra.is_empty(), "{needle}: {:?}", d.extra);
        assert_eq!(d.notes.len(), 1, "{:?}", d.notes);
        let note = &d.notes[0];
        assert!(note.contains(needle) && note.contains(unknown), "{note}");
    };
    let meta = |dir: &Path| dir.join("x.sigmf-meta");
    check(
        &|dir| std::fs::remove_file(meta(dir)).unwrap(),
        "a CSV carries no converter event counts",
    );
    check(
        &|dir| std::fs::write(meta(dir), "{").unwrap(),
        "could not be read (",
    );
    // Data of another length: told from its size, unread.
    check(
        &|dir| {
            let data = dir.join("x.sigmf-data");
            let bytes = std::fs::read(&data).unwrap();
            std::fs::write(&data, &bytes[..bytes.len() - 24]).unwrap();
        },
        "holds another recording (7176 bytes of data, the CSV's samples 7200)",
    );
    // One sample's last digit edited in the CSV: still a valid CSV, not the same samples.
    check(
        &|dir| {
            let path = dir.join("x.csv");
            let mut rows = lines(&path);
            let cells: Vec<String> = rows[5].split(',').map(String::from).collect();
            let v: f64 = cells[4].parse().unwrap();
            rows[5] = [&cells[..4], &[format!("{:?}", v * (1.0 + 1e-15))]]
                .concat()
                .join(",");
            write_lines(&path, &rows);
        },
        "other sample values",
    );
    check(
        &|dir| {
            edit_meta(&meta(dir), |m| {
                m["captures"][0]["core:global_index"] = serde_json::json!(1_001);
            });
        },
        "300 samples from index 1001, the CSV's 300 from 1000",
    );
    check(
        &|dir| {
            edit_meta(&meta(dir), |m| {
                m["global"]["core:sample_rate"] = serde_json::json!(2_401.0)
            })
        },
        "2401 Hz, the CSV's",
    );
    check(
        &|dir| {
            edit_meta(&meta(dir), |m| {
                m["global"]["gyroemu:channels"][1]["name"] = serde_json::json!("tia2_v");
            });
        },
        "channels [",
    );
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

/// The lines of `path`, each without its `\n`.
fn lines(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines().map(String::from).collect()
}

fn write_lines(path: &Path, lines: &[String]) {
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
}

/// Rewrites the `.sigmf-meta` at `path` through `edit`.
fn edit_meta(path: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let mut meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    edit(&mut meta);
    std::fs::write(path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
}

#[test]
fn csv_rows_not_of_consecutive_samples_are_refused_naming_the_line() {
    // Rows missing or repeated once read as a rate 2x or 0.5x, an edited last index as an
    // absurd one: the recorder's 300 rows are samples 1000..=1299 on lines 2..=301.
    let dir = tempfile::tempdir().unwrap();
    recorder().write(dir.path(), "x").unwrap();
    let csv = dir.path().join("x.csv");
    let all = lines(&csv);
    let every_other: Vec<String> = std::iter::once(all[0].clone())
        .chain(all[1..].iter().step_by(2).cloned())
        .collect();
    assert!(every_other[1].starts_with("1000,"));
    write_lines(&csv, &every_other);
    refused(&csv, "line 3, column `sample`: 1002, expected 1001");
    let doubled: Vec<String> = std::iter::once(all[0].clone())
        .chain(all[1..].iter().flat_map(|l| [l.clone(), l.clone()]))
        .collect();
    write_lines(&csv, &doubled);
    refused(&csv, "line 3, column `sample`: 1000, expected 1001");
    let mut edited = all.clone();
    let last = edited.len() - 1;
    edited[last] = edited[last].replacen("1299,", "18446744073709551615,", 1);
    write_lines(&csv, &edited);
    refused(
        &csv,
        "line 301, column `sample`: 18446744073709551615, expected 1299",
    );
    // No row can follow the largest index (checked, not wrapped to 0).
    std::fs::write(&csv, "sample,time_s,x_v\n18446744073709551615,0,1\n0,1,1\n").unwrap();
    refused(
        &csv,
        "line 3: a row after sample index 18446744073709551615",
    );
}

#[test]
fn csv_times_off_the_line_of_consecutive_samples_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    recorder().write(dir.path(), "x").unwrap();
    let csv = dir.path().join("x.csv");
    let all = lines(&csv);
    let time = |l: &str| l.split(',').nth(1).unwrap().parse::<f64>().unwrap();
    let with_time = |k: usize, t: &str| {
        let mut v = all.clone();
        let cells: Vec<&str> = all[k].split(',').collect();
        v[k] = [&[cells[0], t], &cells[2..]].concat().join(",");
        v
    };
    // The last time edited to half the span: the rate would read 2x.
    let (t_first, t_last) = (time(&all[1]), time(&all[300]));
    write_lines(
        &csv,
        &with_time(300, &(t_first + (t_last - t_first) / 2.0).to_string()),
    );
    refused(&csv, "line 3, column `time_s`");
    // One row 1 us late: 2.4e-3 of a sample period at 2400 Hz, far above rounding.
    let t = time(&all[149]) + 1e-6;
    write_lines(&csv, &with_time(149, &t.to_string()));
    refused(&csv, "line 150, column `time_s`");
    write_lines(&csv, &with_time(149, "inf"));
    refused(
        &csv,
        "line 150, column `time_s`: `inf` is not a finite time",
    );
    // What the writer prints far from t = 0 still reads, to the rate its times resolve...
    let rec = |fs: f64, start: u64, len: u64| {
        let mut r =
            SignalRecorder::new(vec!["x_v".into()], fs, start, len).with_time_origin(3.0 / fs);
        for n in start..start + len {
            r.record(n, &[n as f64]);
        }
        r.write_csv(&csv).unwrap();
    };
    rec(1e3, 1_000_000_000_000, 2_000);
    let d = read_dump(&csv).unwrap();
    assert_eq!((d.global_index, d.frames()), (1_000_000_000_000, 2_000));
    assert!((d.sample_rate_hz / 1e3 - 1.0).abs() < 1e-6);
    // ... and where f64 times barely resolve a sample, the rate read would be % off: refused.
    rec(240_000.0, 1 << 52, 50);
    refused(&csv, "gives the rate only to");
}

#[test]
fn csv_error_lines_count_blank_lines_and_crlf() {
    // The csv crate skips blank lines: the line of a row is not its index + 2.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("b.csv");
    std::fs::write(&p, "sample,time_s,x_v\n\n0,0,1\n\n1,0.5,oops\n").unwrap();
    refused(&p, "line 5, column `x_v`: `oops`");
    std::fs::write(&p, "sample,time_s,x_v\r\n\r\n0,0,1\r\n1,0.5,oops\r\n").unwrap();
    refused(&p, "line 4, column `x_v`: `oops`");
    std::fs::write(&p, "sample,time_s,x_v\n0,0,1\n\n\n1,0.5\n").unwrap();
    refused(&p, "line 5:");
    recorder().write(dir.path(), "x").unwrap();
    let csv = dir.path().join("x.csv");
    let all = lines(&csv);
    // A blank line after line 10 and the row of line 20 (sample 1018) removed: sample 1019
    // stands on line 21.
    let mut gap = all.clone();
    gap.remove(19);
    gap.insert(10, String::new());
    write_lines(&csv, &gap);
    refused(&csv, "line 21, column `sample`: 1019, expected 1018");
    // Two blank lines after the header and the time of line 150 edited: it stands on line 152.
    let mut late = all.clone();
    let cells: Vec<String> = late[149].split(',').map(String::from).collect();
    let t = cells[1].parse::<f64>().unwrap() + 1e-6;
    late[149] = format!("{},{t},{}", cells[0], cells[2..].join(","));
    late.splice(1..1, [String::new(), String::new()]);
    write_lines(&csv, &late);
    refused(&csv, "line 152, column `time_s`");
}

#[cfg(unix)]
#[test]
fn devices_and_oversized_files_are_refused_before_they_are_read() {
    // /dev/zero never ends: once read until memory ran out.
    let dir = tempfile::tempdir().unwrap();
    recorder().write(dir.path(), "x").unwrap();
    let p = |ext: &str| dir.path().join(format!("x.{ext}"));
    let meta = std::fs::read(p("sigmf-meta")).unwrap();
    for ext in ["sigmf-meta", "sigmf-data", "csv"] {
        let kept = dir.path().join("kept");
        std::fs::rename(p(ext), &kept).unwrap();
        std::os::unix::fs::symlink("/dev/zero", p(ext)).unwrap();
        match read_dump(&p(ext)) {
            Err(e @ IoError::Read { .. }) => {
                let m = e.to_string();
                assert!(m.contains(&format!("x.{ext}")), "{m}");
                assert!(m.contains("not a regular file"), "{m}");
            }
            other => panic!("{ext}: expected a read error, got {other:?}"),
        }
        std::fs::remove_file(p(ext)).unwrap();
        std::fs::rename(&kept, p(ext)).unwrap();
    }
    // Valid JSON past 16 MiB is no gyroemu metadata.
    let mut padded = meta.clone();
    padded.resize(meta.len() + (17 << 20), b' ');
    std::fs::write(p("sigmf-meta"), &padded).unwrap();
    refused(&p("sigmf-meta"), "not a gyroemu SigMF meta");
    std::fs::write(p("sigmf-meta"), &meta).unwrap();
    // Sparse files past the longest dump gyroemu writes (5e7 frames): refused by their size.
    let data = std::fs::File::options()
        .write(true)
        .open(p("sigmf-data"))
        .unwrap();
    data.set_len(50_000_000 * 8 * 3 + 24).unwrap();
    refused(&p("sigmf-meta"), "over 50000000 frames of 3 f64");
    let csv = std::fs::File::options().write(true).open(p("csv")).unwrap();
    csv.set_len(50_000_000 * 16 * 25 + 1).unwrap();
    refused(&p("csv"), "largest dump CSV gyroemu writes");
}

/// A FIFO at `path` that a thread fills with `bytes` and closes.
#[cfg(unix)]
fn fifo(path: &Path, bytes: Vec<u8>) {
    let made = std::process::Command::new("mkfifo").arg(path).status();
    assert!(made.unwrap().success());
    let path = path.to_path_buf();
    // Not joined: a reader that stops early leaves it a broken pipe, which it ignores.
    std::thread::spawn(move || {
        let mut w = std::fs::File::options().write(true).open(path).unwrap();
        let _ = std::io::Write::write_all(&mut w, &bytes);
    });
}

#[cfg(unix)]
#[test]
fn fifos_are_read_to_their_end_through_a_bound() {
    // Process substitution `<(...)` gives a FIFO: read, but never past the cap.
    let (src, dir) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    recorder().write(src.path(), "x").unwrap();
    let csv = std::fs::read(src.path().join("x.csv")).unwrap();
    fifo(&dir.path().join("x.csv"), csv);
    let d = read_dump(&dir.path().join("x.csv")).unwrap();
    check_samples(&d, &recorder());
    let mut meta = std::fs::read(src.path().join("x.sigmf-meta")).unwrap();
    meta.resize(meta.len() + (17 << 20), b' ');
    std::fs::copy(
        src.path().join("x.sigmf-data"),
        dir.path().join("x.sigmf-data"),
    )
    .unwrap();
    fifo(&dir.path().join("x.sigmf-meta"), meta);
    refused(&dir.path().join("x.sigmf-meta"), "not a gyroemu SigMF meta");
}

#[test]
fn sigmf_captures_gyroemu_does_not_write_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    recorder().write(dir.path(), "x").unwrap();
    let meta = dir.path().join("x.sigmf-meta");
    let set = |key: &str, v: serde_json::Value| {
        edit_meta(&meta, |m| m["captures"][0][key] = v);
    };
    // 300 frames: the last index must be a u64, or frame times wrap around to index 0.
    set("core:global_index", u64::MAX.into());
    refused(
        &meta,
        "captures[0].core:global_index = 18446744073709551615: its 300 frames",
    );
    set("core:global_index", (u64::MAX - 298).into());
    refused(
        &meta,
        "captures[0].core:global_index = 18446744073709551317",
    );
    set("core:global_index", (u64::MAX - 299).into());
    let d = read_dump(&meta).unwrap();
    let t_last = d.t0_s + u64::MAX as f64 / 2_400.0;
    assert_eq!(d.time_s(299), t_last);
    set("core:global_index", 1_000.into());
    set("core:sample_start", 5.into());
    refused(
        &meta,
        "captures[0].core:sample_start = 5: must be 0 (the capture starts at the file's first sample)",
    );
    set("core:sample_start", 0.into());
    read_dump(&meta).unwrap();
    // A second capture is a break in the recording that one time axis cannot describe.
    edit_meta(&meta, |m| {
        let second = serde_json::json!({"core:sample_start": 150, "core:global_index": 5_000});
        m["captures"].as_array_mut().unwrap().push(second);
    });
    refused(&meta, "must be an array of at most one capture");
}

#[test]
fn frame_times_past_f64_are_refused_and_an_unhashed_recording_is_said_unchecked() {
    let dir = tempfile::tempdir().unwrap();
    recorder().write(dir.path(), "x").unwrap();
    let meta = dir.path().join("x.sigmf-meta");
    assert!(
        read_dump(&meta).unwrap().notes.is_empty(),
        "a hashed recording is checked"
    );
    // Index 1299 at 1e-308 Hz is 1.3e311 s: `inspect` printed t = inf .. inf.
    edit_meta(&meta, |m| m["global"]["core:sample_rate"] = 1e-308.into());
    refused(&meta, "core:sample_rate = 1e-308 Hz");
    // The last frame alone past f64 (1000 frames fit below 1.8e308 s, 1299 do not).
    edit_meta(&meta, |m| {
        m["global"]["core:sample_rate"] = (1.1e3 / f64::MAX).into()
    });
    refused(&meta, "the time of sample index 1299");
    // A time origin far out plus the span sums to inf too.
    edit_meta(&meta, |m| {
        m["global"]["core:sample_rate"] = 1e-290.into();
        m["global"]["gyroemu:t0_s"] = f64::MAX.into();
    });
    refused(&meta, "is not a finite number of seconds");
    edit_meta(&meta, |m| {
        m["global"]["core:sample_rate"] = 2_400.0.into();
        m["global"]["gyroemu:t0_s"] = 0.0.into();
    });
    // Without the hash nothing is checked, and the reader says so.
    edit_meta(&meta, |m| {
        m["global"].as_object_mut().unwrap().remove("core:sha512");
    });
    let d = read_dump(&meta).unwrap();
    assert_eq!(d.notes.len(), 1, "{:?}", d.notes);
    assert!(d.notes[0].contains("no core:sha512") && d.notes[0].contains("x.sigmf-data"));
}

#[test]
fn recordings_without_samples_are_refused() {
    // Once printed as rms -0 and peak 0 at read, as if a silent signal had been recorded.
    let dir = tempfile::tempdir().unwrap();
    let meta = gyroemu_io::SigmfMeta::new(1e3, &[("a_v", "V")]);
    gyroemu_io::write_sigmf(dir.path(), "e", &meta, &[&[]]).unwrap();
    let path = dir.path().join("e.sigmf-meta");
    refused(&path, "e.sigmf-data: holds no samples");
    edit_meta(&path, |m| {
        m["global"].as_object_mut().unwrap().remove("core:sha512");
    });
    refused(&path, "e.sigmf-data: holds no samples");
    let csv = dir.path().join("e.csv");
    std::fs::write(&csv, "sample,time_s,a_v\n").unwrap();
    refused(&csv, "holds no samples");
}
