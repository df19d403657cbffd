//! Safe, resumable outputs of `gyroemu run`: the output folder's point files are checked
//! against the config hash (reused when they match, refused or cleared with `--force` when
//! not), a manifest records what is done, and Ctrl-C (or SIGTERM from a scheduler) stops the
//! sweep cleanly so that a rerun of the same command picks up where it stopped.

use crate::commands::BadInput;
use anyhow::Result;
use gyroemu_experiment::board::LaneResult;
use gyroemu_experiment::checkpoint::{scan_points, POINTS_DIR};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// Exit code of a run stopped by Ctrl-C (128 + SIGINT, the shell convention).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Format tag of run and shard manifests.
pub const MANIFEST_FORMAT: &str = "gyroemu-manifest/1";

/// The manifest of a one-machine run.
pub const RUN_MANIFEST: &str = "manifest.json";

/// A run stopped by Ctrl-C after saving what was finished (exit code 130).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Interrupted(pub String);

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
    /// `running`, `interrupted` or `complete`.
    pub status: String,
    /// SHA-256 of the canonical config TOML.
    pub config_sha256: String,
    /// The shard (absent: the whole sweep).
    pub shard: Option<ShardId>,
    /// Operating points of the whole sweep.
    pub points_total: usize,
    /// The point indices this run or shard is responsible for.
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
}

impl Manifest {
    /// A manifest for `points` of a sweep, those in `done` being finished (`next` empty).
    pub fn new(
        status: &str,
        hash: &str,
        config_toml: &str,
        shard: Option<ShardId>,
        points_total: usize,
        points: &[usize],
        done: &BTreeMap<usize, LaneResult>,
    ) -> Self {
        let (d, m): (Vec<usize>, Vec<usize>) = points.iter().partition(|i| done.contains_key(i));
        Self {
            format: MANIFEST_FORMAT.to_string(),
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
        }
    }

    /// Writes the manifest atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        gyroemu_io::write_json(path, self)?;
        Ok(())
    }
}

/// Reads a manifest file.
pub fn read_manifest(path: &Path) -> Result<Manifest, String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let m: Manifest = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    if m.format != MANIFEST_FORMAT {
        return Err(format!(
            "format `{}`, expected `{MANIFEST_FORMAT}`",
            m.format
        ));
    }
    Ok(m)
}

/// The shard manifests `shard-I-of-N.json` in `dir`, sorted by name.
pub fn shard_manifest_paths(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .is_some_and(|n| n.starts_with("shard-") && n.ends_with(".json"))
        })
        .collect();
    v.sort();
    Ok(v)
}

/// The results of a previous run in `out` for the config `hash`, by point index. Results of
/// another config are refused (exit 2) unless `force`, which deletes them and the outputs
/// built from them. Unreadable point files are reported and recomputed.
pub fn previous_points(
    out: &Path,
    hash: &str,
    n_points: usize,
    force: bool,
) -> Result<BTreeMap<usize, LaneResult>> {
    let scan = scan_points(out).map_err(BadInput)?;
    let mut foreign: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for (p, f) in &scan.files {
        if f.config_sha256 != hash {
            foreign
                .entry(f.config_sha256.clone())
                .or_default()
                .push(p.clone());
        }
    }
    let mut manifests = shard_manifest_paths(out)?;
    manifests.push(out.join(RUN_MANIFEST));
    for p in manifests.iter().filter(|p| p.exists()) {
        if let Ok(m) = read_manifest(p) {
            if m.config_sha256 != hash {
                foreign.entry(m.config_sha256).or_default().push(p.clone());
            }
        }
    }
    if let Some((other, paths)) = foreign.iter().next() {
        if !force {
            return Err(BadInput(format!(
                "output folder `{}` holds results of another config (sha256 {} in `{}`{}), not of \
                 this one (sha256 {hash}): choose another --out, or add --force to delete them",
                out.display(),
                &other[..other.len().min(12)],
                paths[0].display(),
                if paths.len() > 1 {
                    format!(" and {} more files", paths.len() - 1)
                } else {
                    String::new()
                },
            ))
            .into());
        }
        eprintln!(
            "--force: deleting the results of another config in `{}`",
            out.display()
        );
        clear_out(out)?;
        return Ok(BTreeMap::new());
    }
    for (p, why) in &scan.bad {
        eprintln!(
            "warning: ignoring `{}` (not a gyroemu point file: {why})",
            p.display()
        );
    }
    scan.lanes(hash, n_points).map_err(|e| BadInput(e).into())
}

/// Deletes the point files, manifests and final outputs of a previous run in `out`.
fn clear_out(out: &Path) -> Result<()> {
    let points = out.join(POINTS_DIR);
    if points.exists() {
        std::fs::remove_dir_all(&points)?;
    }
    let mut files = shard_manifest_paths(out)?;
    for f in [RUN_MANIFEST, "results.csv", "summary.json", "plot.png"] {
        files.push(out.join(f));
    }
    for f in files.iter().filter(|f| f.exists()) {
        std::fs::remove_file(f)?;
    }
    Ok(())
}

static CANCEL: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The flag raised by Ctrl-C (SIGINT) or SIGTERM; the handler is installed on first call. A
/// second signal exits at once with 130 (files being written are temporaries, never left
/// under their final names).
pub fn cancel_flag() -> Arc<AtomicBool> {
    CANCEL
        .get_or_init(|| {
            let flag = Arc::new(AtomicBool::new(false));
            let f = flag.clone();
            let installed = ctrlc::set_handler(move || {
                if f.swap(true, Ordering::SeqCst) {
                    eprintln!("\ninterrupted again: exiting now");
                    std::process::exit(EXIT_INTERRUPTED.into());
                }
                eprintln!(
                    "\ninterrupt: saving the finished points and stopping \
                     (Ctrl-C again to quit at once)"
                );
            });
            if let Err(e) = installed {
                eprintln!("warning: Ctrl-C will not save progress: {e}");
            }
            flag
        })
        .clone()
}
