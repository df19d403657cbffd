//! The signal dump of a run in its output folder. `[dump]` does not change the results, so
//! it does not change the config hash and saved points are reused; but the dump is recorded
//! while its point runs, so a folder whose last run recorded another `[dump]` (or none) gets
//! its dump files deleted and the dumped point computed again.

use crate::error::RunError;
use crate::manifest::read_manifest;
use crate::points::{PointFile, POINTS_DIR};
use crate::records::RecordFile;
use gyroemu_board::{LaneResult, Probe};
use gyroemu_config::Config;
use gyroemu_experiment::{dump_point, Reporter, DUMP_STEM};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The dump files present in `out`.
pub fn dump_files(out: &Path) -> Vec<PathBuf> {
    Probe::file_names(DUMP_STEM)
        .iter()
        .map(|n| out.join(n))
        .filter(|p| p.exists())
        .collect()
}

/// Deletes `files`.
pub(crate) fn remove_files(files: &[PathBuf]) -> Result<(), RunError> {
    for f in files {
        std::fs::remove_file(f)
            .map_err(RunError::io(format!("cannot delete `{}`", f.display())))?;
    }
    Ok(())
}

/// The `[dump]` table of a canonical config text (`None`: no dump).
pub(crate) fn dump_table(config_toml: &str) -> Option<toml::Value> {
    let t: toml::Table = toml::from_str(config_toml).ok()?;
    t.get("dump").cloned()
}

/// What this run does about the dump in `out`, given the folder's last manifest of the same
/// points (`manifest`, whose config text is compared) and the points reused (`prev`). When
/// the last run recorded another `[dump]`: deletes the dump files if `owns_files` (a whole
/// run, or the shard of the dumped point), and if this run has a dump of one of its points
/// (`mine`), drops that point from `prev` and deletes its file, so it runs again.
#[allow(clippy::too_many_arguments)]
pub(crate) fn reconcile_dump(
    cfg: &Config,
    config_toml: &str,
    out: &Path,
    manifest: &Path,
    mine: &[usize],
    owns_files: bool,
    prev: &mut BTreeMap<usize, LaneResult>,
    reporter: &dyn Reporter,
) -> Result<(), RunError> {
    let last = read_manifest(manifest)
        .ok()
        .map(|m| dump_table(&m.config_toml));
    if last.as_ref() == Some(&dump_table(config_toml)) {
        return recompute_lost_dump(cfg, out, mine, owns_files, prev, reporter);
    }
    let stale = dump_files(out);
    if owns_files && !stale.is_empty() {
        remove_files(&stale)?;
        let names: Vec<String> = stale
            .iter()
            .map(|p| {
                p.file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned()
            })
            .collect();
        reporter.note(&format!(
            "deleted the dump of an earlier run's [dump] in `{}`: {}",
            out.display(),
            names.join(", ")
        ));
    }
    if let Some(i) = dump_point(cfg).filter(|i| mine.contains(i)) {
        if forget_point(out, prev, i)? {
            reporter.note(&format!(
                "recomputing point {i} ({} deg/s) to record the dump",
                cfg.emulated_rates_dps()[i]
            ));
        }
    }
    Ok(())
}

/// Drops point `i` from the reused points `prev` and deletes its file, so it runs again;
/// whether it was reused.
fn forget_point(
    out: &Path,
    prev: &mut BTreeMap<usize, LaneResult>,
    i: usize,
) -> Result<bool, RunError> {
    if prev.remove(&i).is_none() {
        return Ok(false);
    }
    remove_files(&[out.join(POINTS_DIR).join(PointFile::file_name(i))])?;
    Ok(true)
}

/// The dumped point of `cfg`'s `[dump]` and the files of its dump that `dir` lacks of those
/// a dump always writes ([`Probe::required_file_names`]: each recorded rate's CSV and SigMF
/// pair); `None` without a `[dump]`.
pub(crate) fn lost_dump_files(cfg: &Config, dir: &Path) -> Option<(usize, Vec<String>)> {
    let (d, i) = (cfg.dump_resolved()?, dump_point(cfg)?);
    let lost = Probe::required_file_names(&d.nodes.unwrap_or_default(), DUMP_STEM)
        .into_iter()
        .filter(|n| !dir.join(n).exists())
        .collect();
    Some((i, lost))
}

/// The last run recorded this same `[dump]`, but a file it always writes is gone (deleted by
/// hand): every point was reused and the folder kept a dump with a part lost, said nowhere.
/// If this run owns the dumped point and reuses it, the point is computed again, which
/// records the dump whole; the dump's other files go first (a WAV the new recording may not
/// write must not stay beside it).
fn recompute_lost_dump(
    cfg: &Config,
    out: &Path,
    mine: &[usize],
    owns_files: bool,
    prev: &mut BTreeMap<usize, LaneResult>,
    reporter: &dyn Reporter,
) -> Result<(), RunError> {
    let Some((i, lost)) = lost_dump_files(cfg, out) else {
        return Ok(());
    };
    if !owns_files || !mine.contains(&i) || !prev.contains_key(&i) || lost.is_empty() {
        return Ok(());
    }
    remove_files(&dump_files(out))?;
    forget_point(out, prev, i)?;
    reporter.note(&format!(
        "the dump in `{}` lacks {}: recomputing point {i} ({} deg/s) to record it again",
        out.display(),
        lost.join(", "),
        cfg.emulated_rates_dps()[i]
    ));
    Ok(())
}
