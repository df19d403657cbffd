//! One experiment run into an output folder, resumable and shardable: the points not yet
//! saved there (all, or the shard's) run, each saved as soon as its lane group finishes; a
//! manifest says what is done; an interrupt keeps what finished; a whole run then writes the
//! results.

use crate::dumps::reconcile_dump;
use crate::error::RunError;
use crate::ledger::Ledger;
use crate::lock::{lock_out, LockScope, OutLock};
use crate::manifest::RunKind;
use crate::points::{canonical_toml, config_hash, scan_points, short_sha, write_point, POINTS_DIR};
use crate::resume::previous_points;
use crate::shard::{check_split, manifest_path, Shard};
use gyroemu_board::LaneResult;
use gyroemu_config::Config;
use gyroemu_experiment::work::{lock_work, measured_lock_rate, measured_throughput, points_work};
use gyroemu_experiment::{
    dump_point, finish_sweep, resolve_lock_with, run_sweep_with, sweep_work, Reporter, SweepError,
    SweepOptions, Work,
};
use gyroemu_report::{check_problems, run_title, write_run};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// What to run: a sweep ([`run`]) or a lot ([`crate::run_lot`]).
pub struct RunRequest<'a> {
    /// The validated config (a lot: validated for the devices this run draws, by
    /// [`gyroemu_analysis::montecarlo::validate_lot`]).
    pub config: &'a Config,
    /// The output folder (it must exist and be writable: see [`prepare_out`]).
    pub out: &'a Path,
    /// Run only this shard of the points (a lot's devices).
    pub shard: Option<Shard>,
    /// Run even above the cap of [`gyroemu_experiment::MAX_POINT_SAMPLES`], and delete results
    /// of another config or kind found in `out` instead of refusing.
    pub force: bool,
    /// Raised (Ctrl-C, SIGTERM): the run saves what finished and returns
    /// [`RunError::Interrupted`].
    pub cancel: Arc<AtomicBool>,
    /// Called after each saved lane group (device) with the number of points (devices) this
    /// run has saved.
    pub on_saved: Option<&'a (dyn Fn(usize) + Sync)>,
}

/// How a run ended. The point files saved are not in its lists (a sweep may have thousands):
/// [`RunRequest::on_saved`] counts them.
#[derive(Clone, Debug, PartialEq)]
pub enum RunOutcome {
    /// The whole sweep is done; these files were written.
    Complete(Vec<PathBuf>),
    /// This shard is done; `next` says how to merge.
    ShardComplete {
        /// What to do when every shard is complete.
        next: String,
        /// The files written: the dump's when this shard recorded it, and its manifest.
        files: Vec<PathBuf>,
    },
}

