//! Reading a signal dump back: a SigMF recording (`.sigmf-meta` + `.sigmf-data`, `rf64_le`) or
//! the CSV beside it (`sample, time_s, <channels...>`).

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
}

impl Dump {
    /// Frames held.
    pub fn frames(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    /// Time of frame `k`, s.
    pub fn time_s(&self, k: usize) -> f64 {
        self.t0_s + (self.global_index + k as u64) as f64 / self.sample_rate_hz
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
/// line or rule: a missing file, a datatype other than `rf64_le`, a data file whose size or
/// SHA-512 disagrees with the metadata, a CSV without `sample,time_s` or with a bad number.
pub fn read_dump(path: &Path) -> Result<Dump, IoError> {
    match dump_source(path) {
        DumpSource::Sigmf(meta) => read_sigmf(&meta),
        DumpSource::Csv(csv) => read_csv_dump(&csv),
    }
}

fn read_err(path: &Path, reason: impl Into<String>) -> IoError {
    IoError::Read {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, IoError> {
    std::fs::read(path).map_err(|e| read_err(path, e.to_string()))
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

/// Reads a SigMF recording from its `.sigmf-meta` path.
pub fn read_sigmf(meta_path: &Path) -> Result<Dump, IoError> {
    let bad = |reason: String| read_err(meta_path, reason);
    let meta: Value = serde_json::from_slice(&read_bytes(meta_path)?)
        .map_err(|e| bad(format!("not JSON: {e}")))?;
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
    let global_index = optional(
        meta.get("captures")
            .and_then(Value::as_array)
            .and_then(|c| c.first())
            .and_then(|c| c.get("core:global_index")),
        "captures[0].core:global_index",
        "an integer >= 0",
        0,
        Value::as_u64,
    )
    .map_err(bad)?;
    let extra = g
        .iter()
        .filter_map(|(k, v)| Some((k.strip_prefix("gyroemu:")?.to_string(), v.as_f64()?)))
        .filter(|(k, _)| k != "t0_s")
        .collect();
    let name = meta_path.file_name().unwrap_or_default().to_string_lossy();
    let data_path = meta_path.with_file_name(format!(
        "{}.sigmf-data",
        name.trim_end_matches(".sigmf-meta")
    ));
    let bytes = read_bytes(&data_path)?;
    if bytes.len() % (8 * n_ch) != 0 {
        return Err(read_err(
            &data_path,
            format!(
                "{} bytes is not a whole number of frames of {n_ch} little-endian f64",
                bytes.len()
            ),
        ));
    }
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
    }
    let frames = bytes.len() / (8 * n_ch);
    let mut data = vec![Vec::with_capacity(frames); n_ch];
    for (i, w) in bytes.chunks_exact(8).enumerate() {
        let v = f64::from_le_bytes(w.try_into().expect("chunks of 8"));
        data[i % n_ch].push(v);
    }
    Ok(Dump {
        path: data_path,
        sample_rate_hz: fs,
        global_index,
        t0_s,
        channels,
        data,
        extra,
    })
}

/// Reads a dump CSV (`sample, time_s, <channels...>`): the rate from the first and last rows'
/// sample and time, units from the channel names' suffixes.
pub fn read_csv_dump(path: &Path) -> Result<Dump, IoError> {
    let bytes = read_bytes(path)?;
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
    let (mut first, mut last) = (None, None);
    for (row, rec) in rd.records().enumerate() {
        let line = row + 2;
        let rec = rec.map_err(|e| read_err(path, format!("line {line}: {e}")))?;
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
        let t = num(1)?;
        first.get_or_insert((n, t));
        last = Some((n, t));
        for (k, ch) in data.iter_mut().enumerate() {
            ch.push(num(k + 2)?);
        }
    }
    let (Some((n0, t0)), Some((n1, t1))) = (first, last) else {
        return Err(read_err(path, "no data rows"));
    };
    let fs = (n1 as f64 - n0 as f64) / (t1 - t0);
    if !(n1 > n0 && fs.is_finite() && fs > 0.0) {
        return Err(read_err(
            path,
            "the rate cannot be read from the `sample` and `time_s` columns (one row, or time not increasing)",
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
    })
}
