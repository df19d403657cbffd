//! Folders that hold another command's results under the names this one writes. `run` writes
//! `results.csv`, `summary.json` and `plot.png` at its top; so does `reproduce` in each
//! preset's folder, and it writes a `summary.json` of its own at its top. Each had written
//! over the other's files without a word (exit 0), leaving a folder whose manifest and points
//! said one config while its results showed another.

use crate::device_file::DEVICES_DIR;
use crate::error::RunError;
use crate::manifest::{shard_manifest_paths, RUN_MANIFEST};
use crate::points::POINTS_DIR;
use std::path::{Path, PathBuf};

/// The file a folder's results are summarised in, by `run` and by `reproduce` alike.
const SUMMARY: &str = "summary.json";

/// What in `dir` says a `run` or `montecarlo` wrote there: its manifest, a shard's manifest,
/// or its saved points or devices.
fn run_marker(dir: &Path) -> Result<Option<PathBuf>, RunError> {
    let direct = [RUN_MANIFEST, POINTS_DIR, DEVICES_DIR]
        .iter()
        .map(|n| dir.join(n))
        .find(|p| p.symlink_metadata().is_ok());
    if direct.is_some() {
        return Ok(direct);
    }
    Ok(shard_manifest_paths(dir)?.into_iter().next())
}

/// Refuses `reproduce` into `out` when `out` or one of its preset folders `names` holds a
/// `run`'s or a lot's results: reproduce would write its own over them. Checked before any
/// folder is made or any sample computed.
pub fn refuse_runs_under(out: &Path, names: &[&str]) -> Result<(), RunError> {
    let dirs = std::iter::once(out.to_path_buf()).chain(names.iter().map(|n| out.join(n)));
    for dir in dirs.filter(|d| d.is_dir()) {
        if let Some(marker) = run_marker(&dir)? {
            return Err(RunError::BadInput(format!(
                "`{}` holds the results of a `gyroemu run` or `montecarlo` (`{}`): reproduce writes its own results.csv, summary.json and figures there and would replace them; choose another --out, or move them away",
                dir.display(),
                marker.display()
            )));
        }
    }
    Ok(())
}

/// Refuses `run` into `out` when it holds a `summary.json` that no run wrote there (no run
/// manifest beside it: `reproduce`'s, at its top or in a preset's folder), unless `force`,
/// which lets the run write over it.
pub fn refuse_other_summary(out: &Path, force: bool) -> Result<(), RunError> {
    let summary = out.join(SUMMARY);
    if force || !summary.exists() || run_marker(out)?.is_some() {
        return Ok(());
    }
    Err(RunError::BadInput(format!(
        "output folder `{}` holds a `{SUMMARY}` that no `gyroemu run` wrote there (no `{RUN_MANIFEST}` or points beside it: `reproduce` writes one at its top and in each preset's folder); a run writes its results.csv, {SUMMARY} and plot.png there and would replace them: choose another --out, or add --force to write over them",
        out.display()
    )))
}