/// Makes sure the output folder exists and is writable before any sample is computed.
pub fn prepare_out(out: &Path) -> Result<(), RunError> {
    // `create_dir_all` on a file, or on a symlink to nothing, says only "File exists".
    if out.exists() && !out.is_dir() {
        return Err(RunError::BadInput(format!(
            "output folder `{}` is a file, not a folder: choose another --out",
            out.display()
        )));
    }
    if !out.exists() && out.symlink_metadata().is_ok() {
        return Err(RunError::BadInput(format!(
            "output folder `{}` is a symbolic link to nothing: create its target or choose another --out",
            out.display()
        )));
    }
    check_path_room(out)?;
    std::fs::create_dir_all(out).map_err(|e| {
        RunError::BadInput(format!(
            "output folder `{}` cannot be created: {e}",
            out.display()
        ))
    })?;
    let probe = out.join(format!(".gyroemu-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .and_then(|_| std::fs::remove_file(&probe))
        .map_err(|e| {
            RunError::BadInput(format!(
                "output folder `{}` is not writable: {e}",
                out.display()
            ))
        })
}

/// What the files written below an output folder add to its path, at most: the longest is a
/// preset folder's dump temporary, `m2tfg-ratetable/.dump_decimated.sigmf-data.tmpXXXXXX.sigmf-data`
/// (63 bytes), and a lot's `devices/.device-999999.json.tmpXXXXXX.json` is shorter.
const PATH_ROOM: usize = 96;

/// The longest path the system opens (PATH_MAX, with its terminating NUL).
#[cfg(target_os = "linux")]
const PATH_MAX: usize = 4096;
#[cfg(not(target_os = "linux"))]
const PATH_MAX: usize = 1024;

/// Refuses an output folder whose path leaves no room for the files written below it: the
/// folder itself could be made, so the run went on and failed on its first point or dump
/// file, after the emulation ("File name too long", exit 1).
fn check_path_room(out: &Path) -> Result<(), RunError> {
    let len = out.as_os_str().len();
    if len + PATH_ROOM < PATH_MAX {
        return Ok(());
    }
    Err(RunError::BadInput(format!(
        "output folder `{}` is a path of {len} bytes: the files written below it add up to {PATH_ROOM} more, past the system's limit of {PATH_MAX} bytes on a path (PATH_MAX): choose a shorter --out (a relative one from a nearer working folder counts only its own length)",
        out.display()
    )))
}

/// The folders `names` below `out`, for a command that writes several runs (reproduce: one per
/// preset): all checked before any is made (a file in the way is named, and nothing is
/// created), then each prepared and locked, so that a `run` writing into one of them holds its
/// lock and none of them is written over.
pub fn lock_subfolders(
    out: &Path,
    names: &[&str],
    command: &str,
    reporter: &dyn Reporter,
) -> Result<Vec<OutLock>, RunError> {
    for n in names {
        let dir = out.join(n);
        if dir.exists() && !dir.is_dir() {
            return Err(RunError::BadInput(format!(
                "`{}` is a file, not a folder: `{command}` writes its {n} files there; move it away",
                dir.display()
            )));
        }
    }
    names
        .iter()
        .map(|n| {
            let dir = out.join(n);
            prepare_out(&dir)?;
            lock_out(&dir, command, LockScope::Folder, reporter)
        })
        .collect()
}

/// The refusals of [`run`] that need nothing computed: a shard count far above the points, a
/// scheduler's split that disagrees with the shards already in `out` ([`check_split`]), an
/// absurd plan without `force`. A program calls it before it creates `out`, so a refused run
/// leaves no folder behind; `run` calls it again under the folder's lock. Returns the work of
/// this run's share and a warning (a `--shard` of another split than `out`'s).
pub fn check_run(
    cfg: &Config,
    out: &Path,
    shard: Option<&Shard>,
    force: bool,
) -> Result<(Work, Option<String>), RunError> {
    let n = cfg.emulated_rates_dps().len();
    if let Some(s) = shard {
        s.check_count(n, "point")?;
    }
    // Refuse an absurd run unless forced.
    let share = match shard {
        Some(s) => points_work(cfg, &s.points(n)),
        None => sweep_work(cfg),
    }
    // Every run of a [pll] config (each shard, each resume) locks its carrier first.
    .plus(lock_work(cfg));
    share.check_cap(force).map_err(RunError::BadInput)?;
    crate::refuse_other_summary(out, force)?;
    let warning = check_split(out, shard, RunKind::Run, &config_hash(cfg), "point")?;
    Ok((share, warning))
}

/// Runs the points of `req` not yet saved in `req.out`, saving each as it finishes; then (a
/// whole sweep) writes the results. The manifest ends `complete`, `interrupted` or `failed`
/// (with the cause in `next`), also when writing the results fails.
pub fn run(req: &RunRequest, reporter: &dyn Reporter) -> Result<RunOutcome, RunError> {
    let (cfg, out) = (req.config, req.out);
    let hash = config_hash(cfg);
    let config_toml = canonical_toml(cfg);
    let rates = cfg.emulated_rates_dps();
    let n = rates.len();
    let mine = Shard::items(req.shard.as_ref(), n);
    // Say what this will cost before anything runs.
    let (share, split_warning) = check_run(cfg, out, req.shard.as_ref(), req.force)?;
    let (throughput, lock_rate) = (measured_throughput(cfg), measured_lock_rate(cfg));
    reporter.note(&share.describe_at(Some(throughput), lock_rate));
    if let Some(w) = split_warning {
        reporter.warn(&w);
    }
    let manifest_path = manifest_path(out, req.shard.as_ref());
    let mut prev = previous_points(out, cfg, n, req.force, reporter)?;
    let owns_dump = req.shard.is_none() || dump_point(cfg).is_some_and(|i| mine.contains(&i));
    reconcile_dump(
        cfg,
        &config_toml,
        out,
        &manifest_path,
        &mine,
        owns_dump,
        &mut prev,
        reporter,
    )?;
    let todo: Vec<usize> = mine
        .iter()
        .copied()
        .filter(|i| !prev.contains_key(i))
        .collect();
    let reused = mine.len() - todo.len();
    let what = Shard::describe(req.shard.as_ref(), n, "point");
    let points_dir = out.join(POINTS_DIR);
    reporter.note(&if reused > 0 && reused == mine.len() {
        format!(
            "{what}: all already computed for this config (sha256 {}) in `{}`: reusing them",
            short_sha(&hash),
            points_dir.display()
        )
    } else if reused > 0 {
        // The plan above is the whole share; say what is left of it.
        format!(
            "{what}: resuming, {reused} already computed for this config in `{}`; left to run: {}",
            points_dir.display(),
            points_work(cfg, &todo)
                .plus(lock_work(cfg))
                .summary_at(Some(throughput), lock_rate)
        )
    } else {
        what
    });
    let ledger = Ledger::start(
        RunKind::Run,
        &hash,
        &config_toml,
        out,
        req.shard.as_ref(),
        n,
        &mine,
        &prev,
    )?;

    // With a [pll], the carrier is locked on the emulated board first and held for the sweep
    // (deterministic: a resume, a shard and a merge lock to the same bits). Ctrl-C stops the
    // lock too: it can run as long as the user's pll.lock_s.
    let (held, lock) = match resolve_lock_with(cfg, Some(&req.cancel)) {
        Ok(v) => v,
        Err(SweepError::Cancelled) => return Err(ledger.interrupted(&prev, "point", &points_dir)),
        Err(e) => return Err(ledger.fail(e.into(), &prev)),
    };
    if let Some(l) = &lock {
        reporter.note(&l.note());
    }
    let saved = AtomicUsize::new(0);
    let on_group = |pts: &[(usize, LaneResult)]| -> Result<(), String> {
        for (i, lane) in pts {
            write_point(out, &hash, *i, rates[*i], lane)?;
            ledger.saved(*i);
        }
        let k = saved.fetch_add(pts.len(), Ordering::SeqCst) + pts.len();
        if let Some(f) = req.on_saved {
            f(k);
        }
        Ok(())
    };
    let task = reporter.task("run");
    let opts = SweepOptions {
        done: prev,
        only: req.shard.as_ref().map(|_| mine.clone()),
        cancel: Some(req.cancel.clone()),
        on_group: Some(&on_group),
        dump: None,
        group_threads: None,
        on_dump_early: None,
        // Point files are written point by point: a run keeps its points whole.
        split: false,
    };
    let swept = match run_sweep_with(&held, &|d, t| task.update(d, t), Some(out), opts) {
        Ok(s) => s,
        Err(e) => {
            // What finished is saved; the manifest says the rest is missing.
            let done = scan_points(out)
                .ok()
                .and_then(|s| s.decodable_lanes(&hash, n).ok())
                .map(|(lanes, _)| lanes)
                .unwrap_or_default();
            return Err(ledger.fail(e.into(), &done));
        }
    };
    task.finish_writing(Some(swept.point_samples), swept.written());
    for note in &swept.dump_notes {
        reporter.warn(note);
    }
    let missing = mine.iter().any(|i| !swept.lanes.contains_key(i));
    if swept.cancelled || missing {
        return Err(ledger.interrupted(&swept.lanes, "point", &points_dir));
    }
    if req.shard.is_some() {
        let next = ledger.shard_complete(&swept.lanes, out)?;
        let mut files = swept.dump_files.clone();
        files.push(ledger.path().to_path_buf());
        return Ok(RunOutcome::ShardComplete { next, files });
    }
    let written = finish_sweep(&held, &swept.lanes)
        .map_err(RunError::from)
        .and_then(|r| Ok((write_run(out, &held, cfg, &r, &run_title(cfg))?, r)));
    let (mut files, r) = written.map_err(|e| ledger.fail(e, &swept.lanes))?;
    for w in &r.warnings {
        reporter.warn(w);
    }
    files.push(ledger.path().to_path_buf());
    files.extend(swept.dump_files.iter().cloned());
    // Refused phases fail the run after its files are written: the manifest says so too.
    let check = check_problems(&out.display().to_string(), &r.problems);
    let files = RunError::refused_unless(check, files).map_err(|e| ledger.fail(e, &swept.lanes))?;
    ledger.complete(&swept.lanes)?;
    Ok(RunOutcome::Complete(files))
}
