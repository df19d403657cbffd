//! The figures and statistics of a dump, on a synthetic recording of known tones: the tone
//! finder's levels are the closed forms 20 log10(A / sqrt 2), the marks sit at the carrier
//! fc, fc +- Omega and 2 fc (f0 stands in for fc in a dump without `carrier_hz`), and every way
//! of naming the dump reads the same pair.

use gyroemu_io::SignalRecorder;
use gyroemu_report::dump_figures::{signal_panels, spectrum_panels};
use gyroemu_report::{channel_stats, read_dump_set, write_dump_figures};
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::path::Path;

const FS: f64 = 48_000.0;
const F0: f64 = 3_010.0;
const OMEGA: f64 = 700.0;
const M: usize = 48;

fn write_pair(dir: &Path) {
    let extra = BTreeMap::from([
        ("f0_hz".to_string(), F0),
        ("omega_hz".into(), OMEGA),
        ("rate_dps".into(), OMEGA * 360.0),
        ("decimation".into(), M as f64),
    ]);
    let names = ["drive1", "tia1_v", "mix1_i1"].map(String::from).to_vec();
    let mut full = SignalRecorder::new(names, FS, 0, 8192).with_extra(extra.clone());
    for n in 0..8192u64 {
        let t = n as f64 / FS;
        let w = 2.0 * PI * F0 * t;
        full.record(
            n,
            &[
                0.8 * w.cos(),
                1e-3 * (w + 0.3).sin() + 2e-5 * (2.0 * PI * (F0 + OMEGA) * t).sin(),
                0.5e-3 + 1e-3 * (2.0 * w).cos(),
            ],
        );
    }
    full.write(dir, "dump_fullrate").unwrap();
    let fs_out = FS / M as f64;
    let mut dec = SignalRecorder::new(vec!["lp_i1".into()], fs_out, 0, 2048).with_extra(extra);
    for k in 0..2048u64 {
        let t = k as f64 / fs_out;
        dec.record(k, &[0.5e-3 + 1e-6 * (2.0 * PI * 123.0 * t).cos()]);
    }
    dec.write(dir, "dump_decimated").unwrap();
}

fn db(a: f64) -> f64 {
    20.0 * (a / 2f64.sqrt()).log10()
}

#[test]
fn stats_give_the_closed_form_tones_and_units() {
    let dir = tempfile::tempdir().unwrap();
    write_pair(dir.path());
    let set = read_dump_set(dir.path()).unwrap();
    let full = channel_stats(set.full.as_ref().unwrap());
    let tia = &full[1];
    assert_eq!((tia.name.as_str(), tia.unit.as_str()), ("tia1_v", "V"));
    assert_eq!(full[0].unit, "m/s²");
    assert_eq!(full[2].unit, "V");
    assert!((tia.peak - 1e-3).abs() < 3e-5);
    let near = |f: f64| {
        tia.tones
            .iter()
            .find(|t| (t.freq_hz - f).abs() < 1.0)
            .unwrap_or_else(|| panic!("no tone at {f} in {:?}", tia.tones))
    };
    assert!((near(F0).level_db() - db(1e-3)).abs() < 0.05);
    assert!((near(F0 + OMEGA).level_db() - db(2e-5)).abs() < 0.05);
    // RMS of two sinusoids: sqrt(A1^2/2 + A2^2/2), over whole-ish periods.
    let rms = ((1e-6 + 4e-10) / 2.0f64).sqrt();
    assert!((tia.rms / rms - 1.0).abs() < 1e-3, "{} vs {rms}", tia.rms);
    // Mixer: DC 0.5 mV and 2 f0 at 1 mV amplitude.
    let mix = &full[2];
    assert!(mix
        .tones
        .iter()
        .any(|t| t.freq_hz == 0.0 && (t.amplitude() - 0.5e-3).abs() < 1e-7));
    assert!(mix
        .tones
        .iter()
        .any(|t| (t.freq_hz - 2.0 * F0).abs() < 1.0 && (t.level_db() - db(1e-3)).abs() < 0.05));
}

