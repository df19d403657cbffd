//! Reading a signal dump back: a SigMF recording (`.sigmf-meta` + `.sigmf-data`, `rf64_le`) or
//! the CSV beside it (`sample, time_s, <channels...>`).

use crate::bounded_read::{read_bounded, Unread};
use crate::sigmf::{unit_from_name, SigmfChannel, SIGMF_DATATYPE_REAL_F64};
use crate::IoError;
use serde_json::Value;
use sha2::{Digest, Sha512};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A recording read back into memory, one vector per channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Dump {
    /// The file the samples came from (`.sigmf-data` or `.csv`).
    pub path: PathBuf,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Sample index of the first frame in the original stream.
    pub global_index: u64,
    /// Time of sample index 0, s: frame k is at `t0_s + (global_index + k) / sample_rate_hz`.
    pub t0_s: f64,
    /// Name and unit of each channel.
    pub channels: Vec<SigmfChannel>,
    /// Samples, `data[channel][frame]`.
    pub data: Vec<Vec<f64>>,
    /// The numeric `gyroemu:<key>` entries of the metadata (operating point), if any.
    pub extra: BTreeMap<String, f64>,
    /// What the reader could not check (a SigMF recording without `core:sha512`), for the
    /// user: each a sentence.
    pub notes: Vec<String>,
}

impl Dump {
    /// Frames held.
    pub fn frames(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    /// Time of frame `k`, s. The readers refuse a recording whose last index passes
    /// `u64::MAX`; a `k` beyond the frames held is summed in f64 rather than wrapped.
    pub fn time_s(&self, k: usize) -> f64 {
        let n = match self.global_index.checked_add(k as u64) {
            Some(n) => n as f64,
            None => self.global_index as f64 + k as f64,
        };
        self.t0_s + n / self.sample_rate_hz
    }

    /// The samples of the channel named `name`.
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        let k = self.channels.iter().position(|c| c.name == name)?;
        Some(&self.data[k])
    }
}

/// The path of a dump's data: `.sigmf-meta` and `.sigmf-data` give the SigMF pair, `.csv` the
/// CSV, any other path is taken as the common stem (SigMF preferred when both exist).
pub fn dump_source(path: &Path) -> DumpSource {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let with = |ext: &str, strip: &str| {
        let n = name.clone().unwrap_or_default();
        path.with_file_name(format!("{}{ext}", n.strip_suffix(strip).unwrap_or(&n)))
    };
    match name.as_deref() {
        Some(n) if n.ends_with(".sigmf-meta") || n.ends_with(".sigmf-data") => {
            let strip = &n[n.len() - ".sigmf-meta".len()..];
            DumpSource::Sigmf(with(".sigmf-meta", strip))
        }
        Some(n) if n.ends_with(".csv") => DumpSource::Csv(path.to_path_buf()),
        _ => {
            let meta = with(".sigmf-meta", "");
            if meta.exists() {
                DumpSource::Sigmf(meta)
            } else {
                DumpSource::Csv(with(".csv", ""))
            }
        }
    }
}

/// Which file a dump is read from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DumpSource {
    /// The `.sigmf-meta` path (its `.sigmf-data` beside it).
    Sigmf(PathBuf),
    /// A CSV path.
    Csv(PathBuf),
}

/// Reads the dump at `path` (see [`dump_source`]). Every refusal names the file and the key,
/// line or rule: a missing file, a device or an oversized file, a datatype other than
/// `rf64_le`, a data file whose size or SHA-512 disagrees with the metadata, captures other
/// than one from sample 0, no samples, a CSV without `sample,time_s`, with a bad number or
/// with rows not of consecutive samples.
pub fn read_dump(path: &Path) -> Result<Dump, IoError> {
    match dump_source(path) {
        DumpSource::Sigmf(meta) => read_sigmf(&meta),
        DumpSource::Csv(csv) => {
            let mut d = read_csv_dump(&csv)?;
            take_sibling_meta(&mut d);
            Ok(d)
        }
    }
}

