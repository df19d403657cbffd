//! Multichannel 32-bit float WAV files (open with `soundfile.read` or `scipy.io.wavfile.read`).

use crate::atomic::atomic_stream;
use crate::IoError;
use std::path::Path;

/// Bytes hound writes before the samples of a 32-bit float file (RIFF + WAVEFORMATEXTENSIBLE fmt
/// chunk + data chunk header). hound uses the extensible format for every sample width above 16 bits.
pub const WAV_F32_HEADER_BYTES: u64 = 68;

/// Largest sample payload a RIFF file can describe: its 32-bit size field counts the file minus 8 bytes.
pub const WAV_F32_MAX_DATA_BYTES: u64 = u32::MAX as u64 - (WAV_F32_HEADER_BYTES - 8);

/// The largest relative error of a WAV's whole-Hz rate against the recording's (0.5 Hz at
/// 5 kHz); a rate further off gets no WAV.
pub const WAV_RATE_REL_TOL: f64 = 1e-4;

/// Why a float WAV of `channels` channels cannot describe a rate of `fs_hz` (a WAV rate is a
/// whole number of Hz in 1..=2^32-1, within [`WAV_RATE_REL_TOL`] of the rate, and its
/// byte-rate field, rate x channels x 4, is 32-bit too), or `None` when it can. The CSV and
/// SigMF beside it carry any rate.
pub fn wav_f32_rate_problem(fs_hz: f64, channels: u64) -> Option<String> {
    let rate = fs_hz.round();
    if !(rate >= 1.0 && rate <= f64::from(u32::MAX)) {
        return Some(format!(
            "the sample rate {fs_hz} Hz does not round to a WAV sample rate in 1..=2^32-1 Hz"
        ));
    }
    // A whole-Hz rate far from the true one scales every frequency and time read from the
    // file (1.5 Hz was written as 2 Hz, 33 % off); at or above 5 kHz the rounding is within it.
    let off = (rate - fs_hz).abs() / fs_hz;
    if off > WAV_RATE_REL_TOL {
        return Some(format!(
            "the sample rate {fs_hz} Hz rounds to the WAV sample rate {rate} Hz, {off:.1e} off (more than {WAV_RATE_REL_TOL:e}): a whole-Hz rate cannot describe it"
        ));
    }
    if rate * channels as f64 * 4.0 > f64::from(u32::MAX) {
        return Some(format!(
            "byte rate {rate} Hz x {channels} channels x 4 bytes overflows the 32-bit WAV byte-rate field"
        ));
    }
    None
}

/// Checks a float-WAV request without touching memory or disk and returns its sample payload in
/// bytes. hound keeps sizes in `u32` and wraps silently past 4 GiB, and computes
/// `rate * channels * 4` in `u32` too, so both are checked here first.
pub fn check_wav_f32_size(
    path: &Path,
    sample_rate_hz: u32,
    channels: u64,
    frames: u64,
) -> Result<u64, IoError> {
    let invalid = |reason: String| IoError::WavInvalid {
        path: path.to_path_buf(),
        reason,
    };
    if channels == 0 {
        return Err(invalid("no channels given".into()));
    }
    if channels > u64::from(u16::MAX) {
        return Err(invalid(format!(
            "{channels} channels given, WAV allows at most {}",
            u16::MAX
        )));
    }
    if sample_rate_hz == 0 {
        return Err(invalid("sample rate is 0 Hz".into()));
    }
    if u64::from(sample_rate_hz) * channels * 4 > u64::from(u32::MAX) {
        return Err(invalid(format!(
            "byte rate {sample_rate_hz} Hz x {channels} channels x 4 bytes overflows the 32-bit WAV byte-rate field"
        )));
    }
    let data = u128::from(channels) * u128::from(frames) * 4;
    if data > u128::from(WAV_F32_MAX_DATA_BYTES) {
        return Err(IoError::WavTooLarge {
            path: path.to_path_buf(),
            channels,
            frames,
            data_bytes: u64::try_from(data).unwrap_or(u64::MAX),
            limit_bytes: WAV_F32_MAX_DATA_BYTES,
        });
    }
    Ok(data as u64)
}

/// Atomically writes one WAV channel per slice as interleaved 32-bit IEEE float (`x as f32`).
/// Values are written as they are, not normalised: a float WAV may exceed +-1, which
/// soundfile/scipy return unchanged (some audio players clip). All slices must have equal length;
/// sizes are validated before any byte is written.
pub fn write_wav_f32(path: &Path, sample_rate_hz: u32, channels: &[&[f64]]) -> Result<(), IoError> {
    let frames = channels.first().map_or(0, |c| c.len());
    if let Some((k, c)) = channels.iter().enumerate().find(|(_, c)| c.len() != frames) {
        return Err(IoError::WavInvalid {
            path: path.to_path_buf(),
            reason: format!(
                "channel {k} has {} samples but channel 0 has {frames}",
                c.len()
            ),
        });
    }
    check_wav_f32_size(path, sample_rate_hz, channels.len() as u64, frames as u64)?;
    write_interleaved(path, sample_rate_hz, channels.len(), frames, |i, k| {
        channels[k][i]
    })
}

/// Writes `frames` frames of `n_ch` channels, sample `(frame, channel)` given by `at`.
/// Callers must have run [`check_wav_f32_size`].
pub(crate) fn write_interleaved<F: Fn(usize, usize) -> f64>(
    path: &Path,
    sample_rate_hz: u32,
    n_ch: usize,
    frames: usize,
    at: F,
) -> Result<(), IoError> {
    let spec = hound::WavSpec {
        channels: n_ch as u16,
        sample_rate: sample_rate_hz,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let wav_err = |source| IoError::Wav {
        path: path.to_path_buf(),
        reason: source,
    };
    atomic_stream(path, |w| {
        let mut ww = hound::WavWriter::new(w, spec).map_err(wav_err)?;
        for i in 0..frames {
            for k in 0..n_ch {
                ww.write_sample(at(i, k) as f32).map_err(wav_err)?;
            }
        }
        ww.finalize().map_err(wav_err)
    })
}
