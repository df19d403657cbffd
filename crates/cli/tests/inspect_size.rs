//! `inspect` of a dump whose figures would be taller than a figure may be (many channels)
//! is refused with exit 2 before anything is written: it had written `spectrum.png`, then
//! failed on `signals.png` with exit 1.

use std::process::Command;

fn csv(channels: usize, rows: usize) -> String {
    let mut s = String::from("sample,time_s");
    for c in 0..channels {
        s += &format!(",c{c}");
    }
    s.push('\n');
    for n in 0..rows {
        s += &format!("{n},{}", n as f64 * 1e-3);
        for c in 0..channels {
            s += &format!(",{}", ((n * (c + 1)) as f64 * 0.1).sin());
        }
        s.push('\n');
    }
    s
}

#[test]
fn a_dump_too_wide_for_its_figures_is_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("figures");
    for (channels, refused) in [(8, false), (80, true)] {
        let file = dir.path().join(format!("c{channels}.csv"));
        std::fs::write(&file, csv(channels, 256)).unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_gyroemu"))
            .args([
                "inspect",
                file.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        if refused {
            assert_eq!(o.status.code(), Some(2), "{err}");
            assert!(err.contains("signals.png") && err.contains("px"), "{err}");
            assert!(!out.exists(), "a folder was made for a refused inspect");
        } else {
            assert!(o.status.success(), "{err}");
            assert!(out.join("signals.png").exists() && out.join("spectrum.png").exists());
            std::fs::remove_dir_all(&out).unwrap();
        }
    }
}