/// A CSV carries samples only: the converter events of its window and the operating point are
/// in the SigMF metadata gyroemu writes beside it. They are taken from there when that
/// recording holds exactly the CSV's samples (same channels, first sample and bits, the rate
/// within the CSV's time stamps' rounding); otherwise a note says the CSV's own reading cannot
/// tell a clipped window from a clean one.
fn take_sibling_meta(d: &mut Dump) {
    let name = d.path.file_name().unwrap_or_default().to_string_lossy();
    let stem = name.strip_suffix(".csv").unwrap_or(&name);
    let (meta, data) = (
        d.path.with_file_name(format!("{stem}.sigmf-meta")),
        d.path.with_file_name(format!("{stem}.sigmf-data")),
    );
    let cannot = "so the converter events of its window (a clipped DAC, TIA or ADC) are unknown \
                  and a clipped window reads clean here";
    if !meta.exists() {
        d.notes.push(format!(
            "a CSV carries no converter event counts nor operating point, and no `{}` is beside \
             it: {cannot}",
            meta.display()
        ));
        return;
    }
    // Its data's size first: a recording of another length is told without reading it.
    let want = (d.frames() * d.channels.len() * 8) as u64;
    if let Ok(got) = std::fs::metadata(&data).map(|m| m.len()) {
        if got != want {
            d.notes.push(format!(
                "`{}` beside this CSV holds another recording ({got} bytes of data, the CSV's samples {want}), {cannot}",
                meta.display()
            ));
            return;
        }
    }
    let why_not = match read_sigmf(&meta) {
        Err(e) => format!("could not be read ({e})"),
        Ok(m) => match same_recording(d, &m) {
            None => {
                d.extra = m.extra;
                d.notes.push(format!(
                    "converter events and operating point from `{}`, which holds the same \
                     samples",
                    meta.display()
                ));
                return;
            }
            Some(differs) => format!("holds another recording ({differs})"),
        },
    };
    d.notes.push(format!(
        "`{}` beside this CSV {why_not}, {cannot}",
        meta.display()
    ));
}

/// What differs between a CSV's recording and a SigMF one, if anything.
fn same_recording(csv: &Dump, sigmf: &Dump) -> Option<String> {
    let names = |d: &Dump| {
        d.channels
            .iter()
            .map(|c| c.name.clone())
            .collect::<Vec<_>>()
    };
    if names(csv) != names(sigmf) {
        return Some(format!(
            "channels {:?}, the CSV's {:?}",
            names(sigmf),
            names(csv)
        ));
    }
    if csv.global_index != sigmf.global_index || csv.frames() != sigmf.frames() {
        return Some(format!(
            "{} samples from index {}, the CSV's {} from {}",
            sigmf.frames(),
            sigmf.global_index,
            csv.frames(),
            csv.global_index
        ));
    }
    // The CSV's rate is read from its time column to 1e-6 of itself (read_csv_dump refuses
    // worse).
    if (csv.sample_rate_hz / sigmf.sample_rate_hz - 1.0).abs() > 2e-6 {
        return Some(format!(
            "{} Hz, the CSV's {} Hz",
            sigmf.sample_rate_hz, csv.sample_rate_hz
        ));
    }
    // Bit for bit, but any NaN equals any NaN (a payload need not survive the CSV's text).
    let same_bits = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
    };
    let same = csv
        .data
        .iter()
        .zip(&sigmf.data)
        .all(|(a, b)| same_bits(a, b));
    (!same).then(|| "other sample values".to_string())
}