#[test]
fn spectrum_marks_the_carrier_sidebands_and_mixer_product_with_their_levels() {
    let dir = tempfile::tempdir().unwrap();
    write_pair(dir.path());
    let set = read_dump_set(&dir.path().join("dump")).unwrap();
    let (title, panels) = spectrum_panels(&set);
    assert!(title.contains("at 252000 deg/s"), "{title}");
    let tia = panels.iter().find(|f| f.title.starts_with("TIA")).unwrap();
    assert!(tia.y_log);
    let xs: Vec<f64> = tia.markers.iter().map(|m| m.x).collect();
    assert_eq!(xs, [F0, F0 - OMEGA, F0 + OMEGA]);
    let f0_label = &tia.markers[0].label;
    assert!(
        f0_label.contains(&format!("{:.1} dBV", db(1e-3))),
        "{f0_label}"
    );
    let mix = panels
        .iter()
        .find(|f| f.title.starts_with("Stage-1"))
        .unwrap();
    assert!(mix
        .markers
        .iter()
        .any(|m| m.x == 2.0 * F0 && m.label.starts_with("2 fc")));
    // The low-pass panel: DC and the 2 fc residual where decimation folds it (6020 Hz at
    // 1 kHz: 20 Hz).
    let lp = panels
        .iter()
        .find(|f| f.title.starts_with("Low-pass"))
        .unwrap();
    let alias = lp
        .markers
        .iter()
        .find(|m| m.label.contains("residual"))
        .unwrap();
    assert!((alias.x - 20.0).abs() < 1e-9, "{}", alias.x);
    let (_, sig) = signal_panels(&set);
    assert_eq!(sig.len(), 4);
}

#[test]
fn every_name_of_the_dump_reads_the_same_pair_and_figures_are_written() {
    let dir = tempfile::tempdir().unwrap();
    write_pair(dir.path());
    let d = dir.path();
    for p in [
        d.to_path_buf(),
        d.join("dump"),
        d.join("dump_fullrate.sigmf-meta"),
        d.join("dump_decimated.sigmf-data"),
        d.join("dump_fullrate"),
        d.join("dump_decimated.csv"),
    ] {
        let set = read_dump_set(&p).unwrap_or_else(|e| panic!("{p:?}: {e}"));
        assert_eq!(set.full.as_ref().map(|f| f.frames()), Some(8192), "{p:?}");
        assert_eq!(
            set.decimated.as_ref().map(|f| f.frames()),
            Some(2048),
            "{p:?}"
        );
    }
    assert!(read_dump_set(&d.join("dump_fullrate.wav")).is_err());
    let set = read_dump_set(d).unwrap();
    let out = d.join("figs");
    std::fs::create_dir(&out).unwrap();
    let files = write_dump_figures(&set, &out).unwrap();
    assert_eq!(files, [out.join("signals.png"), out.join("spectrum.png")]);
    for f in files {
        assert_eq!(&std::fs::read(f).unwrap()[..4], b"\x89PNG");
    }
}

/// A channel the spectrum cannot draw (all zero, or powers beyond f64) is named in its panel's
/// title, so a missing trace never reads as a quiet one; the channels that can be drawn are.
#[test]
fn a_channel_left_out_of_the_spectrum_is_named_in_the_title() {
    let dir = tempfile::tempdir().unwrap();
    let names = ["drive1", "drive2", "tia1_v", "tia2_v"]
        .map(String::from)
        .to_vec();
    let mut rec = SignalRecorder::new(names, FS, 0, 4096);
    for n in 0..4096u64 {
        let c = (2.0 * PI * F0 * n as f64 / FS).cos();
        // 1e200 squared is past f64's largest number: no Welch power of drive2 exists.
        rec.record(n, &[0.8 * c, 1e200 * c, 1e-3 * c, 0.0]);
    }
    rec.write(dir.path(), "dump_fullrate").unwrap();
    let set = read_dump_set(dir.path()).unwrap();
    let (_, panels) = spectrum_panels(&set);
    let drive = panels
        .iter()
        .find(|f| f.title.starts_with("Drive"))
        .unwrap();
    assert!(
        drive
            .title
            .ends_with("not drawn: drive2 (power outside f64's range)"),
        "{}",
        drive.title
    );
    assert_eq!(drive.series.len(), 1);
    let tia = panels.iter().find(|f| f.title.starts_with("TIA")).unwrap();
    assert!(
        tia.title.ends_with("not drawn: tia2_v (all zero)"),
        "{}",
        tia.title
    );
    assert_eq!(tia.series.len(), 1);
}

