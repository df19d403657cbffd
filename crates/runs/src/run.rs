//! One experiment run into an output folder, resumable and shardable: the points not yet
//! saved there (all, or the shard's) run, each saved as soon as its lane group finishes; a
//! manifest says what is done; an interrupt keeps what finished; a whole run then writes the
//! results.

use crate::abort::LiveManifest;
use crate::dumps::reconcile_dump;
use crate::error::RunError;
use crate::manifest::{Manifest, RunKind, ShardId, RUN_MANIFEST};
use crate::points::{canonical_toml, config_hash, scan_points, write_point, POINTS_DIR};
use crate::resume::previous_points;
use crate::shard::Shard;
use gyroemu_board::LaneResult;
use gyroemu_config::Config;
use gyroemu_experiment::work::measured_throughput;
use gyroemu_experiment::{
    dump_point, finish_sweep, run_sweep_with, sweep_work, Reporter, SweepOptions, Work,
};
use gyroemu_report::{check_problems, run_title, write_run};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// What to run.
pub struct RunRequest<'a> {
    /// The validated config.
    pub config: &'a Config,
    /// The output folder (it must exist and be writable: see [`prepare_out`]).
    pub out: &'a Path,
    /// Run only this shard of the points.
    pub shard: Option<Shard>,
    /// Run even above the cap of [`gyroemu_experiment::MAX_POINT_SAMPLES`], and delete results
    /// of another config found in `out` instead of refusing.
    pub force: bool,
    /// Raised (Ctrl-C, SIGTERM): the run saves what finished and returns
    /// [`RunError::Interrupted`].
    pub cancel: Arc<AtomicBool>,
    /// Called after each saved lane group with the number of points this run has saved.
    pub on_saved: Option<&'a (dyn Fn(usize) + Sync)>,
}

/// How a run ended.
#[derive(Clone, Debug, PartialEq)]
pub enum RunOutcome {
    /// The whole sweep is done; these files were written.
    Complete(Vec<PathBuf>),
    /// This shard is done; `next` says how to merge.
    ShardComplete {
        /// What to do when every shard is complete.
        next: String,
    },
}

