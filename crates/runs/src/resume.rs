//! Resuming in an output folder: its point files are checked against the config hash (reused
//! when they match, refused or cleared with `force` when not), unreadable ones reported.

use crate::config_diff::{config_diff, describe_diff};
use crate::dumps::{dump_files, remove_files};
use crate::error::RunError;
use crate::manifest::{read_manifest, shard_manifest_paths, RUN_MANIFEST};
use crate::points::{config_hash, scan_points, POINTS_DIR};
use gyroemu_board::LaneResult;
use gyroemu_config::Config;
use gyroemu_experiment::Reporter;
use gyroemu_report::RUN_FILES;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The results of a previous run in `out` for `cfg` (by its [`config_hash`]), by point
/// index. Results of another config are refused (exit 2), naming the keys that differ,
/// unless `force`, which deletes them and everything built from them. Unreadable point files
/// are reported and recomputed.
pub fn previous_points(
    out: &Path,
    cfg: &Config,
    n_points: usize,
    force: bool,
    reporter: &dyn Reporter,
) -> Result<BTreeMap<usize, LaneResult>, RunError> {
    let hash = &config_hash(cfg);
    let scan = scan_points(out).map_err(RunError::BadInput)?;
    let mut foreign: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for (p, f) in &scan.files {
        if &f.config_sha256 != hash {
            foreign
                .entry(f.config_sha256.clone())
                .or_default()
                .push(p.clone());
        }
    }
    // The config text of another config's manifest, to say what differs.
    let mut other_toml: BTreeMap<String, (PathBuf, String)> = BTreeMap::new();
    let mut manifests = shard_manifest_paths(out)?;
    manifests.push(out.join(RUN_MANIFEST));
    for p in manifests.iter().filter(|p| p.exists()) {
        if let Ok(m) = read_manifest(p) {
            if &m.config_sha256 != hash {
                foreign
                    .entry(m.config_sha256.clone())
                    .or_default()
                    .push(p.clone());
                other_toml
                    .entry(m.config_sha256)
                    .or_insert((p.clone(), m.config_toml));
            }
        }
    }
    if let Some((other, paths)) = foreign.iter().next() {
        if !force {
            let differs = match other_toml.get(other) {
                Some((p, text)) => match config_diff(text, cfg) {
                    Ok(d) if d.is_empty() => format!(
                        "; `{}` lists the same settings: it was written by an older gyroemu                          whose config hash differs",
                        p.display()
                    ),
                    Ok(d) => format!(
                        "; the configs differ in {} (from `{}`)",
                        describe_diff(&d, 12),
                        p.display()
                    ),
                    Err(e) => format!("; the config in `{}` does not parse: {e}", p.display()),
                },
                None => "; no manifest says which config that was".to_string(),
            };
            return Err(RunError::BadInput(format!(
                "output folder `{}` holds results of another config (sha256 {} in `{}`{}), not of \
                 this one (sha256 {}){differs}: choose another --out, or add --force to delete \
                 them",
                out.display(),
                &other[..other.len().min(12)],
                paths[0].display(),
                if paths.len() > 1 {
                    format!(" and {} more files", paths.len() - 1)
                } else {
                    String::new()
                },
                &hash[..hash.len().min(12)],
            )));
        }
        reporter.note(&format!(
            "--force: deleting the results of another config in `{}`",
            out.display()
        ));
        clear_out(out)?;
        return Ok(BTreeMap::new());
    }
    for (p, why) in &scan.bad {
        reporter.warn(&format!(
            "ignoring `{}` (not a gyroemu point file: {why})",
            p.display()
        ));
    }
    scan.lanes(hash, n_points).map_err(RunError::BadInput)
}

/// Deletes the point files, manifests, final outputs and signal dumps of a previous run in
/// `out`.
fn clear_out(out: &Path) -> Result<(), RunError> {
    let points = out.join(POINTS_DIR);
    if points.exists() {
        std::fs::remove_dir_all(&points).map_err(RunError::io(format!(
            "cannot delete `{}`",
            points.display()
        )))?;
    }
    let mut files = shard_manifest_paths(out)?;
    files.extend([RUN_MANIFEST].iter().chain(&RUN_FILES).map(|f| out.join(f)));
    files.retain(|f| f.exists());
    files.extend(dump_files(out));
    remove_files(&files)
}
