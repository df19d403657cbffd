//! Tones in a Welch spectrum: peaks, their frequency between bins and their level corrected
//! for the window's scalloping.

use crate::window::hann_response;
use crate::Psd;

/// One tone found in a spectrum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tone {
    /// Frequency, Hz, refined between bins (0 for the DC level).
    pub freq_hz: f64,
    /// Mean square of the tone, unit^2 (A^2/2 for a sinusoid of amplitude A; c^2 for DC).
    pub mean_square: f64,
    /// Bin of the peak.
    pub bin: usize,
}

impl Tone {
    /// Level in dB re 1 unit rms (dBV for volts): `10 log10(mean_square)`.
    pub fn level_db(&self) -> f64 {
        10.0 * self.mean_square.log10()
    }

    /// Peak amplitude: `sqrt(2 mean_square)` for a sinusoid, `|c|` for DC.
    pub fn amplitude(&self) -> f64 {
        if self.bin == 0 {
            self.mean_square.sqrt()
        } else {
            (2.0 * self.mean_square).sqrt()
        }
    }
}

/// The tone whose peak is bin `k`: between bins k and its larger neighbour the Hann response
/// ratio `H(1 - d) / H(d)` (0.5 at d = 0, 1 at d = 1/2) is solved for the offset d, then the
/// peak power is divided by `H(d)^2`. Exact for one stationary sinusoid far (a few bins) from
/// DC, fs/2 and other tones; the bins at 0 and L/2 are read as they are.
fn refine(psd: &Psd, k: usize) -> Tone {
    let p = &psd.power;
    let l = psd.segment_len;
    if k == 0 || k + 1 >= p.len() {
        return Tone {
            freq_hz: psd.freq_hz(k),
            mean_square: p[k],
            bin: k,
        };
    }
    let (side, neighbour) = if p[k + 1] >= p[k - 1] {
        (1.0, p[k + 1])
    } else {
        (-1.0, p[k - 1])
    };
    let r = (neighbour / p[k]).sqrt();
    let ratio = |d: f64| hann_response(1.0 - d, l) / hann_response(d, l);
    let d = if r <= ratio(0.0) {
        0.0
    } else {
        // The ratio grows monotonically on [0, 1): bisect to full precision.
        let (mut lo, mut hi) = (0.0, 0.999_999);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if ratio(mid) < r {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    };
    let g = hann_response(d, l);
    Tone {
        freq_hz: (k as f64 + side * d) * psd.bin_hz(),
        mean_square: p[k] / (g * g),
        bin: k,
    }
}

/// Bins from DC and from fs/2 within which a tone's mirror image (a real signal's -f, or
/// fs - f) falls in the Hann window's main lobe beside it: [`refine`] reads neither its level
/// nor its frequency there.
pub const EDGE_BINS: usize = 3;

/// Bin 1 over bin 0 of a constant through the Hann window is exactly 1/4, doubled in the
/// one-sided spectrum (bin 1 holds both signs). A tone within 0.1 bin of DC (up to about
/// 0.52, with the record's phases) is, over a segment, a slowly moving level, and is read as
/// one; 0.4 bin gives about 0.84.
const DC_LEAK_MAX: f64 = 0.52;

/// A tone is read as steady only when its bin's power moves between the Welch segments by at
/// most this fraction (1 sigma, [`Psd::spread`]): a steady tone 20 dB above Gaussian noise
/// moves by about 0.17, noise itself by about 1 (its power is exponential in each segment).
pub const SPREAD_MAX: f64 = 0.5;

/// The spread is judged from this many segments on: below it one noise bin's spread is too
/// uncertain to tell.
pub const SPREAD_MIN_SEGMENTS: usize = 4;

/// A tone's two neighbouring bins must hold its window's leakage within this fraction of its
/// peak bin's power, beside what noise of the local level moves them by. Two unit tones 1.5
/// bins apart leave 0.07 there, while the refinement's own error from noise 20 dB down,
/// averaged over 7 segments, is about 0.01.
const SHAPE_TOLERANCE: f64 = 0.03;

/// Why `t` (a peak of `psd`) is not one tone read exactly, if it is not:
/// - a peak within [`EDGE_BINS`] of DC that is not a DC level (its bin 1 more than a
///   constant's leakage), or within [`EDGE_BINS`] of fs/2 (a tone at fs/2 shows only
///   A cos(phase)). There the tone and its mirror image share bins: a 10 Hz tone in 24.7 Hz
///   bins read as a DC of -4.1 dB for -3.0, and one 0.43 bin below fs/2 was read 50 Hz and
///   1.4 dB off;
/// - a peak above DC whose power moves between the segments as noise's does ([`SPREAD_MAX`]): pass-band
///   noise of a low-passed node, a handful of bins wide, stood 20 dB above a median the stop
///   band set and was listed as tones;
/// - a peak whose neighbouring bins are not its window's leakage: another tone within about
///   three bins (two unit tones two bins apart read 1.6 dB low and a quarter bin off each, a
///   rotating drive's sidebands at fc +- Omega as two tones 1 dB high). From 2.5 to 3 bins
///   apart both tones are often read right and sometimes said unresolved.
pub fn unresolved(psd: &Psd, t: &Tone) -> Option<String> {
    let p = &psd.power;
    let (k, last, bin) = (t.bin, p.len() - 1, tidy(psd.bin_hz()));
    let dc = k == 0 && p.len() > 1 && p[1] <= DC_LEAK_MAX * p[0];
    if k < EDGE_BINS && !dc {
        return Some(format!(
            "a tone within {EDGE_BINS} bins of DC ({bin} Hz bins) overlaps its mirror image: its frequency and level are not read; record a longer window"
        ));
    }
    if k + EDGE_BINS > last {
        return Some(format!(
            "a tone within {EDGE_BINS} bins of fs/2 ({} Hz, {bin} Hz bins) overlaps its mirror image: its frequency and level are not read",
            tidy(psd.fs_hz / 2.0)
        ));
    }
    // A DC level is read as the record's mean square even as it moves (a slow modulation,
    // DC_LEAK_MAX), so only tones are asked to stay put.
    let spread = psd.spread.get(k).copied().unwrap_or(f64::NAN);
    if k > 0 && psd.segments >= SPREAD_MIN_SEGMENTS && spread > SPREAD_MAX {
        return Some(format!(
            "its power moves by {:.0} % (1 sigma) between the {} Welch segments, as noise's does (about 100 %) or a tone's whose level or frequency changes within the record: it is not read as one steady tone",
            100.0 * spread,
            psd.segments
        ));
    }
    if k > 0 && !leaks_as_one_tone(psd, t) {
        return Some(format!(
            "its neighbouring bins are not one tone's leakage: another tone within about 3 bins ({bin} Hz bins) shares them, so neither frequency nor level is read; record a longer window"
        ));
    }
    None
}

/// Whether the bins either side of `t`'s peak, and the next one beyond its larger neighbour,
/// hold what one tone at its refined frequency and level leaks there through the Hann window
/// (within [`SHAPE_TOLERANCE`] of the peak bin's power, beside what noise of the local level
/// moves them by). The peak and its larger neighbour fixed the refinement, so they match by
/// construction when one tone holds them; a second tone in either (another within about two
/// bins) moves the refined offset, and the other bins then disagree. The bin two away on the
/// smaller side is not asked: a tone there barely moves the reading.
fn leaks_as_one_tone(psd: &Psd, t: &Tone) -> bool {
    let p = &psd.power;
    let (k, l) = (t.bin, psd.segment_len);
    let offset = t.freq_hz / psd.bin_hz() - k as f64;
    // Noise of mean power s2 in a bin holding power P moves its average over K segments by
    // s2 on average and by sqrt((2 P s2 + s2^2) / K) at 1 sigma (a complex Gaussian added to
    // a phasor); the local median of exponential powers is ln 2 of their mean.
    let s2 = local_median(p, k) / core::f64::consts::LN_2;
    let segments = psd.segments.max(1) as f64;
    // The bin beyond the larger neighbour too: a tone there adds to that neighbour, which set
    // the offset, and leaves the smaller one nearly as one tone's would be.
    let beyond = if offset >= 0.0 {
        (k + 2 < p.len()).then_some(k + 2)
    } else {
        k.checked_sub(2)
    };
    [Some(k - 1), Some(k + 1), beyond]
        .into_iter()
        .flatten()
        .all(|j| {
            let g = hann_response(j as f64 - k as f64 - offset, l);
            let want = t.mean_square * g * g;
            let noise = s2 + 4.0 * ((2.0 * want * s2 + s2 * s2) / segments).sqrt();
            (p[j] - want).abs() <= SHAPE_TOLERANCE * p[k] + noise
        })
}

/// `x` to nine significant digits, written shortest: 468.75 where 2400 / 5.12 gives
/// 468.74999999999994.
fn tidy(x: f64) -> String {
    format!("{x:.8e}").parse::<f64>().unwrap_or(x).to_string()
}

/// The median of the bins within [`FLOOR_HALF_WIDTH`] of bin `k`.
fn local_median(p: &[f64], k: usize) -> f64 {
    let mut near =
        p[k.saturating_sub(FLOOR_HALF_WIDTH)..(k + FLOOR_HALF_WIDTH + 1).min(p.len())].to_vec();
    near.sort_by(f64::total_cmp);
    near[near.len() / 2]
}

/// Bins on each side of a peak whose median is the noise floor it must clear.
const FLOOR_HALF_WIDTH: usize = 32;

/// The strongest `max` tones of `psd`, strongest first: local maxima of the power spectrum (DC
/// counts when bin 0 exceeds bin 1) at least `min_snr_db` above the median of the bins within
/// `FLOOR_HALF_WIDTH` (32) of them. The floor is local because a coloured spectrum has no one
/// floor: on a low-passed node most bins lie in the stop band, and pass-band noise stood 20 dB
/// above the whole spectrum's median and was listed as tones. A single sinusoid's leakage,
/// sampled at the bins, falls monotonically away from its peak, so its sidelobes are not
/// reported as tones.
pub fn find_tones(psd: &Psd, max: usize, min_snr_db: f64) -> Vec<Tone> {
    let p = &psd.power;
    if p.len() < 2 {
        return Vec::new();
    }
    let snr = 10f64.powf(min_snr_db / 10.0);
    let floor = |k: usize| local_median(p, k) * snr;
    let last = p.len() - 1;
    let mut peaks: Vec<usize> = (0..p.len())
        .filter(|&k| {
            let left = k == 0 || p[k] > p[k - 1];
            let right = k == last || p[k] >= p[k + 1];
            left && right && p[k] > 0.0 && p[k] > floor(k)
        })
        .collect();
    peaks.sort_by(|&a, &b| p[b].total_cmp(&p[a]));
    peaks.truncate(max);
    peaks.into_iter().map(|k| refine(psd, k)).collect()
}

/// The tone at the strongest bin within `bins` bins of `freq_hz` (a known frequency such as
/// the carrier), refined like [`find_tones`]; `None` outside the spectrum.
pub fn tone_near(psd: &Psd, freq_hz: f64, bins: usize) -> Option<Tone> {
    let c = (freq_hz / psd.bin_hz()).round();
    if !(c >= 0.0 && (c as usize) < psd.power.len()) {
        return None;
    }
    let c = c as usize;
    let lo = c.saturating_sub(bins);
    let hi = (c + bins).min(psd.power.len() - 1);
    let k = (lo..=hi).max_by(|&a, &b| psd.power[a].total_cmp(&psd.power[b]))?;
    Some(refine(psd, k))
}
