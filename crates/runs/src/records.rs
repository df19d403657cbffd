//! The per-item files of an output folder, whatever the item (an operating point of a sweep,
//! a device of a lot): one small JSON file per finished item in the kind's folder, named by its
//! index, carrying the hash of the config it belongs to. A resumed run, a shard and `merge`
//! find them here.

use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One finished item as stored on disk.
pub trait RecordFile: Serialize + DeserializeOwned {
    /// Format tag of the kind's files.
    const FORMAT: &'static str;
    /// The folder of the kind's files inside an output folder.
    const DIR: &'static str;
    /// The file name's stem: `<stem>-<index>.json`.
    const STEM: &'static str;
    /// The file's format tag.
    fn format(&self) -> &str;
    /// The hash of the config (sweep or lot) the item belongs to.
    fn config_sha256(&self) -> &str;
    /// The item's index.
    fn index(&self) -> usize;
    /// The file name of item `index`.
    fn file_name(index: usize) -> String {
        format!("{}-{index}.json", Self::STEM)
    }
}

/// Every record file found in a kind's folder, with its path, or why it could not be read.
pub struct Scan<R> {
    /// Readable files.
    pub files: Vec<(PathBuf, R)>,
    /// Files in the folder that are not valid record files: (path, reason).
    pub bad: Vec<(PathBuf, String)>,
}

impl<R: RecordFile> Scan<R> {
    /// The config hashes present, with how many files carry each.
    pub fn hashes(&self) -> BTreeMap<&str, usize> {
        let mut m = BTreeMap::new();
        for (_, f) in &self.files {
            *m.entry(f.config_sha256()).or_insert(0) += 1;
        }
        m
    }

    /// The records of the config `hash` with an index below `n`, by index. An index at or
    /// above `n` is an error unless `ignore_beyond` (a lot smaller than the one that wrote
    /// the folder); so is an index present twice.
    pub fn by_index(
        &self,
        hash: &str,
        n: usize,
        ignore_beyond: bool,
    ) -> Result<BTreeMap<usize, (&Path, &R)>, String> {
        let mut out: BTreeMap<usize, (&Path, &R)> = BTreeMap::new();
        for (path, f) in self.files.iter().filter(|(_, f)| f.config_sha256() == hash) {
            let i = f.index();
            if i >= n {
                if ignore_beyond {
                    continue;
                }
                return Err(format!(
                    "`{}` holds {} {i} but the config has {n} (0..{})",
                    path.display(),
                    R::STEM,
                    n.saturating_sub(1)
                ));
            }
            if let Some((prev, _)) = out.insert(i, (path, f)) {
                return Err(format!(
                    "{} {i} is duplicated: `{}` and `{}` both hold it",
                    R::STEM,
                    prev.display(),
                    path.display()
                ));
            }
        }
        Ok(out)
    }
}

/// Reads every `*.json` file in `out/<R::DIR>/` (none when the folder does not exist; hidden
/// temporary files of an interrupted write are skipped).
pub fn scan_records<R: RecordFile>(out: &Path) -> Result<Scan<R>, String> {
    let dir = out.join(R::DIR);
    let mut scan = Scan {
        files: Vec::new(),
        bad: Vec::new(),
    };
    let entries = match std::fs::read_dir(&dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(scan),
        Err(e) => return Err(format!("cannot read `{}`: {e}", dir.display())),
    };
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
            name.is_some_and(|n| !n.starts_with('.') && n.ends_with(".json"))
        })
        .collect();
    paths.sort();
    for p in paths {
        let parsed = gyroemu_io::read_own_text(&p, gyroemu_io::MAX_RECORD_BYTES)
            .map_err(|e| e.to_string())
            .and_then(|t| {
                let v = checked_value(&t)?;
                serde_json::from_value::<R>(v)
                    .map_err(|e| gyroemu_config::plain_words(&e.to_string()))
            })
            .and_then(|f| {
                if f.format() == R::FORMAT {
                    Ok(f)
                } else {
                    Err(format!("format `{}`, expected `{}`", f.format(), R::FORMAT))
                }
            });
        match parsed {
            Ok(f) => scan.files.push((p, f)),
            Err(e) => scan.bad.push((p, e)),
        }
    }
    Ok(scan)
}

/// Bytes as lowercase hex (the hashes' text).
pub(crate) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The key of a record's checksum: SHA-256 of the compact JSON of the rest of the record.
pub const CHECKSUM_KEY: &str = "sha256";

/// SHA-256 (hex) of `v`'s compact JSON (its keys sorted: serde_json's map is ordered).
fn checksum(v: &serde_json::Value) -> String {
    use sha2::{Digest, Sha256};
    let text = serde_json::to_string(v).unwrap_or_default();
    hex(&Sha256::digest(text.as_bytes()))
}

/// A record's JSON with its checksum verified and taken out. A file with no checksum (an
/// older version's) is taken as it is; one whose checksum disagrees was edited or damaged
/// after it was written: a flipped hex bit had moved a merged phase with exit 0.
fn checked_value(text: &str) -> Result<serde_json::Value, String> {
    let mut v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| gyroemu_config::plain_words(&e.to_string()))?;
    let stored = v
        .as_object_mut()
        .and_then(|o| o.remove(CHECKSUM_KEY))
        .and_then(|c| c.as_str().map(str::to_string));
    match stored {
        Some(c) if c != checksum(&v) => Err(
            "its contents do not match its sha256 (the file was edited or damaged after it was written)"
                .to_string(),
        ),
        _ => Ok(v),
    }
}

/// Atomically writes `rec` into `out/<R::DIR>/` (the folder is created), with its checksum.
/// The checksum is taken over the record as a reader parses the written text: serde_json's
/// parser can miss a decimal's nearest double by an ulp (a rate of 122.94026546559225 deg/s
/// read back one off), and a checksum of the exact values then refused an untouched file.
pub fn write_record<R: RecordFile>(out: &Path, rec: &R) -> Result<(), String> {
    let dir = out.join(R::DIR);
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create `{}`: {e}", dir.display()))?;
    // The file keeps the exact values; the sum is of what a reader parses from them.
    let mut exact = serde_json::to_value(rec).map_err(|e| e.to_string())?;
    let text = serde_json::to_string(&exact).map_err(|e| e.to_string())?;
    let read: serde_json::Value = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    let sum = checksum(&read);
    if let Some(o) = exact.as_object_mut() {
        o.insert(CHECKSUM_KEY.to_string(), sum.into());
    }
    gyroemu_io::write_json(&dir.join(R::file_name(rec.index())), &exact).map_err(|e| e.to_string())
}

/// An f64 as 16 hex digits of its IEEE bits (decimal text round-trips only with a correctly
/// rounded parser, and JSON has no NaN).
pub(crate) fn hex_f64(x: f64) -> String {
    format!("{:016x}", x.to_bits())
}

/// The f64 of [`hex_f64`]'s text.
pub(crate) fn f64_hex(s: &str) -> Result<f64, String> {
    if s.len() != 16 {
        return Err(format!("`{s}` is not 16 hex digits"));
    }
    u64::from_str_radix(s, 16)
        .map(f64::from_bits)
        .map_err(|e| format!("`{s}`: {e}"))
}