/// A drive detuned 40 Hz from the resonance (4.7 bins of 8.5 Hz here): the tones sit at the
/// carrier, so the marks do, and read the carrier's level; at f0 the spectrum holds only the
/// tone's skirt, 40 dB down, which the f0 mark had printed as the drive's level.
#[test]
fn the_marks_sit_at_the_carrier_not_at_the_resonance() {
    let dir = tempfile::tempdir().unwrap();
    let fc = F0 + 40.0;
    let extra = BTreeMap::from([("f0_hz".to_string(), F0), ("carrier_hz".into(), fc)]);
    let mut full =
        SignalRecorder::new(vec!["tia1_v".into()], FS, 0, 8192).with_extra(extra.clone());
    for n in 0..8192u64 {
        let t = n as f64 / FS;
        full.record(n, &[1e-3 * (2.0 * PI * fc * t).sin()]);
    }
    full.write(dir.path(), "dump_fullrate").unwrap();
    let set = read_dump_set(&dir.path().join("dump_fullrate.sigmf-meta")).unwrap();
    let (_, panels) = spectrum_panels(&set);
    let tia = panels.iter().find(|f| f.title.starts_with("TIA")).unwrap();
    assert_eq!(tia.markers[0].x, fc);
    let label = &tia.markers[0].label;
    assert!(label.contains(&format!("{:.1} dBV", db(1e-3))), "{label}");
}

/// The low-pass panel of a decimated dump of `lp_i1` = `x(k)`, `n` samples at 2400 Hz from a
/// board of carrier 15 kHz decimating by 100.
fn low_pass_panel(n: u64, x: impl Fn(u64) -> f64) -> gyroemu_plot::Figure {
    low_pass_panel_of(&["lp_i1"], n, |k, _| x(k))
}

/// [`low_pass_panel`] of the channels `names`, channel `c` = `x(k, c)`.
fn low_pass_panel_of(
    names: &[&str],
    n: u64,
    x: impl Fn(u64, usize) -> f64,
) -> gyroemu_plot::Figure {
    let dir = tempfile::tempdir().unwrap();
    let extra = BTreeMap::from([
        ("carrier_hz".to_string(), 15_000.0),
        ("decimation".into(), 100.0),
    ]);
    let channels = names.len();
    let names = names.iter().map(|s| s.to_string()).collect();
    let mut dec = SignalRecorder::new(names, 2400.0, 0, n).with_extra(extra);
    for k in 0..n {
        let row: Vec<f64> = (0..channels).map(|c| x(k, c)).collect();
        dec.record(k, &row);
    }
    dec.write(dir.path(), "dump_decimated").unwrap();
    let set = read_dump_set(&dir.path().join("dump_decimated.sigmf-meta")).unwrap();
    let (_, panels) = spectrum_panels(&set);
    panels
        .into_iter()
        .find(|f| f.title.starts_with("Low-pass"))
        .unwrap()
}

/// A mark on a tone within 3 bins of fs/2 reads `unresolved`, as `inspect` prints it: the
/// 2 fc residual of the m2tfg presets lands exactly on the decimated fs/2 (2 x 15 kHz at
/// 2.4 kHz), and a level there is the tone's and its mirror image's at once.
#[test]
fn a_mark_at_fs_over_2_reads_unresolved() {
    let fs_out = 240_000.0 / 100.0;
    let lp = low_pass_panel(1024, |k| {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        1e-3 + 1e-9 * sign
    });
    let residual = lp
        .markers
        .iter()
        .find(|m| m.label.contains("residual"))
        .unwrap();
    assert_eq!(residual.x, fs_out / 2.0);
    assert!(residual.label.contains("unresolved"), "{}", residual.label);
    // The DC level beside it is read.
    let dc = lp
        .markers
        .iter()
        .find(|m| m.label.starts_with("DC"))
        .unwrap();
    assert!(
        dc.label.contains(&format!("{:.1}", 20.0 * 1e-3f64.log10())),
        "{}",
        dc.label
    );
}

