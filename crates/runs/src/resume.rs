//! Resuming in an output folder: its point files are checked against the config hash (reused
//! when they match, refused or cleared with `force` when not), unreadable ones reported.

use crate::error::RunError;
use crate::manifest::{read_manifest, shard_manifest_paths, RUN_MANIFEST};
use crate::points::{scan_points, POINTS_DIR};
use gyroemu_board::LaneResult;
use gyroemu_experiment::Reporter;
use gyroemu_report::RUN_FILES;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The results of a previous run in `out` for the config `hash`, by point index. Results of
/// another config are refused (exit 2) unless `force`, which deletes them and the outputs
/// built from them. Unreadable point files are reported and recomputed.
pub fn previous_points(
    out: &Path,
    hash: &str,
    n_points: usize,
    force: bool,
    reporter: &dyn Reporter,
) -> Result<BTreeMap<usize, LaneResult>, RunError> {
    let scan = scan_points(out).map_err(RunError::BadInput)?;
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
            return Err(RunError::BadInput(format!(
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

/// Deletes the point files, manifests and final outputs of a previous run in `out`.
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
    for f in files.iter().filter(|f| f.exists()) {
        std::fs::remove_file(f)
            .map_err(RunError::io(format!("cannot delete `{}`", f.display())))?;
    }
    Ok(())
}
