//! Welch's averaged periodogram: periodic Hann segments, 50 % overlap, one-sided.

use crate::window::hann;
use crate::SpectrumError;
use num_complex::Complex64;
use rustfft::FftPlanner;

/// An averaged one-sided power spectrum.
#[derive(Clone, Debug, PartialEq)]
pub struct Psd {
    /// Sample rate of the input, Hz.
    pub fs_hz: f64,
    /// Samples per segment (L); bins are `fs_hz / L` apart.
    pub segment_len: usize,
    /// Segments averaged.
    pub segments: usize,
    /// Power-spectrum scaling, unit^2 per bin, for bins `k = 0 ..= L/2` at `k fs / L`: a
    /// sinusoid of amplitude A centred on bin k > 0 reads A^2/2, a constant c reads c^2 at 0.
    pub power: Vec<f64>,
    /// Equivalent noise bandwidth of the window, Hz: `fs sum(w^2) / sum(w)^2` (1.5 fs/L).
    pub enbw_hz: f64,
    /// Per bin, the standard deviation of the segments' power over their mean (over the
    /// segments, not their number less one): 0 for a steady tone or level, about 1 for
    /// Gaussian noise (a bin's power is then exponential in each segment), between for a tone
    /// whose level moves across the record. NaN with one segment, or where the mean is 0.
    pub spread: Vec<f64>,
}

impl Psd {
    /// Bin spacing, Hz.
    pub fn bin_hz(&self) -> f64 {
        self.fs_hz / self.segment_len as f64
    }

    /// Frequency of bin `k`, Hz.
    pub fn freq_hz(&self, k: usize) -> f64 {
        k as f64 * self.bin_hz()
    }

    /// Frequencies of every bin, Hz.
    pub fn freqs_hz(&self) -> Vec<f64> {
        (0..self.power.len()).map(|k| self.freq_hz(k)).collect()
    }

    /// Power spectral density, unit^2/Hz: `power / enbw_hz`. Summed times the bin spacing it
    /// gives the windowed mean square (the variance of zero-mean noise).
    pub fn density(&self) -> Vec<f64> {
        self.power.iter().map(|p| p / self.enbw_hz).collect()
    }

    /// Median of the density over the bins, unit^2/Hz: a noise-floor estimate that tones
    /// barely move (for white noise it sits a little below the mean, `2 s^2 / fs`).
    pub fn median_density(&self) -> f64 {
        let mut d = self.density();
        d.sort_by(f64::total_cmp);
        d.get(d.len() / 2).copied().unwrap_or(f64::NAN)
    }
}

/// The segment length [`welch`] uses by default for `n` samples: the largest power of two
/// that gives at least 7 half-overlapping segments (`L <= n/4`), at least 4 and at most `n`.
pub fn default_segment_len(n: usize) -> usize {
    let l = if n >= 16 {
        1usize << (n / 4).ilog2()
    } else {
        n
    };
    l.clamp(4.min(n), n)
}

