//! SigMF 1.2.0 recordings (`<stem>.sigmf-data` + `<stem>.sigmf-meta`): raw little-endian f64
//! samples, channels interleaved, described by a JSON metadata file that the `sigmf` Python
//! package validates and that opens with one line of numpy:
//! `np.fromfile(stem + ".sigmf-data", dtype="<f8").reshape(-1, n_channels)`.
//!
//! Deterministic: no wall-clock time is written (`core:datetime` is omitted), so equal inputs
//! give byte-identical files.
//!
//! Extension namespace `gyroemu` (declared in `core:extensions`, optional to readers), global
//! object only:
//! - `gyroemu:channels`: `[{"name": .., "unit": ..}, ..]` in interleave order (unit `""` means
//!   dimensionless or unknown);
//! - `gyroemu:t0_s`: time in seconds of global sample index 0, so sample `k` of the file is at
//!   `t0_s + (core:global_index + k) / core:sample_rate`;
//! - `gyroemu:doc`: this description in one sentence, so the file documents itself;
//! - (1.1.0) numeric keys describing the operating point, from [`SigmfMeta::extra`]: e.g.
//!   `gyroemu:f0_hz`, `gyroemu:rate_dps`, `gyroemu:omega_hz`, `gyroemu:decimation`;
//! - (1.2.0) where the board counts its converters, their events around the window:
//!   `gyroemu:adc_clipped_samples_mode1` and the like, over `gyroemu:events_counted_samples`.

use crate::atomic::atomic_stream;
use crate::json::write_json;
use crate::IoError;
use sha2::{Digest, Sha512};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

/// SigMF specification version written in `core:version`.
pub const SIGMF_VERSION: &str = "1.2.0";

/// SigMF datatype of the data file: real 64-bit IEEE float, little-endian.
pub const SIGMF_DATATYPE_REAL_F64: &str = "rf64_le";

/// Version of the `gyroemu` metadata extension declared in `core:extensions`.
pub const GYROEMU_EXTENSION_VERSION: &str = "1.2.0";

/// One-sentence description of the `gyroemu` extension, stored as `gyroemu:doc`.
const GYROEMU_EXTENSION_DOC: &str = "gyroemu:channels lists each channel's name and unit in \
interleave order (unit \"\" = dimensionless or unknown); gyroemu:t0_s is the time in seconds of \
global sample index 0, so file sample k is at t0_s + (core:global_index + k) / core:sample_rate; \
any other numeric gyroemu:<name>_<unit> key describes the recorded operating point (e.g. \
gyroemu:carrier_hz the drive's carrier, gyroemu:omega_hz the rotating excitation's frequency); \
the *_clipped_samples_* and *_railed_samples_* keys count the converter events of the \
decimation blocks the window spans, over gyroemu:events_counted_samples input samples.";

/// Name and physical unit of one recorded channel (stored in `gyroemu:channels`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SigmfChannel {
    /// Channel name, e.g. `tia1_v`.
    pub name: String,
    /// Unit, e.g. `V`; empty for dimensionless or unknown.
    pub unit: String,
}

/// What the `.sigmf-meta` file says about a recording besides its samples.
#[derive(Clone, Debug, PartialEq)]
pub struct SigmfMeta {
    /// Sample rate, Hz (`core:sample_rate`); must be finite and > 0.
    pub sample_rate_hz: f64,
    /// One entry per channel, in the order of the `channels` argument of [`write_sigmf`].
    pub channels: Vec<SigmfChannel>,
    /// Free text (`core:description`).
    pub description: String,
    /// What produced the signal (`core:hw`).
    pub hw: String,
    /// Index of the file's first sample in the original stream (capture `core:global_index`).
    pub global_index: u64,
    /// Time of global sample index 0, s (`gyroemu:t0_s`); must be finite.
    pub t0_s: f64,
    /// Numbers describing the recording (the operating point), each written as
    /// `gyroemu:<key>`; keys carry their unit (`f0_hz`). Non-finite values are left out.
    pub extra: BTreeMap<String, f64>,
}

impl SigmfMeta {
    /// Metadata for channels `(name, unit)` at `sample_rate_hz`, with an empty description,
    /// `hw` naming the emulator, global index 0 and time origin 0 s.
    pub fn new(sample_rate_hz: f64, channels: &[(&str, &str)]) -> Self {
        SigmfMeta {
            sample_rate_hz,
            channels: channels
                .iter()
                .map(|&(name, unit)| SigmfChannel {
                    name: name.to_string(),
                    unit: unit.to_string(),
                })
                .collect(),
            description: String::new(),
            hw: DEFAULT_HW.to_string(),
            global_index: 0,
            t0_s: 0.0,
            extra: BTreeMap::new(),
        }
    }
}

/// `core:hw` used when the caller does not say otherwise.
pub const DEFAULT_HW: &str =
    "gyroemu: sample-by-sample software emulation of a MEMS vibratory gyroscope readout board (no hardware)";

