//! Merging the shards of a sweep or a lot. Every shard `I/N` of one split must have left a
//! complete `shard-I-of-N.json` of the same kind and config hash, the shards' items (points,
//! devices) must cover every item exactly once, and every item's file must be there; then
//! the results are built from the files exactly as one machine builds them.

use crate::error::RunError;
use crate::manifest::RunKind;
use crate::merge_split::{bad, read_split, Split};
use crate::points::{config_hash, PointFile};
use gyroemu_analysis::montecarlo::LotSummary;
use gyroemu_config::parse_config;
use gyroemu_experiment::work::{lock_work, measured_lock_rate};
use gyroemu_experiment::{finish_sweep, resolve_lock, Reporter};
use gyroemu_report::{check_problems, run_title, write_run};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What a merge wrote, and a lot's figures (what `montecarlo` prints of it).
#[derive(Debug)]
pub struct Merged {
    /// The files written.
    pub files: Vec<PathBuf>,
    /// A lot's summary; `None` for a sweep.
    pub lot: Option<LotSummary>,
}

/// Checks the shards in `dir` and writes the results one machine would have written there
/// (a sweep's `results.csv`, `summary.json`, `plot.png`; a lot's `devices.csv`,
/// `montecarlo.json`, `histogram.png`, `percentiles.png`) and the run manifest; returns the
/// files written, and a lot's summary.
pub fn merge(dir: &Path, reporter: &dyn Reporter) -> Result<Merged, RunError> {
    let split = read_split(dir)?;
    match split.kind {
        RunKind::Run => merge_run(dir, split, reporter).map(|files| Merged { files, lot: None }),
        RunKind::Montecarlo => {
            crate::lot_merge::merge_lot(dir, split, reporter).map(|(files, lot)| Merged {
                files,
                lot: Some(lot),
            })
        }
    }
}

/// A sweep's merge: the config the shards ran, bit for bit, every point's file, then the
/// results built from them.
fn merge_run(dir: &Path, split: Split, reporter: &dyn Reporter) -> Result<Vec<PathBuf>, RunError> {
    let first_name = &split.first_name;
    let cfg = parse_config(&split.first.config_toml)
        .map_err(|e| bad(format!("`{first_name}`: its config does not parse: {e}")))?;
    if config_hash(&cfg) != split.hash {
        return Err(bad(format!(
            "`{first_name}`: its config text does not match its config hash"
        )));
    }
    let warnings = cfg
        .validate()
        .map_err(|e| bad(format!("{first_name}: {e}")))?;
    for w in warnings {
        reporter.warn(&format!("{first_name}: {w}"));
    }
    let n = cfg.emulated_rates_dps().len();
    let records = split.records::<PointFile>(dir, n, false)?;
    let owner = split.owners(n)?;
    // A damaged value is refused here (a run would recompute it): naming the shard to rerun.
    let lanes = records
        .into_iter()
        .map(|(i, (p, f))| {
            let lane = f.lane().map_err(|e| {
                bad(format!(
                    "`{}` does not decode ({e}): rerun its shard with --shard {}/{} to compute \
                     point {i} again",
                    p.display(),
                    owner[&i],
                    split.count
                ))
            })?;
            Ok((i, lane))
        })
        .collect::<Result<BTreeMap<_, _>, RunError>>()?;
    // The shard of the dumped point recorded the dump into this folder: a file of it lost
    // since (deleted by hand) would leave the merged folder with part of its dump missing.
    if let Some((i, lost)) = crate::dumps::lost_dump_files(&cfg, dir) {
        if !lost.is_empty() {
            return Err(bad(format!(
                "the [dump] of this config records point {i}, but `{}` lacks {}: rerun its shard with --shard {}/{} to record the dump again",
                dir.display(),
                lost.join(", "),
                owner[&i],
                split.count
            )));
        }
    }
    // The shards swept at the carrier a [pll] locked: lock again (the same bits) to read out.
    // Said first, with its size: the lock is as long as the user's pll.lock_s (the shards
    // passed the cap with it, or were forced), and nothing else in a merge takes time.
    let lock_samples = lock_work(&cfg).lock_samples;
    if lock_samples > 0 {
        let time = measured_lock_rate(&cfg).map_or(String::new(), |r| {
            format!(", about {:.3} s on one thread", lock_samples as f64 / r)
        });
        reporter.note(&format!(
            "merge: the shards ran at the carrier their [pll] locked; locking it again to read them out (the same lock run, so the same carrier): {:.3e} input samples{time}",
            lock_samples as f64
        ));
    }
    let (held, lock) = resolve_lock(&cfg)?;
    if let Some(l) = &lock {
        reporter.note(&l.note());
    }
    let r = finish_sweep(&held, &lanes)?;
    let written = write_run(dir, &held, &cfg, &r, &run_title(&cfg)).map_err(RunError::from);
    for w in &r.warnings {
        reporter.warn(w);
    }
    // Refused phases fail the merge after its files are written: the manifest says so too.
    let checked = written.and_then(|files| {
        RunError::refused_unless(
            check_problems(&dir.display().to_string(), &r.problems),
            files,
        )
    });
    let (mut files, path) = split.finish(dir, n, checked)?;
    files.push(path);
    reporter.note(&format!("merged {} shards ({n} points)", split.count));
    Ok(files)
}
