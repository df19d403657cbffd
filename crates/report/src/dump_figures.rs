//! The two figures of a signal dump, from the files alone (so `gyroemu inspect` and
//! `reproduce` draw the same): `signals.png`, every node against time, and `spectrum.png`,
//! Welch spectra of the full-rate nodes and of the low-pass output, with the carrier, the
//! rotating excitation's sidebands, the 2 fc mixer product and the low-pass residual marked
//! and their levels read by the tone finder.

use crate::dump_set::{groups, DumpSet, Group};
use crate::error::ReportError;
use gyroemu_core::sig3;
use gyroemu_io::Dump;
use gyroemu_plot::{render_panels_png, Figure, Series, SeriesStyle};
use gyroemu_spectrum::{tone_near, unresolved, welch, Psd, SpectrumError};
use std::path::{Path, PathBuf};

/// Carrier periods of the full-rate nodes shown in `signals.png` (the waveforms stay legible).
pub const SHOWN_CARRIER_PERIODS: f64 = 10.0;
/// Full-rate samples shown when the carrier is unknown (a recording without metadata).
const SHOWN_SAMPLES_UNKNOWN_F0: usize = 400;
/// Spectra are drawn down to this far below their peak (f64 arithmetic's own floor is lower
/// still and would stretch the axis over 30 decades).
pub const SPECTRUM_RANGE_DB: f64 = 200.0;
/// Width of the figures, px; each row of panels is this high.
const WIDTH_PX: u32 = 1600;
const ROW_PX: u32 = 430;
/// Height of the title band above the rows, px.
const TITLE_PX: u32 = 80;

/// `"dBV"` for volts, else `"dB re 1 <unit>"` (or `"dB"` when dimensionless).
pub fn db_unit(unit: &str) -> String {
    match unit {
        "V" => "dBV".into(),
        "" => "dB".into(),
        u => format!("dB re 1 {u}"),
    }
}

/// The density unit of samples in `unit`: `V²/Hz`, `(m/s)²/Hz`.
fn density_unit(unit: &str) -> String {
    match unit {
        "" => "1/Hz".into(),
        u if u.contains('/') => format!("({u})²/Hz"),
        u => format!("{u}²/Hz"),
    }
}

/// Writes `signals.png` and `spectrum.png` of `set` into `dir`; returns their paths.
pub fn write_dump_figures(set: &DumpSet, dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    dump_figures(set)?.write(dir)
}

