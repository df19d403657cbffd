//! Windowed signal dump for the per-sample loop: keeps only frames whose sample index falls in
//! a window, so memory is bounded by the window and not by the run length.

use crate::atomic::atomic_stream;
use crate::fast_text::{push_f64, push_i64};
use crate::sigmf::{
    check_request, unit_from_name, write_sigmf_frames, SigmfChannel, SigmfMeta, DEFAULT_HW,
};
use crate::wav::{check_wav_f32_size, wav_f32_rate_problem, write_interleaved};
use crate::IoError;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Records frames of `names.len()` channels for sample indices `n` in `[start, start + len)`.
#[derive(Clone, Debug)]
pub struct SignalRecorder {
    names: Vec<String>,
    /// Unit of each channel, written into the SigMF metadata.
    units: Vec<String>,
    fs_hz: f64,
    /// Time of sample index 0, s (a decimated stream's sample k stands for a later input).
    t0_s: f64,
    start: u64,
    len: u64,
    /// Interleaved frames, `data.len() / names.len()` of them; capacity reserved up front.
    data: Vec<f64>,
    /// Written into the SigMF metadata as `gyroemu:<key>`.
    extra: BTreeMap<String, f64>,
}

impl SignalRecorder {
    /// A recorder for channels `names`, sampled at `fs_hz`, keeping sample indices
    /// `[start_sample, start_sample + len_samples)`. Reserves `len_samples * names.len()` floats
    /// now so that [`record`](Self::record) never allocates (panics like `Vec::with_capacity`
    /// if that does not fit in memory).
    pub fn new(names: Vec<String>, fs_hz: f64, start_sample: u64, len_samples: u64) -> Self {
        // A window running past u64::MAX would make `wants` wrap around to index 0: clip it.
        let len = len_samples.min((u64::MAX - start_sample).saturating_add(1));
        let cap = usize::try_from(len)
            .ok()
            .and_then(|l| l.checked_mul(names.len()))
            .expect("SignalRecorder window len_samples * channels overflows usize");
        let units = names
            .iter()
            .map(|n| unit_from_name(n).to_string())
            .collect();
        SignalRecorder {
            names,
            units,
            fs_hz,
            t0_s: 0.0,
            start: start_sample,
            len,
            data: Vec::with_capacity(cap),
            extra: BTreeMap::new(),
        }
    }

    /// Sets the time of sample index 0 (the `time_s` column is `t0_s + n / fs_hz`): a
    /// decimated stream whose sample k is formed at input sample kM + M - 1 starts at
    /// (M - 1)/fs_in.
    pub fn with_time_origin(mut self, t0_s: f64) -> Self {
        self.t0_s = t0_s;
        self
    }

    /// Sets each channel's unit (in `names` order), for channels whose name carries none by the
    /// suffix rule (the board's drive and mixer outputs). Panics if the counts differ.
    pub fn with_units<S: AsRef<str>>(mut self, units: &[S]) -> Self {
        assert_eq!(
            units.len(),
            self.names.len(),
            "SignalRecorder::with_units needs one unit per channel"
        );
        self.units = units.iter().map(|u| u.as_ref().to_string()).collect();
        self
    }

    /// Describes the recording in its SigMF metadata: each `(key, value)` becomes
    /// `gyroemu:<key>` (keys carry their unit, e.g. `f0_hz`).
    pub fn with_extra(mut self, extra: BTreeMap<String, f64>) -> Self {
        self.extra = extra;
        self
    }

    /// The first sample index past the window.
    #[inline]
    pub fn end(&self) -> u64 {
        self.start.saturating_add(self.len)
    }

    /// True when sample index `n` lies in the window (one subtraction and one compare).
    #[inline]
    pub fn wants(&self, n: u64) -> bool {
        n.wrapping_sub(self.start) < self.len
    }

