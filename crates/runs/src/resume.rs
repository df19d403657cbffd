//! Resuming in an output folder: its record files (a sweep's points, a lot's devices) are
//! checked against the identity of what runs now (reused when they match, refused or
//! cleared with `force` when not: another config, or another kind of run), unreadable ones
//! reported and recomputed.

use crate::config_diff::{config_diff_for, describe_diff};
use crate::device_file::{lot_hash, DeviceFile, DEVICES_DIR};
use crate::dumps::dump_files;
use crate::error::RunError;
use crate::manifest::{read_manifest, shard_manifest_paths, RunKind, BUILD, RUN_MANIFEST};
use crate::points::{config_hash, scan_points, short_sha, PointFile, POINTS_DIR};
use crate::records::{scan_records, RecordFile};
use gyroemu_analysis::montecarlo::DeviceResult;
use gyroemu_board::LaneResult;
use gyroemu_config::Config;
use gyroemu_experiment::Reporter;
use gyroemu_report::{LOT_FILES, RUN_FILES};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What a command writes into a folder: its kind and its identity.
struct Identity<'a> {
    kind: RunKind,
    hash: String,
    config: &'a Config,
}

/// A foreign identity found in the folder: its kind, the files that carry it, and a
/// manifest's config text (to say what differs) when one names it.
struct Foreign {
    kind: RunKind,
    paths: Vec<PathBuf>,
    toml: Option<(PathBuf, String)>,
}

/// The results of a previous run in `out` for `cfg` (by its [`config_hash`]), by point
/// index. Results of another config or another kind are refused (exit 2), naming the keys
/// that differ, unless `force`, which deletes them and everything built from them.
/// Unreadable point files are reported and recomputed.
pub fn previous_points(
    out: &Path,
    cfg: &Config,
    n_points: usize,
    force: bool,
    reporter: &dyn Reporter,
) -> Result<BTreeMap<usize, LaneResult>, RunError> {
    let id = Identity {
        kind: RunKind::Run,
        hash: config_hash(cfg),
        config: cfg,
    };
    if check_foreign(out, &id, force, reporter)? {
        return Ok(BTreeMap::new());
    }
    let scan = scan_points(out).map_err(RunError::BadInput)?;
    warn_bad::<PointFile>(&scan.bad, reporter);
    // A damaged value is a damaged file like a truncated one: recomputed by the point's own
    // run or shard, not a refusal of every shard of the folder.
    let (lanes, damaged) = scan
        .decodable_lanes(&id.hash, n_points)
        .map_err(RunError::BadInput)?;
    for (p, why) in &damaged {
        reporter.warn(&format!(
            "ignoring `{}` (its data do not decode: {why}); the run or shard of that point \
             computes it again",
            p.display()
        ));
    }
    Ok(lanes)
}

/// The devices of a previous lot in `out` for `cfg` (by its [`lot_hash`]) below `n_devices`,
/// by index, refusing or clearing (`force`) another config's or kind's results like
/// [`previous_points`]. Device files of the same lot beyond `n_devices` (a larger lot ran
/// there) are left alone; unreadable ones are reported and recomputed.
pub fn previous_devices(
    out: &Path,
    cfg: &Config,
    n_devices: usize,
    force: bool,
    reporter: &dyn Reporter,
) -> Result<BTreeMap<usize, DeviceResult>, RunError> {
    let id = Identity {
        kind: RunKind::Montecarlo,
        hash: lot_hash(cfg),
        config: cfg,
    };
    if check_foreign(out, &id, force, reporter)? {
        return Ok(BTreeMap::new());
    }
    let scan = scan_records::<DeviceFile>(out).map_err(RunError::BadInput)?;
    warn_bad::<DeviceFile>(&scan.bad, reporter);
    let mut done = BTreeMap::new();
    let mut stale: Vec<(&Path, String)> = Vec::new();
    for (i, (path, f)) in scan
        .by_index(&id.hash, n_devices, true)
        .map_err(RunError::BadInput)?
    {
        match f.result() {
            Ok(d) => {
                done.insert(i, d);
            }
            Err(e) => stale.push((path, e)),
        }
    }
    // One line for them all: a new gyroemu version can make every file of a lot stale.
    if let Some((path, why)) = stale.first() {
        let more = match stale.len() {
            1 => String::new(),
            k => format!(" and {} more device files", k - 1),
        };
        reporter.warn(&format!(
            "ignoring `{}`{more} (written by another gyroemu version: {why}); those devices \
             are computed again",
            path.display()
        ));
    }
    Ok(done)
}

fn warn_bad<R: RecordFile>(bad: &[(PathBuf, String)], reporter: &dyn Reporter) {
    for (p, why) in bad {
        reporter.warn(&format!(
            "ignoring `{}` (not a gyroemu {} file: {why})",
            p.display(),
            R::STEM
        ));
    }
}

