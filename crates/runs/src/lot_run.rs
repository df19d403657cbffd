//! A production lot run into an output folder, resumable and shardable like a sweep: the
//! devices not yet saved there (all, or the shard's: device `i` belongs to shard `i % N`) are
//! drawn and self-calibrated, devices in parallel, each saved as it finishes; the manifest
//! says what is done; an interrupt keeps what finished; a whole lot then writes its files.

use crate::device_file::{lot_hash, DeviceFile, DEVICES_DIR};
use crate::error::RunError;
use crate::ledger::Ledger;
use crate::manifest::RunKind;
use crate::points::{canonical_toml, short_sha};
use crate::records::write_record;
use crate::resume::previous_devices;
use crate::run::RunRequest;
use crate::shard::{check_split, Shard};
use gyroemu_analysis::montecarlo::{lot_work, run_device, DeviceResult, LotSummary};
use gyroemu_config::Config;
use gyroemu_experiment::work::{measured_lock_rate, measured_throughput};
use gyroemu_experiment::{Reporter, SweepError};
use gyroemu_report::{write_lot, ReportError};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// How a lot ended. The device files saved are not in its lists (a lot may have thousands):
/// [`RunRequest::on_saved`] counts them.
#[derive(Clone, Debug, PartialEq)]
pub enum LotOutcome {
    /// The whole lot is done; these files were written, and these are its figures.
    Complete {
        files: Vec<PathBuf>,
        summary: LotSummary,
    },
    /// This shard is done; `next` says how to merge.
    ShardComplete {
        /// What to do when every shard is complete.
        next: String,
        /// The files written: the shard's manifest.
        files: Vec<PathBuf>,
    },
}

/// The largest lot: its device indices and their validation stay small (a million
/// self-calibrations is months of a machine's time; a mistyped `--devices` would otherwise
/// allocate without bound before the work cap is reached).
pub const MAX_DEVICES: usize = 1_000_000;

/// Refuses a lot of `n` devices outside `1 ..= MAX_DEVICES`, with the rule.
pub fn check_lot_size(n: usize) -> Result<(), String> {
    if n == 0 {
        return Err("--devices = 0: a lot needs at least 1 device".into());
    }
    if n > MAX_DEVICES {
        return Err(format!(
            "--devices = {n}: a lot holds at most {MAX_DEVICES} devices (split a larger study \
             into lots with different montecarlo.seed)"
        ));
    }
    Ok(())
}

/// The lot's size, its shard count and its split against the folder's shards, checked
/// before the folder is created or locked (so a refusal leaves nothing behind); the split's
/// warning, if any (see [`check_split`]).
pub fn check_lot(
    cfg: &Config,
    out: &Path,
    shard: Option<&Shard>,
    n: usize,
) -> Result<Option<String>, RunError> {
    check_lot_size(n).map_err(RunError::BadInput)?;
    if let Some(s) = shard {
        s.check_count(n, "device")?;
    }
    check_split(out, shard, RunKind::Montecarlo, &lot_hash(cfg), "device")
}