fn read_err(path: &Path, reason: impl Into<String>) -> IoError {
    IoError::Read {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// The most frames a gyroemu dump holds: its config refuses a window of more than 5e7
/// full-rate samples (`dump.duration_s`), and the decimated window is shorter.
const MAX_DUMP_FRAMES: u64 = 50_000_000;

/// A gyroemu `.sigmf-meta` is a few kB; 16 MiB is far beyond any of them.
const MAX_META_BYTES: u64 = 16 << 20;

/// The largest dump CSV gyroemu writes: [`MAX_DUMP_FRAMES`] rows of `sample`, `time_s` and at
/// most 14 channels (the decimated nodes), each cell at most 25 bytes with its separator
/// (`-2.2250738585072014e-308,`): 20 GB.
const MAX_CSV_BYTES: u64 = MAX_DUMP_FRAMES * 16 * 25;

/// Reads `path` whole if it holds at most `cap` bytes, else refuses saying `beyond`. Only a
/// regular file or a FIFO (`<(...)`) is read ([`read_bounded`]): a device such as /dev/zero
/// never ends.
fn read_bytes(path: &Path, cap: u64, beyond: &str) -> Result<Vec<u8>, IoError> {
    read_bounded(path, cap, true).map_err(|e| match e {
        Unread::Io(e) => read_err(path, e.to_string()),
        Unread::NotRegular { .. } => read_err(
            path,
            "not a regular file (nor a FIFO): a device such as /dev/zero may never end",
        ),
        Unread::TooBig(_) => read_err(path, format!("more than {cap} bytes: {beyond}")),
    })
}

/// An optional metadata field: `default` when absent (SigMF's), else `read` of it, or why not
/// (a channel count of 1e19 was once read as the default 1).
fn optional<T>(
    v: Option<&Value>,
    name: &str,
    rule: &str,
    default: T,
    read: impl Fn(&Value) -> Option<T>,
) -> Result<T, String> {
    match v {
        None => Ok(default),
        Some(v) => read(v).ok_or_else(|| format!("{name} = {v}: must be {rule}")),
    }
}

/// The numbers a recording's `gyroemu:` keys describe it with (the operating point, the
/// converter events), by name without the prefix. gyroemu writes a finite number under every
/// such key but its channel list, its doc and `t0_s` (read apart): anything else there is
/// refused, not dropped (a clip count written as "2800" was dropped, and the clipped window
/// read clean). Counts (`*_samples*`) must be whole and >= 0; frequencies (`*_hz`) >= 0, and
/// the carrier, the resonances and the low-pass cutoff > 0; the decimation and the low-pass
/// order whole and >= 1.
fn extra_keys(g: &serde_json::Map<String, Value>) -> Result<BTreeMap<String, f64>, String> {
    let mut extra = BTreeMap::new();
    for (k, v) in g {
        let Some(name) = k.strip_prefix("gyroemu:") else {
            continue;
        };
        if matches!(name, "channels" | "doc" | "t0_s") {
            continue;
        }
        let x = v
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{k} = {v}: must be a finite number (gyroemu writes one)"))?;
        let whole = x.fract() == 0.0;
        let rule = if name.contains("_samples") {
            (!(whole && x >= 0.0)).then_some("a whole count >= 0")
        } else if matches!(name, "decimation" | "lpf_order") {
            (!(whole && x >= 1.0)).then_some("a whole number >= 1")
        } else if matches!(
            name,
            "carrier_hz" | "f0_hz" | "f0_mode2_hz" | "lpf_cutoff_hz"
        ) {
            (x <= 0.0).then_some("a frequency > 0")
        } else if name.ends_with("_hz") {
            (x < 0.0).then_some("a frequency >= 0")
        } else {
            None
        };
        if let Some(rule) = rule {
            return Err(format!("{k} = {v}: must be {rule}"));
        }
        extra.insert(name.to_string(), x);
    }
    Ok(extra)
}

/// Reads a SigMF recording from its `.sigmf-meta` path.
pub fn read_sigmf(meta_path: &Path) -> Result<Dump, IoError> {
    let bad = |reason: String| read_err(meta_path, reason);
    let meta = read_bytes(
        meta_path,
        MAX_META_BYTES,
        "not a gyroemu SigMF meta (those are a few kB)",
    )?;
    let meta: Value = serde_json::from_slice(&meta).map_err(|e| bad(format!("not JSON: {e}")))?;
    let g = meta
        .get("global")
        .and_then(Value::as_object)
        .ok_or_else(|| bad("no `global` object".into()))?;
    let datatype = g.get("core:datatype").and_then(Value::as_str);
    if datatype != Some(SIGMF_DATATYPE_REAL_F64) {
        return Err(bad(format!(
            "core:datatype = {}: only `{SIGMF_DATATYPE_REAL_F64}` (what gyroemu writes) is read",
            datatype.map_or("missing".into(), |d| format!("`{d}`"))
        )));
    }
    let fs = g.get("core:sample_rate").and_then(Value::as_f64);
    let fs = match fs {
        Some(f) if f.is_finite() && f > 0.0 => f,
        _ => {
            return Err(bad(format!(
                "core:sample_rate = {}: must be a finite number > 0",
                g.get("core:sample_rate")
                    .map_or("missing".into(), Value::to_string)
            )))
        }
    };
    let n_ch = optional(
        g.get("core:num_channels"),
        "core:num_channels",
        "an integer 1..=65535",
        1,
        |v| {
            v.as_u64()
                .filter(|n| (1..=65_535).contains(n))
                .map(|n| n as usize)
        },
    )
    .map_err(bad)?;
    let channels: Vec<SigmfChannel> = match g.get("gyroemu:channels").and_then(Value::as_array) {
        Some(list) => {
            if list.len() != n_ch {
                return Err(bad(format!(
                    "gyroemu:channels names {} channel(s) but core:num_channels = {n_ch}",
                    list.len()
                )));
            }
            list.iter()
                .enumerate()
                .map(|(k, c)| {
                    let name = c.get("name").and_then(Value::as_str);
                    let name =
                        name.ok_or_else(|| bad(format!("gyroemu:channels[{k}] has no name")))?;
                    Ok(SigmfChannel {
                        name: name.to_string(),
                        unit: c
                            .get("unit")
                            .and_then(Value::as_str)
                            .unwrap_or("")
                            .to_string(),
                    })
                })
                .collect::<Result<_, IoError>>()?
        }
        None => (0..n_ch)
            .map(|k| SigmfChannel {
                name: format!("channel{k}"),
                unit: String::new(),
            })
            .collect(),
    };
    let t0_s = optional(
        g.get("gyroemu:t0_s"),
        "gyroemu:t0_s",
        "a finite number",
        0.0,
        |v| v.as_f64().filter(|t| t.is_finite()),
    )
    .map_err(bad)?;
    // gyroemu writes one capture from the file's first sample: a second one marks a
    // discontinuity that one time axis cannot describe.
    let captures = optional(
        meta.get("captures"),
        "captures",
        "an array of at most one capture (gyroemu records without a break)",
        Vec::new(),
        |v| v.as_array().filter(|c| c.len() <= 1).cloned(),
    )
    .map_err(bad)?;
    let capture = captures.first();
    optional(
        capture.and_then(|c| c.get("core:sample_start")),
        "captures[0].core:sample_start",
        "0 (the capture starts at the file's first sample)",
        (),
        |v| (v.as_u64() == Some(0)).then_some(()),
    )
    .map_err(bad)?;
    let global_index = optional(
        capture.and_then(|c| c.get("core:global_index")),
        "captures[0].core:global_index",
        "an integer >= 0",
        0,
        Value::as_u64,
    )
    .map_err(bad)?;
    let extra = extra_keys(g).map_err(bad)?;
    let name = meta_path.file_name().unwrap_or_default().to_string_lossy();
    let data_path = meta_path.with_file_name(format!(
        "{}.sigmf-data",
        name.trim_end_matches(".sigmf-meta")
    ));
    let bytes = read_bytes(
        &data_path,
        MAX_DUMP_FRAMES * 8 * n_ch as u64,
        &format!("over {MAX_DUMP_FRAMES} frames of {n_ch} f64, the longest dump gyroemu writes"),
    )?;
    if bytes.len() % (8 * n_ch) != 0 {
        return Err(read_err(
            &data_path,
            format!(
                "{} bytes is not a whole number of frames of {n_ch} little-endian f64",
                bytes.len()
            ),
        ));
    }
    let mut notes = Vec::new();
    if let Some(want) = g.get("core:sha512").and_then(Value::as_str) {
        let got: String = Sha512::digest(&bytes)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        if !want.eq_ignore_ascii_case(&got) {
            return Err(read_err(
                &data_path,
                "its SHA-512 differs from core:sha512 in the metadata (changed or truncated)",
            ));
        }
    } else {
        // gyroemu always writes the hash: without it a changed or truncated file reads clean.
        notes.push(format!(
            "no core:sha512 in the metadata: `{}` was read unchecked",
            data_path.display()
        ));
    }
    let frames = bytes.len() / (8 * n_ch);
    if frames == 0 {
        return Err(read_err(&data_path, "holds no samples (0 bytes)"));
    }
    // Frame k is at global index global_index + k: the last must be a u64 (no wrap-around).
    if global_index.checked_add(frames as u64 - 1).is_none() {
        return Err(bad(format!(
            "captures[0].core:global_index = {global_index}: its {frames} frames would run \
             past sample index {}",
            u64::MAX
        )));
    }
    let mut data = vec![Vec::with_capacity(frames); n_ch];
    for (i, w) in bytes.chunks_exact(8).enumerate() {
        let v = f64::from_le_bytes(w.try_into().expect("chunks of 8"));
        data[i % n_ch].push(v);
    }
    let dump = Dump {
        path: data_path,
        sample_rate_hz: fs,
        global_index,
        t0_s,
        channels,
        data,
        extra,
        notes,
    };
    // Every frame's time must be a number: a rate of 1e-308 Hz put them at infinity.
    if !(dump.time_s(0).is_finite() && dump.time_s(frames - 1).is_finite()) {
        return Err(bad(format!(
            "core:sample_rate = {fs:?} Hz with gyroemu:t0_s = {t0_s:?} s: the time of sample \
             index {}, t0_s + index / rate, is not a finite number of seconds",
            global_index + (frames as u64 - 1)
        )));
    }
    Ok(dump)
}

/// The line a CSV record starts on, from the position the csv crate gives it: that is where
/// it began scanning, before the blank lines it skips and the `\n` of a `\r\n`, so those are
/// counted here.
fn record_line(bytes: &[u8], pos: &csv::Position) -> u64 {
    let from = usize::try_from(pos.byte()).map_or(bytes.len(), |b| b.min(bytes.len()));
    let skipped = bytes[from..]
        .iter()
        .take_while(|&&b| b == b'\n' || b == b'\r')
        .filter(|&&b| b == b'\n')
        .count();
    pos.line() + skipped as u64
}

/// The line data row `row` (0-based) of `bytes`, already parsed once, starts on: read again,
/// as it is only wanted for a message.
fn row_line(bytes: &[u8], row: usize) -> u64 {
    let mut rd = csv::Reader::from_reader(bytes);
    let mut rec = csv::StringRecord::new();
    for _ in 0..=row {
        if !matches!(rd.read_record(&mut rec), Ok(true)) {
            return 0;
        }
    }
    rec.position().map_or(0, |p| record_line(bytes, p))
}

/// Reads a dump CSV (`sample, time_s, <channels...>`): the rate from the first and last rows'
/// sample and time, units from the channel names' suffixes. Every row must be the next
/// sample of the one before, at its time on the straight line through the first and last
/// rows: a missing, repeated or edited row would otherwise change the rate read.
pub fn read_csv_dump(path: &Path) -> Result<Dump, IoError> {
    let bytes = read_bytes(
        path,
        MAX_CSV_BYTES,
        "beyond the largest dump CSV gyroemu writes (5e7 rows of at most 16 columns)",
    )?;
    let mut rd = csv::Reader::from_reader(bytes.as_slice());
    let headers: Vec<String> = rd
        .headers()
        .map_err(|e| read_err(path, format!("bad header: {e}")))?
        .iter()
        .map(String::from)
        .collect();
    if headers.len() < 3 || headers[0] != "sample" || headers[1] != "time_s" {
        return Err(read_err(
            path,
            format!(
                "the header is `{}`: a dump CSV starts with `sample,time_s` and one channel or more",
                headers.join(",")
            ),
        ));
    }
    let n_ch = headers.len() - 2;
    let mut data = vec![Vec::new(); n_ch];
    let mut times = Vec::new();
    let mut first_last: Option<(u64, u64)> = None;
    let mut rec = csv::StringRecord::new();
    loop {
        match rd.read_record(&mut rec) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => {
                let line = record_line(&bytes, e.position().unwrap_or(rd.position()));
                return Err(read_err(path, format!("line {line}: {e}")));
            }
        }
        let line = rec.position().map_or(0, |p| record_line(&bytes, p));
        if rec.len() != headers.len() {
            return Err(read_err(
                path,
                format!(
                    "line {line} has {} fields, the header {}",
                    rec.len(),
                    headers.len()
                ),
            ));
        }
        let num = |k: usize| -> Result<f64, IoError> {
            rec[k].trim().parse::<f64>().map_err(|_| {
                read_err(
                    path,
                    format!(
                        "line {line}, column `{}`: `{}` is not a number",
                        headers[k], &rec[k]
                    ),
                )
            })
        };
        let n: u64 = rec[0].trim().parse().map_err(|_| {
            read_err(
                path,
                format!(
                    "line {line}, column `sample`: `{}` is not a sample index",
                    &rec[0]
                ),
            )
        })?;
        if let Some((_, prev)) = first_last {
            let Some(want) = prev.checked_add(1) else {
                return Err(read_err(
                    path,
                    format!("line {line}: a row after sample index {prev}, the largest there is"),
                ));
            };
            if n != want {
                return Err(read_err(
                    path,
                    format!(
                        "line {line}, column `sample`: {n}, expected {want}: each row must be \
                         the next sample of the row before (a row missing, repeated or edited)"
                    ),
                ));
            }
        }
        first_last = Some((first_last.map_or(n, |(n0, _)| n0), n));
        let t = num(1)?;
        if !t.is_finite() {
            return Err(read_err(
                path,
                format!(
                    "line {line}, column `time_s`: `{}` is not a finite time",
                    &rec[1]
                ),
            ));
        }
        times.push(t);
        for (k, ch) in data.iter_mut().enumerate() {
            ch.push(num(k + 2)?);
        }
    }
    let Some((n0, n1)) = first_last else {
        return Err(read_err(path, "holds no samples (no data rows)"));
    };
    let (t0, t1) = (times[0], times[times.len() - 1]);
    let steps = times.len() - 1;
    let fs = steps as f64 / (t1 - t0);
    if !(steps > 0 && fs.is_finite() && fs > 0.0) {
        return Err(read_err(
            path,
            "the rate cannot be read from the `sample` and `time_s` columns (one row, or time not increasing)",
        ));
    }
    // The writer prints each time as the f64 t0_s + n / fs_hz, exactly: a row strays from the
    // line through the first and last rows by a few roundings of its terms (each at most
    // max|t| + n/fs in size): 16 ulps of that bound the strays. A thousandth of a sample period on
    // top is margin, still far below a row out of step.
    let scale = times.iter().fold(0.0, |m: f64, t| m.max(t.abs())) + n1 as f64 / fs;
    let tol = 1e-3 / fs + 16.0 * f64::EPSILON * scale;
    for (i, &t) in times.iter().enumerate() {
        let want = t0 + (t1 - t0) * (i as f64 / steps as f64);
        if (t - want).abs() > tol {
            return Err(read_err(
                path,
                format!(
                    "line {}, column `time_s`: {t} s, but {want} s on the straight line through \
                     the first and last rows ({fs} Hz): the times are not those of consecutive \
                     samples",
                    row_line(&bytes, i)
                ),
            ));
        }
    }
    // The first and last times carry up to an ulp of `scale` each: far from t = 0 over few
    // rows that is a wrong rate, refused rather than printed.
    let rate_err = 2.0 * f64::EPSILON * scale / (t1 - t0);
    if rate_err > 1e-6 {
        return Err(read_err(
            path,
            format!(
                "the `time_s` column, at {t1} s, gives the rate only to {rate_err:.1e} of itself \
                 over {steps} rows (f64 rounding): read the SigMF recording instead"
            ),
        ));
    }
    let channels = headers[2..]
        .iter()
        .map(|name| SigmfChannel {
            name: name.clone(),
            unit: unit_from_name(name).to_string(),
        })
        .collect();
    Ok(Dump {
        path: path.to_path_buf(),
        sample_rate_hz: fs,
        global_index: n0,
        t0_s: t0 - n0 as f64 / fs,
        channels,
        data,
        extra: BTreeMap::new(),
        notes: Vec::new(),
    })
}