/// Refuses `out` when it holds results of another identity, unless `force`, which deletes
/// them (then returns `true`).
fn check_foreign(
    out: &Path,
    id: &Identity,
    force: bool,
    reporter: &dyn Reporter,
) -> Result<bool, RunError> {
    let mut foreign: BTreeMap<String, Foreign> = BTreeMap::new();
    let mut add = |hash: &str, kind: RunKind, path: &Path, toml: Option<String>| {
        if hash == id.hash {
            return;
        }
        let f = foreign.entry(hash.to_string()).or_insert(Foreign {
            kind,
            paths: Vec::new(),
            toml: None,
        });
        f.paths.push(path.to_path_buf());
        if let (None, Some(t)) = (&f.toml, toml) {
            f.kind = kind;
            f.toml = Some((path.to_path_buf(), t));
        }
    };
    for (p, f) in scan_points(out).map_err(RunError::BadInput)?.files {
        add(&f.config_sha256, RunKind::Run, &p, None);
    }
    for (p, f) in scan_records::<DeviceFile>(out)
        .map_err(RunError::BadInput)?
        .files
    {
        add(&f.lot_sha256, RunKind::Montecarlo, &p, None);
    }
    let mut manifests = shard_manifest_paths(out)?;
    manifests.push(out.join(RUN_MANIFEST));
    // Results of this config by another build (fused multiply-adds or not) differ in their
    // last bits: resumed or merged beside this build's, they matched neither build's run.
    let mut other_build: Option<(PathBuf, String)> = None;
    for p in manifests.iter().filter(|p| p.exists()) {
        if let Ok(m) = read_manifest(p) {
            if m.config_sha256 == id.hash && !m.build.is_empty() && m.build != BUILD {
                other_build.get_or_insert((p.clone(), m.build.clone()));
            }
            add(&m.config_sha256, m.kind, p, Some(m.config_toml));
        }
    }
    if let Some((p, build)) = &other_build {
        if !force {
            return Err(RunError::BadInput(format!(
                "output folder `{}` holds results of this config computed by a gyroemu build with {build} (`{}`); this build has {BUILD}, and their bits differ (1e-13 to 2.8e-8 relative), so a folder of both would match neither build's run: run the build that began it, choose another --out, or add --force to delete them",
                out.display(),
                p.display()
            )));
        }
        if foreign.is_empty() {
            return force_clear(out, "another gyroemu build", reporter);
        }
    }
    let Some((other, f)) = foreign.iter().next() else {
        return Ok(false);
    };
    if !force {
        let found = format!(
            "sha256 {} in `{}`{}",
            short_sha(other),
            f.paths[0].display(),
            if f.paths.len() > 1 {
                format!(" and {} more files", f.paths.len() - 1)
            } else {
                String::new()
            }
        );
        if f.kind != id.kind {
            return Err(RunError::BadInput(format!(
                "output folder `{}` holds {} ({found}), not {}: choose another --out, or add \
                 --force to delete it",
                out.display(),
                f.kind.describe(),
                id.kind.describe()
            )));
        }
        let differs = match &f.toml {
            Some((p, text)) => match config_diff_for(id.kind, text, id.config) {
                Ok(d) if d.is_empty() => format!(
                    "; `{}` lists the same settings: it was written by an older gyroemu \
                     whose config hash differs",
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
            "output folder `{}` holds results of another config ({found}), not of this one \
             (sha256 {}){differs}: choose another --out, or add --force to delete them",
            out.display(),
            short_sha(&id.hash),
        )));
    }
    force_clear(out, "another config", reporter)
}

/// `--force`'s deletion of the results of `what` in `out`, said; `true`.
fn force_clear(out: &Path, what: &str, reporter: &dyn Reporter) -> Result<bool, RunError> {
    reporter.note(&format!(
        "--force: deleting the results of {what} in `{}`",
        out.display()
    ));
    clear_out(out, reporter)?;
    Ok(true)
}

/// Deletes the record files, manifests, final outputs and signal dumps of a previous run or
/// lot in `out`, unless another gyroemu still runs there.
fn clear_out(out: &Path, reporter: &dyn Reporter) -> Result<(), RunError> {
    if let Some((lock, holder)) = crate::lock::live_other_lock(out, reporter)? {
        return Err(RunError::Locked(format!(
            "--force would delete the files of {} in `{}` (it holds `{}`): wait for it to finish or stop it first",
            holder.describe(),
            out.display(),
            lock.display()
        )));
    }
    // A folder --force cannot clear is one that cannot be written: bad input (exit 2), like
    // an output folder that cannot be created, and refused before any sample.
    let cannot = |p: &Path| {
        let p = p.display().to_string();
        move |e: std::io::Error| {
            RunError::BadInput(format!(
                "--force cannot delete `{p}` ({e}): make the output folder writable, or choose another --out"
            ))
        }
    };
    for dir in [POINTS_DIR, DEVICES_DIR] {
        let d = out.join(dir);
        if d.exists() {
            std::fs::remove_dir_all(&d).map_err(cannot(&d))?;
        }
    }
    let mut files = shard_manifest_paths(out)?;
    files.extend(
        [RUN_MANIFEST]
            .iter()
            .chain(&RUN_FILES)
            .chain(&LOT_FILES)
            .map(|f| out.join(f)),
    );
    files.retain(|f| f.exists());
    files.extend(dump_files(out));
    for f in &files {
        std::fs::remove_file(f).map_err(cannot(f))?;
    }
    Ok(())
}
