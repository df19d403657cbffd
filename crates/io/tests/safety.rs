//! Size guard, atomicity and the windowed recorder.

mod common;
use common::entries;
use gyroemu_io::{
    check_wav_f32_size, write_atomic, write_atomic_via, write_json, IoError, SignalRecorder,
    WAV_F32_MAX_DATA_BYTES,
};
use std::path::Path;

#[test]
fn wav_guard_at_the_4_gib_boundary() {
    let p = Path::new("/nowhere/x.wav");
    // RIFF size field = file size - 8 = 60 header bytes + data, must fit in u32.
    assert_eq!(WAV_F32_MAX_DATA_BYTES, (1u64 << 32) - 1 - 60);
    let max_frames_1ch = WAV_F32_MAX_DATA_BYTES / 4;
    assert_eq!(
        check_wav_f32_size(p, 48_000, 1, max_frames_1ch).unwrap(),
        max_frames_1ch * 4
    );
    let err = check_wav_f32_size(p, 48_000, 1, max_frames_1ch + 1).unwrap_err();
    match &err {
        IoError::WavTooLarge {
            data_bytes,
            limit_bytes,
            ..
        } => {
            assert_eq!(*data_bytes, (max_frames_1ch + 1) * 4);
            assert_eq!(*limit_bytes, WAV_F32_MAX_DATA_BYTES);
        }
        e => panic!("wrong error {e}"),
    }
    let msg = err.to_string();
    assert!(
        msg.contains("x.wav") && msg.contains(&((max_frames_1ch + 1) * 4).to_string()),
        "{msg}"
    );
    // Multi-channel: 8 channels x 2^27 frames = exactly 4 GiB of data -> refused.
    assert!(check_wav_f32_size(p, 1000, 8, 1 << 27).is_err());
    assert!(check_wav_f32_size(p, 1000, 8, (1 << 27) - 8).is_ok());
    // No u64 overflow on absurd requests.
    assert!(matches!(
        check_wav_f32_size(p, 1000, 65_535, u64::MAX),
        Err(IoError::WavTooLarge { .. })
    ));
    // hound's u32 byte-rate field.
    assert!(check_wav_f32_size(p, u32::MAX, 2, 1).is_err());
    assert!(check_wav_f32_size(p, 1000, 70_000, 1).is_err());
}

#[test]
fn missing_directory_is_an_error_naming_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no_such_dir").join("out.bin");
    let err = write_atomic(&path, b"abc").unwrap_err();
    assert!(matches!(err, IoError::TempCreate { .. }), "{err}");
    assert!(err.to_string().contains("no_such_dir"), "{err}");
    assert!(!path.exists());
    assert!(entries(dir.path()).is_empty());
}

/// Serialises half of itself, then fails: a write that breaks midway.
struct Breaks;
impl serde::Serialize for Breaks {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{Error, SerializeStruct};
        let mut st = s.serialize_struct("Breaks", 2)?;
        st.serialize_field("ok_field", &vec![1.0; 10_000])?;
        Err(S::Error::custom("deliberate failure midway"))
    }
}

#[test]
fn failing_write_leaves_existing_target_and_no_temp() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("keep.json");
    std::fs::write(&path, b"old contents").unwrap();

    let err = write_json(&path, &Breaks).unwrap_err();
    assert!(
        err.to_string().contains("keep.json") && err.to_string().contains("deliberate"),
        "{err}"
    );
    assert_eq!(std::fs::read(&path).unwrap(), b"old contents");
    assert_eq!(entries(dir.path()), vec!["keep.json"]);

    // A path-based producer that writes junk, then fails.
    let err = write_atomic_via(&path, |tmp| {
        assert_eq!(tmp.parent(), Some(dir.path()));
        assert_eq!(tmp.extension().unwrap(), "json");
        std::fs::write(tmp, b"half")?;
        Err("encoder exploded".into())
    })
    .unwrap_err();
    assert!(err.to_string().contains("encoder exploded"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), b"old contents");
    assert_eq!(entries(dir.path()), vec!["keep.json"]);

    // And a successful one replaces it, leaving no temp behind.
    write_atomic_via(&path, |tmp| Ok(std::fs::write(tmp, b"new")?)).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"new");
    write_atomic(&path, b"newer").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"newer");
    assert_eq!(entries(dir.path()), vec!["keep.json"]);
}