    /// Stores `frame` (one value per channel) as sample `n`; no-op outside the window, never
    /// allocates. Frames normally arrive in order; a skipped index is filled with NaN, a repeated
    /// one overwrites. Missing channels of a short frame are NaN, extra values are ignored.
    #[inline]
    pub fn record(&mut self, n: u64, frame: &[f64]) {
        if !self.wants(n) {
            return;
        }
        let ch = self.names.len();
        let at = (n - self.start) as usize * ch;
        if at >= self.data.len() {
            // Within the reserved capacity: these never reallocate.
            self.data.resize(at + ch, f64::NAN);
        }
        let dst = &mut self.data[at..at + ch];
        let m = ch.min(frame.len());
        dst[..m].copy_from_slice(&frame[..m]);
        dst[m..].fill(f64::NAN);
    }

    /// Sample rate, Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// First sample index of the window.
    #[inline]
    pub fn start(&self) -> u64 {
        self.start
    }

    /// Time of sample index 0, s.
    pub fn t0_s(&self) -> f64 {
        self.t0_s
    }

    /// Channel names in column order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Channel units in column order (see [`with_units`](Self::with_units)).
    pub fn units(&self) -> &[String] {
        &self.units
    }

    /// Number of frames held (highest recorded index - start + 1).
    pub fn len(&self) -> usize {
        if self.names.is_empty() {
            0
        } else {
            self.data.len() / self.names.len()
        }
    }

    /// True when nothing has been recorded yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A copy of channel `k` over the recorded frames. Panics if `k >= names().len()`.
    pub fn channel(&self, k: usize) -> Vec<f64> {
        let ch = self.names.len();
        assert!(k < ch, "channel {k} requested but the recorder has {ch}");
        self.data.iter().skip(k).step_by(ch).copied().collect()
    }

    /// The names of every file [`SignalRecorder::write`] writes for `stem`.
    pub fn file_names(stem: &str) -> [String; 4] {
        ["csv", "wav", "sigmf-data", "sigmf-meta"].map(|e| format!("{stem}.{e}"))
    }

    /// Writes, each atomically:
    /// - `<dir>/<stem>.csv` (columns `sample`, `time_s`, then one per name; exact float text);
    /// - `<dir>/<stem>.wav` (one 32-bit float channel per name at round(fs_hz) Hz), when a WAV
    ///   header can hold the rate ([`wav_f32_rate_problem`]; an output rate below 0.5 Hz or
    ///   more than 1e-4 of itself off its nearest whole Hz, or a byte rate past 2^32, has only
    ///   the CSV and SigMF) and float32 every sample
    ///   ([`wav_range_problem`](Self::wav_range_problem)). WAV values are the raw signals,
    ///   not normalised, so they may exceed +-1: read them with `soundfile.read(path)` or
    ///   `scipy.io.wavfile.read(path)`, not an audio player;
    /// - `<dir>/<stem>.sigmf-data` + `<dir>/<stem>.sigmf-meta` (SigMF 1.2.0, `rf64_le`, full
    ///   f64 precision at the exact fs_hz; capture `core:global_index` = first sample index,
    ///   `gyroemu:t0_s` = time origin, `gyroemu:channels` = names with their units: those of
    ///   [`with_units`](Self::with_units), else read from the names' suffixes):
    ///   `np.fromfile(path, dtype="<f8").reshape(-1, n_channels)`.
    ///
    /// The WAV size and the SigMF request are checked before any file is written. Returns the
    /// paths written (CSV, WAV when written, SigMF data, SigMF meta).
    pub fn write(&self, dir: &Path, stem: &str) -> Result<Vec<PathBuf>, IoError> {
        self.write_with(dir, stem, &BTreeMap::new())
    }

    /// [`SignalRecorder::write`] with `more` added to the metadata's `gyroemu:<key>` entries
    /// (what is known only once the window is recorded).
    pub fn write_with(
        &self,
        dir: &Path,
        stem: &str,
        more: &BTreeMap<String, f64>,
    ) -> Result<Vec<PathBuf>, IoError> {
        let csv_path = dir.join(format!("{stem}.csv"));
        let wav_path = dir.join(format!("{stem}.wav"));
        let ch = self.names.len();
        let frames = self.len();
        // No channels at all is refused by the size check (nothing to write).
        let wav = ch == 0
            || (wav_f32_rate_problem(self.fs_hz, ch as u64).is_none()
                && self.wav_range_problem().is_none());
        if wav {
            check_wav_f32_size(
                &wav_path,
                self.fs_hz.round() as u32,
                ch as u64,
                frames as u64,
            )?;
        }
        let mut meta = self.sigmf_meta(stem);
        meta.extra.extend(more.iter().map(|(k, v)| (k.clone(), *v)));
        check_request(&dir.join(format!("{stem}.sigmf-data")), &meta, ch)?;

        self.write_csv(&csv_path)?;
        let mut files = vec![csv_path];
        if wav {
            let rate = self.fs_hz.round() as u32;
            write_interleaved(&wav_path, rate, ch, frames, |i, k| self.data[i * ch + k])?;
            files.push(wav_path);
        }
        let sigmf = write_sigmf_frames(dir, stem, &meta, ch, frames, |i, k| self.data[i * ch + k])?;
        files.extend([sigmf.data_path, sigmf.meta_path]);
        Ok(files)
    }

