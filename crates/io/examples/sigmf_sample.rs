//! Writes two small SigMF recordings into the folder given as the first argument (default
//! `sigmf_sample`), one through `write_sigmf` and one through `SignalRecorder`, for checking
//! with `python3 scripts/check_sigmf.py <folder>`.

use gyroemu_io::{write_sigmf, SigmfMeta, SignalRecorder};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or("sigmf_sample".into()));
    std::fs::create_dir_all(&dir)?;
    let fs_hz = 48_000.0;
    let n = 4800;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / fs_hz).collect();
    // A ramp and a square wave: enough to see the channel layout in any viewer.
    let ramp: Vec<f64> = t.iter().map(|&x| x * 10.0).collect();
    let square: Vec<f64> = (0..n)
        .map(|i| if (i / 24) % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let mut meta = SigmfMeta::new(fs_hz, &[("time_s", "s"), ("ramp_v", "V"), ("square", "")]);
    meta.description = "gyroemu SigMF sample: time, ramp, square".into();
    let files = write_sigmf(&dir, "sample_direct", &meta, &[&t, &ramp, &square])?;
    println!("{}", files.meta_path.display());

    let names = vec!["tia1_v".to_string(), "q1_m".into()];
    let mut r = SignalRecorder::new(names, 1234.5, 10, 100).with_time_origin(1e-3);
    for k in 0..200u64 {
        r.record(k, &[k as f64 * 0.5, -(k as f64) * 1e-9]);
    }
    r.write(&dir, "sample_recorder")?;
    println!("{}", dir.join("sample_recorder.sigmf-meta").display());
    Ok(())
}