/// Welch power spectrum of `x` sampled at `fs_hz`: segments of `segment_len` samples (`None`:
/// [`default_segment_len`]) starting every `segment_len - segment_len / 2` samples, each
/// multiplied by a periodic Hann window, transformed, and their one-sided |X_k|^2 averaged.
/// Bins `0 < k < L/2` carry both signs of frequency (doubled); 0 and L/2 do not. The mean is
/// not removed. Refuses non-finite samples, a bad rate, segments outside `4..=x.len()`, and a
/// spectrum beyond f64's range (see [`SpectrumError::OutOfRange`]).
pub fn welch(x: &[f64], fs_hz: f64, segment_len: Option<usize>) -> Result<Psd, SpectrumError> {
    if !(fs_hz.is_finite() && fs_hz > 0.0) {
        return Err(SpectrumError::Rate(fs_hz));
    }
    if x.len() < 4 {
        return Err(SpectrumError::TooShort {
            got: x.len(),
            min: 4,
        });
    }
    if let Some((index, &value)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(SpectrumError::NonFinite { index, value });
    }
    // Samples far from 1 are scaled by a power of two (exact) so that no square over- or
    // underflows on the way; the power is scaled back at the end.
    let peak = x.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
    let (down, up) = power_of_two_scale(peak);
    let l = segment_len.unwrap_or_else(|| default_segment_len(x.len()));
    if !(4..=x.len()).contains(&l) {
        return Err(SpectrumError::Segment {
            segment: l,
            len: x.len(),
        });
    }
    let w = hann(l);
    let s1: f64 = w.iter().sum();
    let s2: f64 = w.iter().map(|v| v * v).sum();
    let hop = l - l / 2;
    let fft = FftPlanner::<f64>::new().plan_fft_forward(l);
    let mut buf = vec![Complex64::default(); l];
    let mut scratch = vec![Complex64::default(); fft.get_inplace_scratch_len()];
    let bins = l / 2 + 1;
    let mut acc = vec![0.0; bins];
    // The squares of the powers, normalised so that the largest a segment can hold (a
    // constant at the peak: (L peak)^2) is 1, so that its square cannot overflow.
    let mut acc2 = vec![0.0; bins];
    let norm = {
        let top = l as f64 * peak * down;
        if top > 0.0 {
            1.0 / (top * top)
        } else {
            1.0
        }
    };
    let mut segments = 0;
    let mut start = 0;
    while start + l <= x.len() {
        for ((b, &xi), &wi) in buf.iter_mut().zip(&x[start..start + l]).zip(&w) {
            *b = Complex64::new(xi * down * wi, 0.0);
        }
        fft.process_with_scratch(&mut buf, &mut scratch);
        for ((a, a2), b) in acc.iter_mut().zip(&mut acc2).zip(&buf) {
            let p = b.norm_sqr();
            *a += p;
            *a2 += (p * norm) * (p * norm);
        }
        segments += 1;
        start += hop;
    }
    let scale = 1.0 / (segments as f64 * s1 * s1);
    let power = acc
        .iter()
        .enumerate()
        .map(|(k, a)| {
            // Bin L/2 exists only for even L and is its own mirror image.
            let both_signs = k > 0 && !(l.is_multiple_of(2) && k == l / 2);
            let sides = if both_signs { 2.0 } else { 1.0 };
            a * scale * sides * up * up
        })
        .collect::<Vec<f64>>();
    // Underflow: the (scaled) segments hold power, but scaled back it is below the normal
    // range. Samples only in the tail no segment reaches leave every bin at 0: not this.
    let held = acc.iter().any(|&a| a > 0.0);
    let strongest = power.iter().fold(0.0, |m: f64, p| m.max(*p));
    if power.iter().any(|p| !p.is_finite()) || (held && strongest < f64::MIN_POSITIVE) {
        return Err(SpectrumError::OutOfRange { peak });
    }
    let k = segments as f64;
    let spread = acc
        .iter()
        .zip(&acc2)
        .map(|(&a, &a2)| {
            let mean = a * norm / k;
            if segments < 2 || mean == 0.0 {
                return f64::NAN;
            }
            // Rounding can leave a steady bin's variance a hair below 0.
            ((a2 / k - mean * mean).max(0.0)).sqrt() / mean
        })
        .collect();
    Ok(Psd {
        fs_hz,
        segment_len: l,
        segments,
        power,
        enbw_hz: fs_hz * s2 / (s1 * s1),
        spread,
    })
}

/// The power of two `e` by which samples of largest magnitude `peak` are divided so that
/// their squares and sums stay in f64's normal range: 0 (no scaling, the bits of the plain
/// sums) for `peak` within 2^-300 .. 2^300, else about log2(peak), within +-1000.
pub fn scale_exponent(peak: f64) -> i32 {
    if peak == 0.0 || !peak.is_finite() || (-300.0..=300.0).contains(&peak.log2()) {
        return 0;
    }
    (peak.log2().floor() as i32).clamp(-1000, 1000)
}

/// The factors `(2^-e, 2^e)` of [`scale_exponent`] for samples of largest magnitude `peak`:
/// samples times the first have squares in range; a root mean square times the second (or a
/// power times it twice) is back in the samples' unit, exactly.
pub fn power_of_two_scale(peak: f64) -> (f64, f64) {
    let e = scale_exponent(peak);
    // 2^e for |e| <= 1000, exactly: an exponent field with a zero mantissa.
    let pow2 = |e: i32| f64::from_bits(((1023 + e) as u64) << 52);
    (pow2(-e), pow2(e))
}