/// Paths and checksum of a written recording.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SigmfFiles {
    /// `<dir>/<stem>.sigmf-data`.
    pub data_path: PathBuf,
    /// `<dir>/<stem>.sigmf-meta`.
    pub meta_path: PathBuf,
    /// Lower-case hex SHA-512 of the data file (also in `core:sha512`).
    pub sha512_hex: String,
}

/// Atomically writes `<dir>/<stem>.sigmf-data` (samples of `channels` interleaved frame by frame,
/// little-endian f64, bit-exact) then `<dir>/<stem>.sigmf-meta`. The data is streamed and hashed
/// as it is written, never held twice in memory. All channels must have equal length and
/// `meta.channels` one entry per channel; the request is checked before any file is touched.
pub fn write_sigmf(
    dir: &Path,
    stem: &str,
    meta: &SigmfMeta,
    channels: &[&[f64]],
) -> Result<SigmfFiles, IoError> {
    let data_path = dir.join(format!("{stem}.sigmf-data"));
    let frames = channels.first().map_or(0, |c| c.len());
    if let Some((k, c)) = channels.iter().enumerate().find(|(_, c)| c.len() != frames) {
        return Err(IoError::SigmfInvalid {
            path: data_path,
            reason: format!(
                "channel {k} has {} samples but channel 0 has {frames}",
                c.len()
            ),
        });
    }
    write_sigmf_frames(dir, stem, meta, channels.len(), frames, |i, k| {
        channels[k][i]
    })
}

/// Writes a recording of `frames` frames of `n_ch` channels, sample `(frame, channel)` given by
/// `at`. Shared by [`write_sigmf`] and the signal recorder (which holds interleaved frames).
pub(crate) fn write_sigmf_frames<F: Fn(usize, usize) -> f64>(
    dir: &Path,
    stem: &str,
    meta: &SigmfMeta,
    n_ch: usize,
    frames: usize,
    at: F,
) -> Result<SigmfFiles, IoError> {
    let data_path = dir.join(format!("{stem}.sigmf-data"));
    let meta_path = dir.join(format!("{stem}.sigmf-meta"));
    check_request(&data_path, meta, n_ch)?;
    let sha512_hex = write_hashed(&data_path, |sink| {
        // Encode a block of samples at a time: one hash update and one write per 8 KiB.
        let mut block = [0u8; 8192];
        let mut used = 0;
        for i in 0..frames {
            for k in 0..n_ch {
                block[used..used + 8].copy_from_slice(&at(i, k).to_le_bytes());
                used += 8;
                if used == block.len() {
                    sink.write_all(&block)?;
                    used = 0;
                }
            }
        }
        sink.write_all(&block[..used])
    })?;
    write_json(&meta_path, &meta_json(meta, n_ch, &sha512_hex))?;
    Ok(SigmfFiles {
        data_path,
        meta_path,
        sha512_hex,
    })
}

/// Rejects requests SigMF cannot describe, naming the data file and the reason.
pub(crate) fn check_request(path: &Path, meta: &SigmfMeta, n_ch: usize) -> Result<(), IoError> {
    let invalid = |reason: String| IoError::SigmfInvalid {
        path: path.to_path_buf(),
        reason,
    };
    if n_ch == 0 {
        return Err(invalid("no channels given".into()));
    }
    if meta.channels.len() != n_ch {
        return Err(invalid(format!(
            "{n_ch} channel(s) of samples but the metadata names {}",
            meta.channels.len()
        )));
    }
    if !(meta.sample_rate_hz.is_finite() && meta.sample_rate_hz > 0.0) {
        return Err(invalid(format!(
            "sample_rate_hz = {} must be finite and > 0",
            meta.sample_rate_hz
        )));
    }
    if !meta.t0_s.is_finite() {
        return Err(invalid(format!("t0_s = {} must be finite", meta.t0_s)));
    }
    Ok(())
}

/// The `.sigmf-meta` document (SigMF 1.2.0; keys come out sorted, so the text is deterministic).
fn meta_json(meta: &SigmfMeta, n_ch: usize, sha512_hex: &str) -> serde_json::Value {
    let channels: Vec<serde_json::Value> = meta
        .channels
        .iter()
        .map(|c| serde_json::json!({ "name": c.name, "unit": c.unit }))
        .collect();
    let mut doc = serde_json::json!({
        "global": {
            "core:datatype": SIGMF_DATATYPE_REAL_F64,
            "core:sample_rate": meta.sample_rate_hz,
            "core:version": SIGMF_VERSION,
            "core:num_channels": n_ch,
            "core:sha512": sha512_hex,
            "core:description": meta.description,
            "core:recorder": "gyroemu",
            "core:hw": meta.hw,
            "core:extensions": [{
                "name": "gyroemu",
                "version": GYROEMU_EXTENSION_VERSION,
                "optional": true
            }],
            "gyroemu:channels": channels,
            "gyroemu:t0_s": meta.t0_s,
            "gyroemu:doc": GYROEMU_EXTENSION_DOC,
        },
        "captures": [{
            "core:sample_start": 0,
            "core:global_index": meta.global_index
        }],
        "annotations": []
    });
    if let Some(g) = doc["global"].as_object_mut() {
        for (k, v) in meta.extra.iter().filter(|(_, v)| v.is_finite()) {
            g.insert(format!("gyroemu:{k}"), serde_json::json!(v));
        }
    }
    doc
}