#[test]
fn recorder_keeps_exactly_the_window() {
    let names = vec!["a_v".to_string(), "b_a".to_string()];
    let fs_hz = 1000.0;
    let mut r = SignalRecorder::new(names.clone(), fs_hz, 10, 5);
    assert!(r.is_empty());
    for n in 0..100u64 {
        assert_eq!(r.wants(n), (10..15).contains(&n), "n = {n}");
        r.record(n, &[n as f64, -(n as f64) * 0.5]);
    }
    assert_eq!(r.len(), 5);
    assert_eq!(r.names(), &names[..]);
    assert_eq!(r.channel(0), vec![10.0, 11.0, 12.0, 13.0, 14.0]);
    assert_eq!(r.channel(1), vec![-5.0, -5.5, -6.0, -6.5, -7.0]);

    // Window touching the end of u64 does not wrap to index 0.
    let e = SignalRecorder::new(names.clone(), fs_hz, u64::MAX - 2, 10);
    assert!(e.wants(u64::MAX) && e.wants(u64::MAX - 2) && !e.wants(0) && !e.wants(u64::MAX - 3));

    let dir = tempfile::tempdir().unwrap();
    r.write(dir.path(), "dump").unwrap();
    assert_eq!(
        entries(dir.path()),
        vec!["dump.csv", "dump.sigmf-data", "dump.sigmf-meta", "dump.wav"]
    );

    let mut rd = csv::Reader::from_path(dir.path().join("dump.csv")).unwrap();
    let hdr: Vec<String> = rd.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(hdr, ["sample", "time_s", "a_v", "b_a"]);
    let rows: Vec<csv::StringRecord> = rd.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 5);
    for (i, row) in rows.iter().enumerate() {
        let n = 10 + i as u64;
        assert_eq!(row[0].parse::<u64>().unwrap(), n);
        assert_eq!(row[1].parse::<f64>().unwrap(), n as f64 / fs_hz);
        assert_eq!(row[2].parse::<f64>().unwrap(), n as f64);
        assert_eq!(row[3].parse::<f64>().unwrap(), -(n as f64) * 0.5);
    }

    let mut w = hound::WavReader::open(dir.path().join("dump.wav")).unwrap();
    assert_eq!(
        (w.spec().channels, w.spec().sample_rate, w.duration()),
        (2, 1000, 5)
    );
    let s: Vec<f32> = w.samples::<f32>().map(Result::unwrap).collect();
    assert_eq!(
        s,
        vec![10.0, -5.0, 11.0, -5.5, 12.0, -6.0, 13.0, -6.5, 14.0, -7.0]
    );
}

#[test]
fn recorder_gaps_are_nan_and_a_rate_no_wav_holds_writes_no_wav() {
    let mut r = SignalRecorder::new(vec!["x".into()], 0.2, 0, 4);
    r.record(2, &[7.0]);
    let c = r.channel(0);
    assert_eq!(c.len(), 3);
    assert!(c[0].is_nan() && c[1].is_nan() && c[2] == 7.0);
    let dir = tempfile::tempdir().unwrap();
    r.write(dir.path(), "x").unwrap();
    assert_eq!(
        entries(dir.path()),
        ["x.csv", "x.sigmf-data", "x.sigmf-meta"]
    );
}

/// An error's reason is said once: in its message, not again as its source (a CLI printing
/// the chain showed every disk error twice).
#[test]
fn an_io_error_says_its_reason_once() {
    use std::error::Error;
    let e = IoError::Write {
        path: "out/x.csv".into(),
        reason: std::io::Error::other("No space left on device"),
    };
    assert!(e.source().is_none());
    let mut chain = e.to_string();
    let mut s = e.source();
    while let Some(x) = s {
        chain += &format!(": {x}");
        s = x.source();
    }
    assert_eq!(chain.matches("No space left").count(), 1, "{chain}");
}
