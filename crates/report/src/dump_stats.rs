//! What `gyroemu inspect` prints about a dump: per channel the RMS, the peak and the
//! strongest tones (frequency and level).

use crate::dump_figures::{db_unit, SPECTRUM_RANGE_DB};
use crate::dump_set::{channel_unit, DumpSet};
use gyroemu_spectrum::{find_tones, power_of_two_scale, unresolved, welch, Tone};

/// Tones listed per channel.
pub const TONES_LISTED: usize = 4;
/// A tone must stand this far above the median of its neighbouring bins to be listed, dB.
pub const TONE_MIN_SNR_DB: f64 = 20.0;

/// Below this many bins (segments under 32 samples) a tone's own main lobe is a third of the
/// bins whose median it must clear: 24 samples of a clean level or tone found none.
pub const SHORT_SPECTRUM_BINS: usize = 17;

/// The numbers of one channel.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelStats {
    /// Channel name.
    pub name: String,
    /// Unit of its samples.
    pub unit: String,
    /// Root mean square over the recording.
    pub rms: f64,
    /// Largest |sample| (NaN if any sample is NaN).
    pub peak: f64,
    /// The strongest tones, strongest first, within [`SPECTRUM_RANGE_DB`] of the first (empty
    /// when the spectrum cannot be computed).
    pub tones: Vec<Tone>,
    /// For each of `tones`, why it is not read (near DC or fs/2: [`unresolved`]), if so.
    pub unresolved: Vec<Option<String>>,
    /// Why there are no tones, when the spectrum was refused (e.g. non-finite samples).
    pub spectrum_error: Option<String>,
    /// Bins of the spectrum the tones were sought in (0 when it was refused).
    pub bins: usize,
}

/// The statistics of every channel of `d`.
pub fn channel_stats(d: &gyroemu_io::Dump) -> Vec<ChannelStats> {
    d.channels
        .iter()
        .zip(&d.data)
        .map(|(c, x)| {
            // NaN when any sample is (`f64::max` skips NaN: an all-NaN channel read 0).
            let peak = if x.iter().any(|v| v.is_nan()) {
                f64::NAN
            } else {
                x.iter().fold(0.0, |m: f64, v| m.max(v.abs()))
            };
            let rms = rms(x, peak);
            let (mut tones, spectrum_error, psd) = match welch(x, d.sample_rate_hz, None) {
                Ok(p) => (find_tones(&p, TONES_LISTED, TONE_MIN_SNR_DB), None, Some(p)),
                Err(e) => (Vec::new(), Some(e.to_string()), None),
            };
            // Below that range lies f64 arithmetic's own floor, not the signal.
            if let Some(top) = tones.first().map(Tone::level_db) {
                tones.retain(|t| t.level_db() >= top - SPECTRUM_RANGE_DB);
            }
            let unresolved = tones
                .iter()
                .map(|t| psd.as_ref().and_then(|p| unresolved(p, t)))
                .collect();
            let bins = psd.as_ref().map_or(0, |p| p.power.len());
            ChannelStats {
                name: c.name.clone(),
                unit: channel_unit(&c.name, &c.unit).to_string(),
                rms,
                peak,
                tones,
                unresolved,
                spectrum_error,
                bins,
            }
        })
        .collect()
}

/// Root mean square of `x` (largest |sample| `peak`): squares of samples far from 1 are
/// taken scaled by a power of two (exact), so that 1e200 does not read inf nor 1e-170 zero.
fn rms(x: &[f64], peak: f64) -> f64 {
    let n = x.len().max(1) as f64;
    let (down, up) = power_of_two_scale(peak);
    (x.iter().map(|v| (v * down) * (v * down)).sum::<f64>() / n).sqrt() * up
}

/// What the recording's metadata says the board clipped around its window (the DAC, the TIA's
/// rails, the ADC: `gyroemu_board::EVENT_KEYS`), as one sentence, if anything: the tones of a
/// clipped signal are its harmonics and intermodulation, not the device's response, and the
/// run's warning is not beside the dump when it is read later.
pub fn clipping_warning(d: &gyroemu_io::Dump) -> Option<String> {
    let what = ["DAC (drive)", "TIA rail", "ADC"];
    let parts: Vec<String> = gyroemu_board::EVENT_KEYS
        .iter()
        .enumerate()
        .filter_map(|(i, key)| {
            let n = *d.extra.get(*key)?;
            (n > 0.0).then(|| format!("{} mode {}: {n}", what[i / 2], i % 2 + 1))
        })
        .collect();
    if parts.is_empty() {
        return None;
    }
    let over = d
        .extra
        .get(gyroemu_board::EVENTS_COUNTED_KEY)
        .map_or(String::new(), |n| format!(" of {n}"));
    Some(format!(
        "the board clipped in the decimation blocks this window spans ({} samples{over}): every channel downstream of a clipped converter or rail holds a clipped signal, whose tones are not the device's response",
        parts.join(", ")
    ))
}

/// The table `gyroemu inspect` prints: one block per recording, one line per channel.
pub fn inspect_text(set: &DumpSet) -> String {
    let mut out = String::new();
    for d in set.recordings() {
        let n = d.frames();
        // A rate read from a CSV's time column carries its rounding: show it to 12 digits.
        let fs = format!("{:.12e}", d.sample_rate_hz)
            .parse::<f64>()
            .unwrap_or(d.sample_rate_hz);
        // Decimals enough to tell one sample period from the next (a GHz dump read
        // `t = 0.000002 .. 0.000003 s` at six).
        let decimals = (-(1.0 / d.sample_rate_hz).log10()).ceil().clamp(6.0, 17.0) as usize + 1;
        out.push_str(&format!(
            "{}: {} channel(s), {n} samples at {fs} Hz, t = {:.*} .. {:.*} s\n",
            d.path.display(),
            d.channels.len(),
            decimals,
            d.time_s(0),
            decimals,
            d.time_s(n.saturating_sub(1)),
        ));
        for note in &d.notes {
            out.push_str(&format!("  note: {note}\n"));
        }
        if let Some(w) = clipping_warning(d) {
            out.push_str(&format!("  warning: {w}\n"));
        }
        out.push_str(&format!(
            "  {:<10} {:<5} {:>11} {:>11}  strongest tones (Hz: level)\n",
            "channel", "unit", "rms", "peak"
        ));
        for s in channel_stats(d) {
            let tones = match (&s.spectrum_error, s.tones.is_empty()) {
                (Some(e), _) => format!("no spectrum: {e}"),
                (None, true) if s.peak == 0.0 => "none: the channel is zero throughout".into(),
                (None, true) if s.bins < SHORT_SPECTRUM_BINS => format!(
                    "none read: a spectrum of {} bins is too short to tell a tone from its window's own leakage, which sets the median there; record a longer window",
                    s.bins
                ),
                (None, true) => {
                    format!("none {TONE_MIN_SNR_DB} dB above the median of its neighbouring bins")
                }
                (None, false) => s
                    .tones
                    .iter()
                    .zip(&s.unresolved)
                    .map(|(t, why)| match why {
                        // The bin's frequency, with no level: neither is the tone's.
                        Some(why) => format!("near {:.1}: unresolved ({why})", t.freq_hz),
                        None => {
                            format!("{:.1}: {:.1} {}", t.freq_hz, t.level_db(), db_unit(&s.unit))
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(", "),
            };
            out.push_str(&format!(
                "  {:<10} {:<5} {:>11.4e} {:>11.4e}  {tones}\n",
                s.name,
                if s.unit.is_empty() { "-" } else { &s.unit },
                s.rms,
                s.peak
            ));
        }
    }
    out
}