/// Both figures of a dump, laid out and checked, not yet drawn.
pub struct DumpFigures([(&'static str, String, Vec<Figure>); 2]);

/// Lays out both figures of `set` and checks their size before either is drawn: a dump of
/// many channels (80 and more) had written `spectrum.png`, then failed on `signals.png`'s
/// height, leaving half of what was asked.
pub fn dump_figures(set: &DumpSet) -> Result<DumpFigures, ReportError> {
    // The two figures are independent: laid out (their spectra computed) on two threads.
    let (signals, spectrum) = rayon::join(|| signal_panels(set), || spectrum_panels(set));
    let figures = [
        ("signals.png", signals.0, signals.1),
        ("spectrum.png", spectrum.0, spectrum.1),
    ];
    for (file, _, panels) in &figures {
        let height = figure_height(panels.len());
        if height > gyroemu_plot::MAX_SIDE_PX as usize {
            return Err(gyroemu_plot::PlotError::InvalidLayout {
                path: PathBuf::from(file),
                reason: format!(
                    "{} panels, {WIDTH_PX} x {height} px, beyond the {} px a figure may take (at most {} panels); nothing was written: inspect fewer channels",
                    panels.len(),
                    gyroemu_plot::MAX_SIDE_PX,
                    2 * ((gyroemu_plot::MAX_SIDE_PX - TITLE_PX) / ROW_PX)
                ),
            }
            .into());
        }
    }
    Ok(DumpFigures(figures))
}

/// A figure's height for `panels` panels, two to a row.
fn figure_height(panels: usize) -> usize {
    TITLE_PX as usize + ROW_PX as usize * panels.div_ceil(2).max(1)
}

impl DumpFigures {
    /// Draws both figures into `dir` (on two threads); returns their paths.
    pub fn write(self, dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
        let render = |(file, title, panels): (&str, String, Vec<Figure>)| {
            let path = dir.join(file);
            let h = figure_height(panels.len()) as u32;
            render_panels_png(&title, &panels, 2, WIDTH_PX, h, &path).map(|_| path)
        };
        let [a, b] = self.0;
        let (a, b) = rayon::join(|| render(a), || render(b));
        Ok(vec![a?, b?])
    }
}

/// "m2tfg-rotating/dump at 175 deg/s": the dump's folder and name, and the operating point
/// when the metadata says it.
fn heading(set: &DumpSet) -> String {
    let p = std::path::Path::new(&set.name);
    let last: Vec<String> = p
        .components()
        .rev()
        .take(2)
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let short: Vec<&str> = last.iter().rev().map(String::as_str).collect();
    let rate = set
        .extra("rate_dps")
        .map(|r| format!(" at {r} deg/s"))
        .unwrap_or_default();
    format!("{}{rate}", short.join("/"))
}

/// The panels of `signals.png` and its title.
pub fn signal_panels(set: &DumpSet) -> (String, Vec<Figure>) {
    let mut panels = Vec::new();
    let mut zero = Vec::new();
    for (d, decimated) in set
        .full
        .iter()
        .map(|d| (d, false))
        .chain(set.decimated.iter().map(|d| (d, true)))
    {
        let n = d.frames();
        let shown = if decimated {
            n
        } else {
            let per = carrier_hz(set)
                .map(|fc| (SHOWN_CARRIER_PERIODS * d.sample_rate_hz / fc).ceil() as usize);
            n.min(per.unwrap_or(SHOWN_SAMPLES_UNKNOWN_F0)).max(2.min(n))
        };
        let x_label = if shown < n {
            format!("Time (s): the first {shown} of {n} samples")
        } else {
            format!("Time (s): {n} samples at {} Hz", d.sample_rate_hz)
        };
        let ts: Vec<f64> = (0..shown).map(|k| d.time_s(k)).collect();
        for (title, unit, chans) in groups(d) {
            if chans.iter().all(|(_, x)| x.iter().all(|&v| v == 0.0)) {
                zero.push(title);
                continue;
            }
            let y_label = if unit.is_empty() {
                "value".to_string()
            } else {
                format!("({unit})")
            };
            let mut f = Figure::new(title, x_label.as_str(), y_label);
            for (name, x) in chans {
                f = f.with(Series::new(
                    name,
                    SeriesStyle::Line,
                    ts.clone(),
                    x[..shown].to_vec(),
                ));
            }
            panels.push(f);
        }
    }
    let mut title = format!("{}: every node in time", heading(set));
    if !zero.is_empty() {
        title.push_str(&format!(" (zero throughout: {})", zero.join(", ")));
    }
    (title, panels)
}

/// A known frequency to mark: what it is and where.
struct Mark {
    what: String,
    freq_hz: f64,
}

/// The drive's carrier, where the driven tones sit: `gyroemu:carrier_hz` (a detuned or
/// PLL-locked carrier differs from f0), else, in a dump written before it was recorded,
/// `gyroemu:f0_hz`.
fn carrier_hz(set: &DumpSet) -> Option<f64> {
    set.extra("carrier_hz").or_else(|| set.extra("f0_hz"))
}

/// The markers of a full-rate panel: the carrier fc, mode 2's resonance when the bins tell it
/// from fc, the rotating excitation's sidebands when the spectrum resolves them, 2 fc on the
/// mixer's output (and DC there).
fn full_rate_marks(set: &DumpSet, psd: &Psd, stage1: bool) -> (Vec<Mark>, Option<String>) {
    let mut marks = Vec::new();
    let mut note = None;
    let Some(fc) = carrier_hz(set) else {
        return (
            marks,
            Some("carrier unknown (no gyroemu:carrier_hz nor gyroemu:f0_hz)".into()),
        );
    };
    let f0b = set.extra("f0_mode2_hz").unwrap_or(fc);
    if stage1 {
        marks.push(Mark {
            what: "DC".into(),
            freq_hz: 0.0,
        });
        marks.push(Mark {
            what: "2 fc".into(),
            freq_hz: 2.0 * fc,
        });
        return (marks, None);
    }
    marks.push(Mark {
        what: "fc".into(),
        freq_hz: fc,
    });
    if (f0b - fc).abs() > 2.0 * psd.bin_hz() {
        marks.push(Mark {
            what: "f0 mode 2".into(),
            freq_hz: f0b,
        });
    }
    if let Some(om) = set.extra("omega_hz").filter(|&o| o > 0.0) {
        if om > 2.0 * psd.bin_hz() {
            marks.push(Mark {
                what: "fc − Ω".into(),
                freq_hz: fc - om,
            });
            marks.push(Mark {
                what: "fc + Ω".into(),
                freq_hz: fc + om,
            });
        } else {
            note = Some(format!(
                "fc ± Ω unresolved (Ω = {} Hz, bins {} Hz)",
                sig3(om),
                sig3(psd.bin_hz())
            ));
        }
    }
    (marks, note)
}

/// The markers of the low-pass panel: DC, the modulation (rotating: Ω; rate table: its
/// frequency) and where the 2 fc residual lands after decimation.
fn lowpass_marks(set: &DumpSet, psd: &Psd) -> (Vec<Mark>, Option<String>) {
    let mut marks = vec![Mark {
        what: "DC".into(),
        freq_hz: 0.0,
    }];
    let mut notes = Vec::new();
    for (key, what) in [("omega_hz", "Ω"), ("table_freq_hz", "table frequency")] {
        match set.extra(key).filter(|&f| f > 0.0) {
            Some(f) if f > 2.0 * psd.bin_hz() => marks.push(Mark {
                what: what.into(),
                freq_hz: f,
            }),
            Some(f) => notes.push(format!(
                "{what} ({} Hz) unresolved in {} Hz bins",
                sig3(f),
                sig3(psd.bin_hz())
            )),
            None => {}
        }
    }
    let Some(fc) = carrier_hz(set) else {
        return (marks, notes.pop());
    };
    let fs = psd.fs_hz;
    let alias = (2.0 * fc - fs * (2.0 * fc / fs).round()).abs();
    if alias > 2.0 * psd.bin_hz() {
        marks.push(Mark {
            what: "2 fc residual (aliased)".into(),
            freq_hz: alias,
        });
    } else if alias < 0.5 * psd.bin_hz() {
        notes.push("the 2 fc residual aliases onto DC".into());
    } else {
        // Within two bins of DC but not on it: in a spectrum of a few bins that can be fs/2.
        notes.push(format!(
            "the 2 fc residual (aliased to {} Hz) unresolved in {} Hz bins",
            sig3(alias),
            sig3(psd.bin_hz())
        ));
    }
    (marks, (!notes.is_empty()).then(|| notes.join("; ")))
}

/// One spectrum panel: the channels' densities (log axis, down to the display floor), the
/// marks with each channel's level there.
fn spectrum_panel(
    title: &str,
    unit: &str,
    chans: &[(&str, &[f64])],
    fs_hz: f64,
    marks: impl Fn(&Psd) -> (Vec<Mark>, Option<String>),
) -> Option<Figure> {
    // A channel left out is named in the title, so a missing trace never reads as a quiet one.
    let mut psds: Vec<(&str, Psd)> = Vec::new();
    let mut left_out = Vec::new();
    for (name, x) in chans {
        if x.iter().all(|&v| v == 0.0) {
            left_out.push(format!("{name} (all zero)"));
            continue;
        }
        match welch(x, fs_hz, None) {
            Ok(p) => psds.push((name, p)),
            Err(SpectrumError::OutOfRange { .. }) => {
                left_out.push(format!("{name} (power outside f64's range)"))
            }
            Err(_) => left_out.push(format!("{name} (no spectrum)")),
        }
    }
    let first = &psds.first()?.1;
    let peak = psds
        .iter()
        .flat_map(|(_, p)| p.density())
        .fold(0.0, f64::max);
    let floor = peak * 10f64.powf(-SPECTRUM_RANGE_DB / 10.0);
    let (marks, note) = marks(first);
    let left_out = (!left_out.is_empty()).then(|| format!("not drawn: {}", left_out.join(", ")));
    let notes: Vec<String> = note.into_iter().chain(left_out).collect();
    let mut f = Figure::new(
        match notes.is_empty() {
            false => format!("{title}: {}", notes.join("; ")),
            true => title.to_string(),
        },
        format!(
            "Frequency (Hz): {} segment(s) of {}, ENBW {} Hz",
            first.segments,
            first.segment_len,
            sig3(first.enbw_hz)
        ),
        format!("PSD ({})", density_unit(unit)),
    )
    .log_y();
    for (name, p) in &psds {
        let ys = p.density().into_iter().map(|d| d.max(floor)).collect();
        f = f.with(Series::new(*name, SeriesStyle::Line, p.freqs_hz(), ys));
    }
    for m in marks {
        let mut level_read = false;
        let levels: Vec<String> = psds
            .iter()
            .map(|(_, p)| match tone_near(p, m.freq_hz, 2) {
                None => "-".into(),
                // As `inspect` says it: a tone sharing its bins with its mirror image.
                Some(t) if unresolved(p, &t).is_some() => "unresolved".into(),
                Some(t) => {
                    level_read = true;
                    format!("{:.1}", t.level_db())
                }
            })
            .collect();
        // The unit only beside a level; one word for all channels once (the m2tfg presets'
        // 2 fc residual, unresolved on fs/2 in every channel, ran into its own mark).
        let label = if level_read {
            format!("{}: {} {}", m.what, levels.join(" / "), db_unit(unit))
        } else if levels.len() > 1 && levels.iter().all(|l| l == "unresolved") {
            format!("{}: unresolved (every channel)", m.what)
        } else {
            format!("{}: {}", m.what, levels.join(" / "))
        };
        f = f.with_marker(m.freq_hz, label);
    }
    Some(f)
}

/// The panels of `spectrum.png` and its title.
pub fn spectrum_panels(set: &DumpSet) -> (String, Vec<Figure>) {
    let mut panels = Vec::new();
    let full_groups = set.full.as_ref().map(groups).unwrap_or_default();
    if let Some(d) = &set.full {
        for (title, unit, chans) in &full_groups {
            let stage1 = chans.iter().any(|(n, _)| n.starts_with("mix1_"));
            panels.extend(spectrum_panel(title, unit, chans, d.sample_rate_hz, |p| {
                full_rate_marks(set, p, stage1)
            }));
        }
    }
    if let Some(d) = &set.decimated {
        let lp = lowpass_group(d);
        if let Some((title, unit, chans)) = &lp {
            panels.extend(spectrum_panel(title, unit, chans, d.sample_rate_hz, |p| {
                lowpass_marks(set, p)
            }));
        }
    }
    let title = format!(
        "{}: Welch PSD (one-sided, Hann, 50 % overlap); marked levels in dB re 1 unit rms",
        heading(set)
    );
    (title, panels)
}

/// The low-pass output's channels of a decimated recording.
fn lowpass_group(d: &Dump) -> Option<Group<'_>> {
    groups(d)
        .into_iter()
        .find(|(_, _, c)| c.iter().any(|(n, _)| n.starts_with("lp_")))
}