/// Runs the devices of the lot of `n` devices of `req` not yet saved in `req.out`, saving
/// each as it finishes; then (a whole lot) writes its files. The manifest ends `complete`,
/// `interrupted` or `failed` (with the cause in `next`).
pub fn run_lot(
    req: &RunRequest,
    n: usize,
    reporter: &dyn Reporter,
) -> Result<LotOutcome, RunError> {
    let (cfg, out) = (req.config, req.out);
    if cfg.montecarlo.is_none() {
        return Err(RunError::BadInput(
            "the config has no [montecarlo] section: a lot draws its devices from it".into(),
        ));
    }
    let split_warning = check_lot(cfg, out, req.shard.as_ref(), n)?;
    let hash = lot_hash(cfg);
    let config_toml = canonical_toml(cfg);
    let mine = Shard::items(req.shard.as_ref(), n);
    let prev = previous_devices(out, cfg, n, req.force, reporter)?;
    let todo: Vec<u64> = mine
        .iter()
        .filter(|i| !prev.contains_key(i))
        .map(|&i| i as u64)
        .collect();
    let (work, input_total) = lot_work(cfg, &todo);
    work.check_cap(req.force).map_err(RunError::BadInput)?;
    let what = Shard::describe(req.shard.as_ref(), n, "device");
    let devices_dir = out.join(DEVICES_DIR);
    let reused = mine.len() - todo.len();
    reporter.note(&if mine.is_empty() {
        what
    } else if todo.is_empty() {
        format!(
            "{what}: all already computed for this lot (sha256 {}) in `{}`: reusing them",
            short_sha(&hash),
            devices_dir.display()
        )
    } else {
        let resumed = if reused > 0 {
            format!(
                ", resuming: {reused} already computed in `{}`",
                devices_dir.display()
            )
        } else {
            String::new()
        };
        format!(
            "{what}{resumed}; {} devices to run, {}",
            todo.len(),
            work.describe_at(Some(measured_throughput(cfg)), measured_lock_rate(cfg))
        )
    });
    if let Some(w) = split_warning {
        reporter.warn(&w);
    }
    let ledger = Ledger::start(
        RunKind::Montecarlo,
        &hash,
        &config_toml,
        out,
        req.shard.as_ref(),
        n,
        &mine,
        &prev,
    )?;

    let done = Mutex::new(prev);
    let task = reporter.task("montecarlo");
    let samples = AtomicU64::new(0);
    let saved = AtomicUsize::new(0);
    // Raised by the caller's flag (copied at each progress report) or by a failed device.
    let stop = Arc::new(AtomicBool::new(false));
    let copy_cancel = || {
        if req.cancel.load(Ordering::Relaxed) {
            stop.store(true, Ordering::Relaxed);
        }
    };
    let on_samples = |d: u64| {
        let all = samples.fetch_add(d, Ordering::Relaxed) + d;
        task.update(all, input_total);
        copy_cancel();
    };
    let outcomes: Vec<Result<u64, RunError>> = todo
        .par_iter()
        .with_max_len(1)
        .map(|&i| {
            copy_cancel();
            if stop.load(Ordering::Relaxed) {
                return Ok(0);
            }
            let finished = (|| {
                let Some(d) = run_device(cfg, i, Some(&stop), &on_samples)? else {
                    return Ok(0);
                };
                write_record(out, &DeviceFile::new(&hash, &d))
                    .map_err(|e| RunError::Sweep(SweepError::Output(e)))?;
                ledger.saved(i as usize);
                let ps = d.point_samples;
                done.lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .insert(i as usize, d);
                let k = saved.fetch_add(1, Ordering::SeqCst) + 1;
                if let Some(f) = req.on_saved {
                    f(k);
                }
                Ok(ps)
            })();
            if finished.is_err() {
                stop.store(true, Ordering::Relaxed);
            }
            finished
        })
        .collect();
    let done = done.into_inner().unwrap_or_else(|e| e.into_inner());
    let mut point_samples = 0;
    for o in outcomes {
        match o {
            Ok(ps) => point_samples += ps,
            Err(e) => return Err(ledger.fail(e, &done)),
        }
    }
    task.finish(Some(point_samples));
    if mine.iter().any(|i| !done.contains_key(i)) {
        return Err(ledger.interrupted(&done, "device", &devices_dir));
    }
    if req.shard.is_some() {
        let next = ledger.shard_complete(&done, out)?;
        let files = vec![ledger.path().to_path_buf()];
        return Ok(LotOutcome::ShardComplete { next, files });
    }
    let devices: Vec<DeviceResult> = done.values().cloned().collect();
    let (mut files, summary) =
        write_lot(out, cfg, &devices).map_err(|e| ledger.fail(e.into(), &done))?;
    warn_devices(&devices, reporter);
    files.push(ledger.path().to_path_buf());
    // Untrusted devices fail the lot after its files are written: the manifest says so too.
    let check = check_unreliable(&out.display().to_string(), &summary, &devices);
    let files = RunError::refused_unless(check, files)
        .map_err(|e| ledger.fail(e.with_lot(&summary), &done))?;
    ledger.complete(&done)?;
    Ok(LotOutcome::Complete { files, summary })
}

/// Most distinct device warnings repeated to the user (all are in `montecarlo.json`).
const SHOWN_WARNINGS: usize = 5;

/// The devices' warnings, each text once with how many devices share it.
fn warn_devices(devices: &[DeviceResult], reporter: &dyn Reporter) {
    let mut by_text: BTreeMap<&str, (u64, usize)> = BTreeMap::new();
    for d in devices {
        for w in &d.warnings {
            by_text.entry(w).or_insert((d.index, 0)).1 += 1;
        }
    }
    let mut list: Vec<(&str, (u64, usize))> = by_text.into_iter().collect();
    list.sort_by_key(|(_, (first, _))| *first);
    for (w, (first, k)) in list.iter().take(SHOWN_WARNINGS) {
        reporter.warn(&format!("device {first} (and {} more): {w}", k - 1));
    }
    if list.len() > SHOWN_WARNINGS {
        reporter.warn(&format!(
            "{} more distinct device warnings: see `warnings` in montecarlo.json",
            list.len() - SHOWN_WARNINGS
        ));
    }
}

/// A lot holding devices whose numbers cannot be trusted (written as NaN, left out of the
/// spreads, counted as failing the spec) fails after its files are written, naming them.
pub(crate) fn check_unreliable(
    what: &str,
    summary: &LotSummary,
    devices: &[DeviceResult],
) -> Result<(), ReportError> {
    if summary.unreliable.is_empty() {
        return Ok(());
    }
    let first: Vec<String> = devices
        .iter()
        .filter(|d| summary.unreliable.contains(&d.index))
        .take(5)
        .map(|d| {
            let why = d
                .problems
                .first()
                .cloned()
                .unwrap_or_else(|| format!("{} is not finite", summary.headline));
            format!("device {}: {why}", d.index)
        })
        .collect();
    Err(ReportError::Unreliable(format!(
        "{what}: {} of the {} devices have numbers that cannot be trusted (NaN in devices.csv, \
         left out of the percentiles, counted as failing the spec):\n  {}",
        summary.unreliable.len(),
        summary.devices,
        first.join("\n  ")
    )))
}