/// Makes sure the output folder exists and is writable before any sample is computed.
pub fn prepare_out(out: &Path) -> Result<(), RunError> {
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

/// Runs the points of `req` not yet saved in `req.out`, saving each as it finishes; then (a
/// whole sweep) writes the results. The manifest ends `complete`, `interrupted` or `failed`
/// (with the cause in `next`), also when writing the results fails.
pub fn run(req: &RunRequest, reporter: &dyn Reporter) -> Result<RunOutcome, RunError> {
    let (cfg, out) = (req.config, req.out);
    let hash = config_hash(cfg);
    let config_toml = canonical_toml(cfg);
    let rates = cfg.emulated_rates_dps();
    let n = rates.len();
    let mine: Vec<usize> = match &req.shard {
        Some(s) => s.points(n),
        None => (0..n).collect(),
    };
    // Say what this will cost before anything runs; refuse an absurd run unless forced.
    let whole = sweep_work(cfg);
    let share = Work {
        points: mine.len(),
        point_samples: (whole.point_samples as f64 * mine.len() as f64 / n as f64) as u64,
        ..whole
    };
    share.check_cap(req.force).map_err(RunError::BadInput)?;
    reporter.note(&share.describe(Some(measured_throughput(cfg))));
    let manifest_path = match &req.shard {
        Some(s) => out.join(s.manifest_name()),
        None => out.join(RUN_MANIFEST),
    };
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
    let reused = mine.iter().filter(|i| prev.contains_key(i)).count();
    let what = match &req.shard {
        Some(s) => format!(
            "shard {}/{} ({}): {} of the {n} points",
            s.index,
            s.count,
            s.source,
            mine.len()
        ),
        None => format!("{n} points"),
    };
    let points_dir = out.join(POINTS_DIR);
    reporter.note(&if reused == mine.len() {
        format!(
            "{what}: all already computed for this config (sha256 {}) in `{}`: reusing them",
            &hash[..12],
            points_dir.display()
        )
    } else if reused > 0 {
        format!(
            "{what}: resuming, {reused} already computed for this config in `{}`",
            points_dir.display()
        )
    } else {
        what
    });
    let shard_id = req.shard.as_ref().map(|s| ShardId {
        index: s.index,
        count: s.count,
    });
    let manifest = |status: &str, done: &BTreeMap<usize, LaneResult>| {
        Manifest::new(
            RunKind::Run,
            status,
            &hash,
            &config_toml,
            shard_id,
            n,
            &mine,
            done,
        )
    };
    manifest("running", &prev).write(&manifest_path)?;
    // What an abrupt exit (a second Ctrl-C) leaves: the points saved until then.
    let mut aborted = manifest("interrupted", &prev);
    aborted.next = "stopped at once by a second Ctrl-C or SIGTERM: rerun the same command to \
                    resume"
        .into();
    let live = LiveManifest::new(&manifest_path, aborted);
    let fail = |e: RunError, done: &BTreeMap<usize, LaneResult>| {
        let mut m = manifest("failed", done);
        m.next = format!("fix the cause ({e}) and rerun the same command");
        match live.write_final(&manifest_path, &m) {
            Ok(()) => e,
            Err(w) => RunError::Unrecorded {
                cause: Box::new(e),
                manifest: manifest_path.clone(),
                why: w.to_string(),
            },
        }
    };

    let saved = AtomicUsize::new(0);
    let on_group = |pts: &[(usize, LaneResult)]| -> Result<(), String> {
        for (i, lane) in pts {
            write_point(out, &hash, *i, rates[*i], lane)?;
            live.saved(&[*i]);
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
    };
    let swept = match run_sweep_with(cfg, &|d, t| task.update(d, t), Some(out), opts) {
        Ok(s) => s,
        Err(e) => {
            // What finished is saved; the manifest says the rest is missing.
            let done = scan_points(out)
                .ok()
                .and_then(|s| s.lanes(&hash, n).ok())
                .unwrap_or_default();
            return Err(fail(e.into(), &done));
        }
    };
    task.finish_writing(Some(swept.point_samples), swept.written());
    let missing = mine.iter().filter(|i| !swept.lanes.contains_key(i)).count();
    if swept.cancelled || missing > 0 {
        let mut m = manifest("interrupted", &swept.lanes);
        m.next = "rerun the same command to resume".into();
        let e = RunError::Interrupted(format!(
            "interrupted: {} of {} points saved in `{}`, {missing} missing (listed in `{}`); \
             rerun the same command to resume",
            mine.len() - missing,
            mine.len(),
            points_dir.display(),
            manifest_path.display()
        ));
        return match live.write_final(&manifest_path, &m) {
            Ok(()) => Err(e),
            Err(w) => Err(RunError::Unrecorded {
                cause: Box::new(e),
                manifest: manifest_path.clone(),
                why: w.to_string(),
            }),
        };
    }
    let mut m = manifest("complete", &swept.lanes);
    if let Some(s) = &req.shard {
        m.next = format!(
            "when all {} shards are complete: gyroemu merge {}",
            s.count,
            out.display()
        );
        live.write_final(&manifest_path, &m)
            .map_err(|e| fail(e, &swept.lanes))?;
        return Ok(RunOutcome::ShardComplete { next: m.next });
    }
    let written = finish_sweep(cfg, &swept.lanes)
        .map_err(RunError::from)
        .and_then(|r| Ok((write_run(out, cfg, &r, &run_title(cfg))?, r)));
    let (mut files, r) = written.map_err(|e| fail(e, &swept.lanes))?;
    live.write_final(&manifest_path, &m)
        .map_err(|e| fail(e, &swept.lanes))?;
    files.push(manifest_path);
    files.extend(swept.dump_files.iter().cloned());
    for w in &r.warnings {
        reporter.warn(w);
    }
    check_problems(&out.display().to_string(), &r.problems)?;
    Ok(RunOutcome::Complete(files))
}
