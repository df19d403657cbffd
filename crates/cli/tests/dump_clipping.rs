//! A dump of a clipped run says so on its own: its SigMF metadata carries the converter events
//! of the blocks its window spans, and `gyroemu inspect` warns where any is not zero (the
//! run's warning is not beside the dump when it is read later), and so does its CSV.

mod common;

use common::*;

/// A Coriolis run whose TIA output (about 10 mV) meets an ADC of `full_scale_v`.
fn adc_board(full_scale_v: f64) -> String {
    small_board(&format!(
        "adc_bits = 12\nadc_full_scale_v = {full_scale_v:?}\n[experiment]\nkind = \"coriolis\"\nrates_dps = [100.0]\naverage_s = 0.1\nsettle_s = 0.05\n[dump]\n"
    ))
}

#[test]
fn inspect_warns_of_a_dump_whose_window_clipped_and_only_then() {
    let dir = tempfile::tempdir().unwrap();
    // 2 mV full scale clips most of the carrier; 100 mV none of it.
    for (full_scale_v, clipped) in [(0.002, true), (0.1, false)] {
        let cfg = config(dir.path(), "c.toml", &adc_board(full_scale_v));
        let out = dir.path().join(format!("out{clipped}"));
        ok(gyroemu(&["run", s(&cfg), "--out", s(&out)], &[]));
        for stem in ["dump_fullrate", "dump_decimated"] {
            let meta = json(&out.join(format!("{stem}.sigmf-meta")));
            let g = &meta["global"];
            let adc = g["gyroemu:adc_clipped_samples_mode1"].as_f64().unwrap();
            let counted = g["gyroemu:events_counted_samples"].as_f64().unwrap();
            assert!(counted >= 100.0, "{stem}: {g}");
            // A clipped carrier clips on most samples, a clean one on none.
            assert_eq!(adc > 0.5 * counted, clipped, "{stem}: {g}");
            assert_eq!(adc == 0.0, !clipped, "{stem}: {g}");
            assert_eq!(g["gyroemu:dac_clipped_samples_mode1"].as_f64(), Some(0.0));
            // The CSV beside the recording warns alike (its events are in the metadata).
            for ext in ["sigmf-meta", "csv"] {
                let file = out.join(format!("{stem}.{ext}"));
                let o = ok(gyroemu(
                    &["inspect", s(&file), "--out", s(&dir.path().join("insp"))],
                    &[],
                ));
                let text = String::from_utf8_lossy(&o.stdout);
                assert_eq!(
                    text.contains("warning: the board clipped") && text.contains("ADC mode 1: "),
                    clipped,
                    "{ext}: {text}"
                );
            }
        }
    }
}
