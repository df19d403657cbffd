//! `gyroemu inspect`'s RMS and peak of a channel: the RMS of a square wave is its amplitude
//! (to the rounding of its sum), at any magnitude f64 holds (1e300 once read inf, 1e-170 read 0); ordinary
//! samples keep the bits of the plain mean of squares; a spectrum beyond f64's range is said,
//! with no tones listed; a NaN sample makes the peak NaN (it read 0 on an all-NaN channel).

use gyroemu_io::SignalRecorder;
use gyroemu_io::{Dump, SigmfChannel};
use gyroemu_report::dump_stats::channel_stats;
use gyroemu_report::{inspect_text, read_dump_set};
use std::collections::BTreeMap;

fn dump(x: Vec<f64>) -> Dump {
    Dump {
        path: "x.csv".into(),
        sample_rate_hz: 1000.0,
        global_index: 0,
        t0_s: 0.0,
        channels: vec![SigmfChannel {
            name: "x_v".into(),
            unit: "V".into(),
        }],
        data: vec![x],
        extra: BTreeMap::new(),
        notes: Vec::new(),
    }
}

#[test]
fn a_square_wave_reads_its_amplitude_at_any_magnitude() {
    for a in [1e-300, 1e-170, 1e-5, 1.0, 7.5e3, 1e170, 1e300, f64::MAX] {
        let x: Vec<f64> = (0..256).map(|i| if i % 2 == 0 { a } else { -a }).collect();
        let s = &channel_stats(&dump(x))[0];
        assert_eq!(s.peak, a);
        // A sum of 256 rounded squares: within 256 ulps of the amplitude.
        assert!(
            (s.rms / a - 1.0).abs() < 256.0 * f64::EPSILON,
            "{a:e}: {}",
            s.rms
        );
    }
}

#[test]
fn ordinary_samples_keep_the_plain_mean_of_squares() {
    let x: Vec<f64> = (0..1000)
        .map(|i| 1e-3 * (i as f64 * 0.37).sin() + 2e-4)
        .collect();
    let plain = (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
    assert_eq!(channel_stats(&dump(x))[0].rms.to_bits(), plain.to_bits());
}

#[test]
fn a_spectrum_beyond_f64_lists_no_tones_and_says_why() {
    for a in [1e-170, 1e300] {
        let x: Vec<f64> = (0..256).map(|i| if i % 2 == 0 { a } else { -a }).collect();
        let s = &channel_stats(&dump(x))[0];
        assert!(s.tones.is_empty(), "{a:e}: {:?}", s.tones);
        let why = s.spectrum_error.as_deref().unwrap_or_default();
        assert!(why.contains("outside f64's range"), "{a:e}: {why}");
    }
    // Within range the Nyquist tone is found at its level: 20 log10(1e150) dB above 1.
    let x: Vec<f64> = (0..256)
        .map(|i| if i % 2 == 0 { 1e150 } else { -1e150 })
        .collect();
    let s = &channel_stats(&dump(x))[0];
    assert!((s.tones[0].freq_hz - 500.0).abs() < 1e-6, "{:?}", s.tones);
}

#[test]
fn a_nan_sample_makes_the_peak_and_rms_nan_not_a_clean_number() {
    // All NaN, and one NaN among finite samples: neither may read as a peak of finite data.
    let all = vec![f64::NAN; 64];
    let mut one: Vec<f64> = (0..64).map(|i| (i as f64 * 0.3).sin()).collect();
    one[17] = f64::NAN;
    for x in [all, one] {
        let s = &channel_stats(&dump(x))[0];
        assert!(s.peak.is_nan() && s.rms.is_nan(), "{s:?}");
        assert!(s
            .spectrum_error
            .as_deref()
            .unwrap_or_default()
            .contains("NaN"));
    }
    // An infinite sample is the peak.
    let s = &channel_stats(&dump(vec![1.0, f64::NEG_INFINITY, 2.0, 0.5]))[0];
    assert_eq!(s.peak, f64::INFINITY);
}

#[test]
fn what_the_reader_could_not_check_is_printed_with_the_recording() {
    let mut d = dump(vec![1.0, -1.0, 1.0, -1.0]);
    let set = |d: Dump| gyroemu_report::DumpSet {
        name: "x".into(),
        dir: ".".into(),
        full: Some(d),
        decimated: None,
    };
    let text = gyroemu_report::inspect_text(&set(d.clone()));
    assert!(!text.contains("note:"), "{text}");
    d.notes.push("no core:sha512 in the metadata".into());
    let text = gyroemu_report::inspect_text(&set(d));
    assert!(
        text.contains("  note: no core:sha512 in the metadata\n"),
        "{text}"
    );
}

#[test]
fn the_window_is_printed_to_a_sample_period_at_any_rate() {
    // Four samples at 4.8 GHz from t = 2 us: six decimals printed both ends as 0.000002.
    let mut d = dump(vec![1.0, -1.0, 1.0, -1.0]);
    d.sample_rate_hz = 4.8e9;
    d.t0_s = 2e-6;
    let set = gyroemu_report::DumpSet {
        name: "x".into(),
        dir: ".".into(),
        full: Some(d),
        decimated: None,
    };
    let text = gyroemu_report::inspect_text(&set);
    let window = text
        .split("t = ")
        .nth(1)
        .unwrap()
        .split(" s")
        .next()
        .unwrap();
    let ends: Vec<f64> = window.split(" .. ").map(|t| t.parse().unwrap()).collect();
    let period = 1.0 / 4.8e9;
    assert!(
        (ends[1] - ends[0] - 3.0 * period).abs() < 0.1 * period,
        "{window}"
    );
}

/// `inspect`'s line for channel `name` of a 2400 Hz decimated dump of `n` samples of `level`.
fn inspect_line(name: &str, n: u64, level: f64) -> String {
    let dir = tempfile::tempdir().unwrap();
    let mut r = SignalRecorder::new(vec![name.into()], 2400.0, 0, n);
    for k in 0..n {
        r.record(k, &[level]);
    }
    r.write(dir.path(), "dump_decimated").unwrap();
    let set = read_dump_set(&dir.path().join("dump_decimated.sigmf-meta")).unwrap();
    let text = inspect_text(&set);
    text.lines().find(|l| l.contains(name)).unwrap().to_string()
}

#[test]
fn a_record_too_short_for_tones_says_so_not_that_none_stands_out() {
    // 24 samples of a clean level: 4-sample segments, 3 bins, and the Hann window's own
    // leakage (bin 1 = c^2/2) is the median a tone must clear by 20 dB. It printed "none 20
    // dB above the median", as if the channel held no tone; 256 samples read the level.
    let line = inspect_line("lp_i1", 24, -0.019);
    assert!(
        line.contains("none read: a spectrum of 3 bins is too short"),
        "{line}"
    );
    let line = inspect_line("lp_i1", 256, -0.019);
    assert!(
        line.contains(&format!("0.0: {:.1} dBV", 20.0 * 0.019f64.log10())),
        "{line}"
    );
}

#[test]
fn a_channel_zero_throughout_says_so_not_that_its_record_is_short() {
    // A Coriolis dump's stage-2 channels are zero: 24 of them had printed "too short", as if
    // a longer window would show a tone.
    let line = inspect_line("c1_i", 24, 0.0);
    assert!(
        line.contains("zero throughout") && !line.contains("too short"),
        "{line}"
    );
}
