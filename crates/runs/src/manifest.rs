//! The manifest a run or a shard writes beside its outputs: what is done, what is missing,
//! what to do next, and the canonical config (so `merge` can rebuild the results).

use crate::error::RunError;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Format tag of run and shard manifests.
pub const MANIFEST_FORMAT: &str = "gyroemu-manifest/1";

/// The manifest of a one-machine run.
pub const RUN_MANIFEST: &str = "manifest.json";

/// What an output folder holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RunKind {
    /// A sweep (`gyroemu run`): the points are its operating points.
    #[default]
    Run,
    /// A production lot (`gyroemu montecarlo`): the points are its devices.
    Montecarlo,
}

impl RunKind {
    /// The `next` of a manifest whose results were written but refuse some of their numbers
    /// (`RunError::Refused`): where they are listed, and that the same config refuses
    /// them again while a changed one meets this folder's results (hence `--force`).
    /// `rerun`: how to run it again (the run itself, or every shard and then the merge).
    pub(crate) fn refused_next(self, rerun: &str) -> String {
        let listed = match self {
            RunKind::Run => "phases refused (NaN in results.csv, listed in summary.json's `problems`)",
            RunKind::Montecarlo => {
                "devices whose numbers cannot be trusted (listed in montecarlo.json's `devices_unreliable`)"
            }
        };
        format!("{listed}: the same config refuses them again; change it and {rerun}")
    }
    /// How the user names it.
    pub fn describe(self) -> &'static str {
        match self {
            RunKind::Run => "a sweep of `gyroemu run`",
            RunKind::Montecarlo => "a lot of `gyroemu montecarlo`",
        }
    }
}

/// A shard's place in the split.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardId {
    pub index: usize,
    pub count: usize,
}

/// What a run or a shard has done, written beside its outputs (`manifest.json`, or
/// `shard-I-of-N.json`). Not part of the byte-identical results: it may name the time-free
/// facts of one particular run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Manifest {
    /// [`MANIFEST_FORMAT`].
    pub format: String,
    /// What the folder holds (absent in manifests of older versions: a sweep).
    #[serde(default)]
    pub kind: RunKind,
    /// `running`, `interrupted`, `failed` or `complete`.
    pub status: String,
    /// SHA-256 of the canonical config TOML.
    pub config_sha256: String,
    /// The shard (absent: the whole sweep).
    pub shard: Option<ShardId>,
    /// Operating points of the whole sweep (devices of the whole lot).
    pub points_total: usize,
    /// The point (device) indices this run or shard is responsible for.
    pub points: Vec<usize>,
    /// Of those, the ones whose results are in `points/`.
    pub points_done: Vec<usize>,
    /// Of those, the ones still to compute.
    pub points_missing: Vec<usize>,
    /// What to do next.
    pub next: String,
    pub gyroemu_version: String,
    /// The canonical config (`gyroemu merge` rebuilds the results from it).
    pub config_toml: String,
    /// [`BUILD`] of the binary that wrote it (empty in manifests of older versions).
    #[serde(default)]
    pub build: String,
}

/// What a result's bits depend on beyond the source, the config and the seed: whether the
/// build fuses multiply-adds (the default x86-64-v3 build does; the portable one does not, and
/// its phases differ by 1e-13 to 2.8e-8 relative). Every lane count and thread count of one build
/// gives the same bits; two builds do not, so a folder keeps to one.
pub const BUILD: &str = if cfg!(target_feature = "fma") {
    "fused multiply-add"
} else {
    "unfused multiply-add"
};

impl Manifest {
    /// A manifest for `points` of a sweep or lot, those in `done` being finished (`next`
    /// empty).
    #[allow(clippy::too_many_arguments)]
    pub fn new<V>(
        kind: RunKind,
        status: &str,
        hash: &str,
        config_toml: &str,
        shard: Option<ShardId>,
        points_total: usize,
        points: &[usize],
        done: &BTreeMap<usize, V>,
    ) -> Self {
        let (d, m): (Vec<usize>, Vec<usize>) = points.iter().partition(|i| done.contains_key(i));
        Self {
            format: MANIFEST_FORMAT.to_string(),
            kind,
            status: status.to_string(),
            config_sha256: hash.to_string(),
            shard,
            points_total,
            points: points.to_vec(),
            points_done: d,
            points_missing: m,
            next: String::new(),
            gyroemu_version: env!("CARGO_PKG_VERSION").to_string(),
            config_toml: config_toml.to_string(),
            build: BUILD.to_string(),
        }
    }

    /// Points `done` (of this manifest's) are saved.
    pub fn mark_done(&mut self, done: &[usize]) {
        self.points_missing.retain(|i| !done.contains(i));
        for &i in done {
            if self.points.contains(&i) && !self.points_done.contains(&i) {
                self.points_done.push(i);
            }
        }
        self.points_done.sort_unstable();
    }

    /// Writes the manifest atomically.
    pub fn write(&self, path: &Path) -> Result<(), RunError> {
        gyroemu_io::write_json(path, self)
            .map_err(|e| RunError::Report(gyroemu_report::ReportError::Io(e)))
    }
}

/// Reads a manifest file.
pub fn read_manifest(path: &Path) -> Result<Manifest, String> {
    let text = gyroemu_io::read_own_text(path, gyroemu_io::MAX_MANIFEST_BYTES)
        .map_err(|e| e.to_string())?;
    let m: Manifest =
        serde_json::from_str(&text).map_err(|e| gyroemu_config::plain_words(&e.to_string()))?;
    if m.format != MANIFEST_FORMAT {
        return Err(format!(
            "format `{}`, expected `{MANIFEST_FORMAT}`",
            m.format
        ));
    }
    Ok(m)
}

/// The shard manifests `shard-I-of-N.json` in `dir`, sorted by name.
pub fn shard_manifest_paths(dir: &Path) -> Result<Vec<PathBuf>, RunError> {
    files_like(dir, "shard-", ".json")
}

/// The files in `dir` whose names start with `prefix` and end with `suffix`, sorted.
pub(crate) fn files_like(dir: &Path, prefix: &str, suffix: &str) -> Result<Vec<PathBuf>, RunError> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(RunError::io(format!("cannot read `{}`", dir.display())))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .is_some_and(|n| n.starts_with(prefix) && n.ends_with(suffix))
        })
        .collect();
    v.sort();
    Ok(v)
}