    /// Why the float32 WAV copy would lose a sample, if it would: a finite value beyond
    /// float32's range (it would read inf) or a nonzero one below its normal range (0 or a
    /// subnormal of few digits). [`write`](Self::write) then writes no WAV; the CSV and SigMF
    /// keep f64.
    pub fn wav_range_problem(&self) -> Option<String> {
        let ch = self.names.len().max(1);
        let (i, &x) = self.data.iter().enumerate().find(|&(_, &x)| {
            let y = x as f32;
            x.is_finite() && (y.is_infinite() || (x != 0.0 && y.abs() < f32::MIN_POSITIVE))
        })?;
        Some(format!(
            "`{}` holds {x:e}, outside float32's normal range ({:e} .. {:e}): its WAV copy would read {}",
            self.names.get(i % ch).map_or("", String::as_str),
            f32::MIN_POSITIVE,
            f32::MAX,
            (x as f32)
        ))
    }

    /// Writes only the CSV (columns `sample`, `time_s`, then one per name), atomically. The
    /// text is byte for byte what [`write_csv`](crate::write_csv) writes for the same cells;
    /// numbers are laid out by hand (ryu digits) instead of through `fmt` and the csv crate,
    /// which is what makes a dump of millions of values take a fraction of a second.
    pub fn write_csv(&self, csv_path: &Path) -> Result<(), IoError> {
        let ch = self.names.len();
        let mut headers = vec!["sample".to_string(), "time_s".to_string()];
        headers.extend(self.names.iter().cloned());
        let io_err = |source| IoError::Write {
            path: csv_path.to_path_buf(),
            reason: source,
        };
        atomic_stream(csv_path, |w| {
            // The header through the csv crate (its quoting rules), the rows by hand.
            let mut head = csv::Writer::from_writer(Vec::new());
            head.write_record(&headers)
                .and_then(|_| head.flush().map_err(csv::Error::from))
                .map_err(|source| IoError::Csv {
                    path: csv_path.to_path_buf(),
                    reason: source,
                })?;
            let head = head.into_inner().map_err(|e| io_err(e.into_error()))?;
            w.write_all(&head).map_err(io_err)?;
            let mut line = Vec::with_capacity(32 * (ch + 2));
            for (i, frame) in self.data.chunks_exact(ch.max(1)).enumerate() {
                let n = self.start + i as u64;
                line.clear();
                push_i64(n as i64, &mut line);
                line.push(b',');
                push_f64(self.t0_s + n as f64 / self.fs_hz, &mut line);
                for &x in frame {
                    line.push(b',');
                    push_f64(x, &mut line);
                }
                line.push(b'\n');
                w.write_all(&line).map_err(io_err)?;
            }
            w.flush().map_err(io_err)
        })
    }

    /// SigMF description of this recorder's dump `stem`.
    fn sigmf_meta(&self, stem: &str) -> SigmfMeta {
        SigmfMeta {
            sample_rate_hz: self.fs_hz,
            channels: self
                .names
                .iter()
                .zip(&self.units)
                .map(|(n, u)| SigmfChannel {
                    name: n.clone(),
                    unit: u.clone(),
                })
                .collect(),
            description: format!(
                "gyroemu signal dump {stem}: {} frame(s) from sample index {}",
                self.len(),
                self.start
            ),
            hw: DEFAULT_HW.to_string(),
            global_index: self.start,
            t0_s: self.t0_s,
            extra: self.extra.clone(),
        }
    }
}