/// A writer that feeds every byte to SHA-512 on its way to the file.
pub(crate) struct HashSink<'a, W: Write> {
    inner: &'a mut W,
    hasher: Sha512,
}

impl<W: Write> HashSink<'_, W> {
    /// Hashes and writes all of `bytes`.
    pub(crate) fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.hasher.update(bytes);
        self.inner.write_all(bytes)
    }
}

/// Atomically writes `path` with the bytes `fill` sends to its sink (buffered, streamed) and
/// returns their SHA-512 as lower-case hex.
pub(crate) fn write_hashed<F>(path: &Path, fill: F) -> Result<String, IoError>
where
    F: FnOnce(&mut HashSink<'_, std::io::BufWriter<&mut std::fs::File>>) -> std::io::Result<()>,
{
    let mut digest = String::new();
    atomic_stream(path, |w| {
        let mut sink = HashSink {
            inner: w,
            hasher: Sha512::new(),
        };
        fill(&mut sink).map_err(|source| IoError::Write {
            path: path.to_path_buf(),
            reason: source,
        })?;
        digest = to_hex(&sink.hasher.finalize());
        Ok(())
    })?;
    Ok(digest)
}

/// Lower-case hex of `bytes`.
fn to_hex(bytes: &[u8]) -> String {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let mut s = String::with_capacity(2 * bytes.len());
    for &b in bytes {
        s.push(HEX[usize::from(b >> 4)] as char);
        s.push(HEX[usize::from(b & 15)] as char);
    }
    s
}

/// Unit implied by a channel name's suffix under the project's naming rule (`q1_m`, `v1_m_s`,
/// `tia1_v`, `f0_hz`); `""` when the name carries no recognised unit.
pub(crate) fn unit_from_name(name: &str) -> &'static str {
    const SUFFIXES: [(&str, &str); 8] = [
        ("_rad_s", "rad/s"),
        ("_m_s", "m/s"),
        ("_rad", "rad"),
        ("_hz", "Hz"),
        ("_m", "m"),
        ("_v", "V"),
        ("_a", "A"),
        ("_s", "s"),
    ];
    SUFFIXES
        .iter()
        .find(|(suffix, _)| name.ends_with(suffix) && name.len() > suffix.len())
        .map_or("", |&(_, unit)| unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streaming_hash_of_abc_is_the_fips_180_2_vector() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("abc.bin");
        let hex = write_hashed(&path, |sink| sink.write_all(b"abc")).unwrap();
        // FIPS 180-2, appendix C.1 (SHA-512 of "abc").
        let expected = "ddaf35a193617abacc417349ae20413112e6fa4e89a97ea20a9eeee64b55d39a\
                        2192992a274fc1a836ba3c23a3feebbd454d4423643ce80e2a9ac94fa54ca49f";
        assert_eq!(hex, expected);
        assert_eq!(std::fs::read(&path).unwrap(), b"abc");
    }

    #[test]
    fn streaming_hash_matches_one_shot_hash_across_block_boundaries() {
        // 8192-byte blocks: lengths around one and two blocks exercise the partial last block.
        let dir = tempfile::tempdir().unwrap();
        for frames in [0usize, 1, 1023, 1024, 1025, 2049] {
            let x: Vec<f64> = (0..frames).map(|i| i as f64 * 0.5 - 3.0).collect();
            let meta = SigmfMeta::new(1e3, &[("x", "")]);
            let files = write_sigmf(dir.path(), "h", &meta, &[&x]).unwrap();
            let bytes = std::fs::read(&files.data_path).unwrap();
            assert_eq!(bytes.len(), 8 * frames);
            assert_eq!(files.sha512_hex, to_hex(&Sha512::digest(&bytes)));
        }
    }

    #[test]
    fn hex_encoding_is_lower_case_two_digits_per_byte() {
        assert_eq!(to_hex(&[0x00, 0x0f, 0xa0, 0xff]), "000fa0ff");
    }

    #[test]
    fn units_follow_the_name_suffix_rule() {
        assert_eq!(unit_from_name("q1_m"), "m");
        assert_eq!(unit_from_name("v1_m_s"), "m/s");
        assert_eq!(unit_from_name("tia1_v"), "V");
        assert_eq!(unit_from_name("time_s"), "s");
        assert_eq!(unit_from_name("mix1_i1"), "");
        assert_eq!(unit_from_name("drive1"), "");
        assert_eq!(unit_from_name("_m"), "");
    }
}
