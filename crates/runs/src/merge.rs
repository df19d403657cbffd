//! Merging the shards of a sweep. Every shard `I/N` of one split must have
//! left a complete `shard-I-of-N.json` with the same config hash, the shards' points must
//! cover every operating point exactly once, and every point's file must be there; then the
//! results are built from the point files exactly as a one-machine run builds them.

use crate::config_diff::{config_diff, describe_diff};
use crate::error::RunError;
use crate::manifest::{read_manifest, shard_manifest_paths, Manifest, RUN_MANIFEST};
use crate::points::{config_hash, scan_points, PointFile, POINTS_DIR};
use gyroemu_config::parse_config;
use gyroemu_experiment::{finish_sweep, resolve_lock, Reporter};
use gyroemu_report::{check_problems, run_title, write_run};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn bad(msg: String) -> RunError {
    RunError::BadInput(msg)
}

/// Checks the shards in `dir` and writes `results.csv`, `summary.json`, `plot.png` and the
/// run manifest there; returns the files written.
pub fn merge(dir: &Path, reporter: &dyn Reporter) -> Result<Vec<PathBuf>, RunError> {
    if !dir.is_dir() {
        return Err(bad(format!("`{}` is not a folder", dir.display())));
    }
    let paths = shard_manifest_paths(dir)?;
    if paths.is_empty() {
        return Err(bad(format!(
            "no shard manifests (shard-I-of-N.json) in `{}`: run the shards with --shard I/N \
             --out {} first",
            dir.display(),
            dir.display()
        )));
    }
    let mut shards: Vec<(String, Manifest)> = Vec::new();
    for p in &paths {
        let name = p
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        let m = read_manifest(p).map_err(|e| bad(format!("`{}`: {e}", p.display())))?;
        let Some(id) = m.shard else {
            return Err(bad(format!("`{}` is not a shard manifest", p.display())));
        };
        if name != format!("shard-{}-of-{}.json", id.index, id.count) {
            return Err(bad(format!(
                "`{}` describes shard {}/{}: its name does not match",
                p.display(),
                id.index,
                id.count
            )));
        }
        shards.push((name, m));
    }
    // One split, one config.
    let (first_name, first) = &shards[0];
    let count = first.shard.map_or(0, |s| s.count);
    let hash = first.config_sha256.clone();
    for (name, m) in &shards[1..] {
        let c = m.shard.map_or(0, |s| s.count);
        if c != count {
            return Err(bad(format!(
                "`{first_name}` and `{name}` belong to different splits ({count} and {c} shards): \
                 keep the shards of one split in `{}`",
                dir.display()
            )));
        }
        if m.config_sha256 != hash {
            let differs = parse_config(&m.config_toml)
                .ok()
                .and_then(|c| config_diff(&first.config_toml, &c).ok())
                .filter(|d| !d.is_empty())
                .map_or(String::new(), |d| {
                    format!("; they differ in {}", describe_diff(&d, 12))
                });
            return Err(bad(format!(
                "`{name}` ran another config than `{first_name}` (config sha256 {} vs \
                 {}){differs}: every shard must run the same config",
                &m.config_sha256[..m.config_sha256.len().min(12)],
                &hash[..hash.len().min(12)]
            )));
        }
    }
    let by_index: BTreeMap<usize, &Manifest> = shards
        .iter()
        .filter_map(|(_, m)| m.shard.map(|s| (s.index, m)))
        .collect();
    let absent: Vec<String> = (0..count)
        .filter(|i| !by_index.contains_key(i))
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !absent.is_empty() {
        return Err(bad(format!(
            "shard {} of `{}` missing (no shard-I-of-{count}.json): run it with --shard I/{count} \
             --out {}",
            absent.join(", "),
            dir.display(),
            dir.display()
        )));
    }
    for (i, m) in &by_index {
        if m.status != "complete" {
            return Err(bad(format!(
                "shard {i}/{count} is {} ({} of its {} points missing): rerun it with --shard \
                 {i}/{count} to finish it",
                m.status,
                m.points_missing.len(),
                m.points.len()
            )));
        }
    }
    // The config: the one the shards ran, bit for bit.
    let cfg = parse_config(&first.config_toml)
        .map_err(|e| bad(format!("`{first_name}`: its config does not parse: {e}")))?;
    if config_hash(&cfg) != hash {
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
    // Every point claimed by exactly one shard.
    let mut owner: BTreeMap<usize, usize> = BTreeMap::new();
    for (&i, m) in &by_index {
        for &p in &m.points {
            if p >= n {
                return Err(bad(format!(
                    "shard {i}/{count} lists point {p}, but the config has {n} points"
                )));
            }
            if let Some(j) = owner.insert(p, i) {
                return Err(bad(format!(
                    "point {p} is duplicated: shards {j}/{count} and {i}/{count} both ran it"
                )));
            }
        }
    }
    let unclaimed: Vec<usize> = (0..n).filter(|p| !owner.contains_key(p)).collect();
    if !unclaimed.is_empty() {
        return Err(bad(format!(
            "points {unclaimed:?} are missing: no shard ran them"
        )));
    }
    // Every point's file, once, of this config.
    let scan = scan_points(dir).map_err(bad)?;
    if let Some((p, why)) = scan.bad.first() {
        return Err(bad(format!(
            "`{}` is not a gyroemu point file ({why}): remove it",
            p.display()
        )));
    }
    if let Some((p, f)) = scan.files.iter().find(|(_, f)| f.config_sha256 != hash) {
        return Err(bad(format!(
            "`{}` (point {}) belongs to another config (sha256 {}): remove it",
            p.display(),
            f.index,
            &f.config_sha256[..f.config_sha256.len().min(12)]
        )));
    }
    let lanes = scan.lanes(&hash, n).map_err(bad)?;
    let lost: Vec<String> = (0..n)
        .filter(|p| !lanes.contains_key(p))
        .map(|p| {
            format!(
                "{} (shard {}/{count})",
                dir.join(POINTS_DIR).join(PointFile::file_name(p)).display(),
                owner[&p]
            )
        })
        .collect();
    if !lost.is_empty() {
        return Err(bad(format!(
            "point files missing although their shards are complete: {}; rerun those shards",
            lost.join(", ")
        )));
    }
    // The shards swept at the carrier a [pll] locked: lock again (the same bits) to read out.
    let (held, lock) = resolve_lock(&cfg)?;
    if let Some(l) = &lock {
        reporter.note(&crate::run::lock_note(l));
    }
    let r = finish_sweep(&held, &lanes)?;
    let all: Vec<usize> = (0..n).collect();
    let mut m = Manifest::new("complete", &hash, &first.config_toml, None, n, &all, &lanes);
    let path = dir.join(RUN_MANIFEST);
    let mut files = match write_run(dir, &held, &r, &run_title(&cfg)) {
        Ok(f) => f,
        Err(e) => {
            // The run manifest says the merge failed and why (the shards' stay as they are).
            m.status = "failed".into();
            m.next = format!(
                "fix the cause ({e}) and rerun gyroemu merge {}",
                dir.display()
            );
            return Err(match m.write(&path) {
                Ok(()) => e.into(),
                Err(w) => RunError::Unrecorded {
                    cause: Box::new(e.into()),
                    manifest: path,
                    why: w.to_string(),
                },
            });
        }
    };
    m.next = format!("merged from {count} shards");
    m.write(&path)?;
    files.push(path);
    reporter.note(&format!("merged {count} shards ({n} points)"));
    for w in &r.warnings {
        reporter.warn(w);
    }
    check_problems(&dir.display().to_string(), &r.problems)?;
    Ok(files)
}