/// A mark no channel reads a level at says so once and without a dB unit: the m2tfg presets'
/// 2 fc residual, unresolved on fs/2 in all four low-pass channels, once ran
/// `unresolved / unresolved / unresolved / unresolved dBV` into its own mark.
#[test]
fn a_mark_no_channel_reads_says_so_once_without_a_unit() {
    let alternating = |k: u64, c: usize| {
        let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        (1.0 + c as f64) * 1e-3 + 1e-9 * sign
    };
    let four = low_pass_panel_of(&["lp_i1", "lp_q1", "lp_i2", "lp_q2"], 1024, alternating);
    let label = |fig: &gyroemu_plot::Figure, start: &str| {
        let m = fig.markers.iter().find(|m| m.label.starts_with(start));
        m.unwrap().label.clone()
    };
    let residual = label(&four, "2 fc residual");
    assert_eq!(
        residual,
        "2 fc residual (aliased): unresolved (every channel)"
    );
    // Levels that are read keep their unit, one per channel.
    let dc = label(&four, "DC");
    assert_eq!(dc.matches(" / ").count(), 3, "{dc}");
    assert!(dc.ends_with(" dBV"), "{dc}");
    // One channel: the word alone.
    let one = low_pass_panel(1024, |k| alternating(k, 0));
    assert_eq!(
        label(&one, "2 fc residual"),
        "2 fc residual (aliased): unresolved"
    );
}

#[test]
fn a_residual_near_fs_over_2_in_a_coarse_spectrum_is_not_said_to_land_on_dc() {
    // 24 decimated samples at 2400 Hz: 4-sample segments, 600 Hz bins; 2 fc = 30 kHz lands at
    // 1200 Hz (fs/2), which is within two bins of DC there but is not DC.
    let lp = low_pass_panel(24, |_| -0.019);
    assert!(!lp.title.contains("onto DC"), "{}", lp.title);
    assert!(
        lp.title.contains("aliased to 1200 Hz") && lp.title.contains("unresolved in 600 Hz bins"),
        "{}",
        lp.title
    );
}

#[test]
fn a_rotating_drive_with_its_sidebands_in_one_bin_pair_reads_no_level() {
    // cos(Omega t) cos(wc t) over four modulation periods, the default dump window: the
    // default segments are one modulation period, so the sidebands at fc +- Omega are one bin
    // either side of fc and share their bins. Nothing is at fc; inspect read two tones 1 dB
    // high 17 Hz off and the fc mark read a level.
    let dir = tempfile::tempdir().unwrap();
    let (fs, fc, om) = (240_000.0, 15_000.0, 240_000.0 / 1024.0);
    let extra = BTreeMap::from([
        ("carrier_hz".to_string(), fc),
        ("omega_hz".into(), om),
        ("decimation".into(), 100.0),
    ]);
    let n = 4096u64;
    let mut full = SignalRecorder::new(vec!["drive1".into()], fs, 0, n).with_extra(extra);
    for i in 0..n {
        let t = i as f64 / fs;
        full.record(i, &[(2.0 * PI * om * t).cos() * (2.0 * PI * fc * t).cos()]);
    }
    full.write(dir.path(), "dump_fullrate").unwrap();
    let set = read_dump_set(&dir.path().join("dump_fullrate.sigmf-meta")).unwrap();
    let s = &channel_stats(set.full.as_ref().unwrap())[0];
    assert!(!s.tones.is_empty());
    for (t, why) in s.tones.iter().zip(&s.unresolved) {
        assert!(why.is_some(), "read {t:?}");
    }
    let (_, panels) = spectrum_panels(&set);
    let fc_mark = panels
        .iter()
        .flat_map(|f| &f.markers)
        .find(|m| m.label.starts_with("fc:"))
        .unwrap();
    assert!(fc_mark.label.contains("unresolved"), "{}", fc_mark.label);
}
