//! The shards of one split found in a folder, read and checked for a merge: every index
//! present and complete, one kind, one config hash, every item claimed by exactly one shard
//! and its file there. Shared by the merges of a sweep (`merge.rs`) and of a lot
//! (`lot_merge.rs`).

use crate::config_diff::{config_diff_for, describe_diff};
use crate::dumps::dump_table;
use crate::error::RunError;
use crate::manifest::{read_manifest, shard_manifest_paths, Manifest, RunKind, RUN_MANIFEST};
use crate::points::{short_sha, SECTIONS_OUTSIDE_HASH};
use crate::records::{scan_records, RecordFile};
use crate::shard::absent_shards;
use gyroemu_config::parse_config;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

pub(crate) fn bad(msg: String) -> RunError {
    RunError::BadInput(msg)
}

/// The shards of one split found in a folder, checked: every index present and complete,
/// one kind, one config hash.
pub(crate) struct Split {
    pub count: usize,
    pub kind: RunKind,
    pub hash: String,
    /// The file name of the first shard's manifest, and the manifest.
    pub first_name: String,
    pub first: Manifest,
    /// Every shard's manifest (file name, manifest) by shard index.
    pub by_index: BTreeMap<usize, (String, Manifest)>,
}

pub(crate) fn read_split(dir: &Path) -> Result<Split, RunError> {
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
        let m = read_manifest(p).map_err(|e| {
            // Its name says which shard it was: that shard's rerun writes it again.
            let rerun = name
                .strip_prefix("shard-")
                .and_then(|n| n.strip_suffix(".json"))
                .and_then(|n| n.split_once("-of-"))
                .map_or(String::new(), |(i, n)| {
                    format!(": rerun its shard with --shard {i}/{n} to write it again")
                });
            bad(format!("`{}` cannot be read ({e}){rerun}", p.display()))
        })?;
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
        // The count of the missing shards below is `count` minus those present.
        if id.index >= id.count {
            return Err(bad(format!(
                "`{}` describes shard {}/{}: a shard's index is below its count",
                p.display(),
                id.index,
                id.count
            )));
        }
        shards.push((name, m));
    }
    // One split, one kind, one config.
    let (first_name, first) = shards[0].clone();
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
        if m.kind != first.kind {
            return Err(bad(format!(
                "`{name}` is a shard of {}, `{first_name}` of {}: keep the shards of one split \
                 in `{}`",
                m.kind.describe(),
                first.kind.describe(),
                dir.display()
            )));
        }
        if m.config_sha256 != hash {
            let differs = parse_config(&m.config_toml)
                .ok()
                .and_then(|c| config_diff_for(first.kind, &first.config_toml, &c).ok())
                .filter(|d| !d.is_empty())
                .map_or(String::new(), |d| {
                    format!("; they differ in {}", describe_diff(&d, 12))
                });
            return Err(bad(format!(
                "`{name}` ran another config than `{first_name}` (config sha256 {} vs \
                 {}){differs}: every shard must run the same config",
                short_sha(&m.config_sha256),
                short_sha(&hash)
            )));
        }
        // Two builds give other bits (fused multiply-adds or not): a merge of both matches
        // neither build's one-machine run.
        if !m.build.is_empty() && !first.build.is_empty() && m.build != first.build {
            return Err(bad(format!(
                "`{name}` was computed by a gyroemu build with {}, `{first_name}` by one with {}: their bits differ (1e-13 to 2.8e-8 relative), so a merge would match neither build's run; rerun the shards with one build",
                m.build, first.build
            )));
        }
        // `[dump]` leaves the hash alone (it changes no result), but the folder holds one
        // dump: shards of different dumps would leave files the merged manifest misdescribes.
        if dump_table(&m.config_toml) != dump_table(&first.config_toml) {
            return Err(bad(format!(
                "`{name}` and `{first_name}` ran the same sweep with different [dump] sections: the folder holds one dump, so rerun the shards with one [dump] (a rerun only recomputes the dumped point)"
            )));
        }
        // Sections the hash leaves out ([selfcal], [montecarlo] in a sweep): the results
        // agree, but summary.json records one config, and it had silently been shard 0's. (A
        // lot's merge compares its spec itself, naming the keys.)
        if first.kind == RunKind::Run && m.config_toml != first.config_toml {
            let tables = |t: &str| toml::from_str::<toml::Table>(t).unwrap_or_default();
            let (a, b) = (tables(&first.config_toml), tables(&m.config_toml));
            let differ: Vec<&String> = a
                .keys()
                .chain(b.keys().filter(|k| !a.contains_key(*k)))
                .filter(|k| a.get(*k) != b.get(*k))
                .collect();
            // A section the hash covers cannot differ under one hash: a manifest's config
            // text edited by hand (it had been said to be a section the hash leaves out).
            let covered: Vec<String> = differ
                .iter()
                .filter(|k| !SECTIONS_OUTSIDE_HASH.contains(&k.as_str()))
                .map(|k| format!("[{k}]"))
                .collect();
            if !covered.is_empty() {
                return Err(bad(format!(
                    "`{name}` and `{first_name}` carry the same config sha256 but their config texts differ in {}, which the hash covers: one of them was edited after its run, so which config their points ran is unknown; rerun those shards from the config",
                    covered.join(", ")
                )));
            }
            let sections: Vec<String> = differ.iter().map(|k| format!("[{k}]")).collect();
            return Err(bad(format!(
                "`{name}` and `{first_name}` ran the same results from configs that differ in {}, which the hash leaves out: the merged summary records one config, so rerun the shards with one",
                if sections.is_empty() {
                    "sections".to_string()
                } else {
                    sections.join(", ")
                }
            )));
        }
    }
    let by_index: BTreeMap<usize, (String, Manifest)> = shards
        .into_iter()
        .filter_map(|(name, m)| m.shard.map(|s| (s.index, (name, m))))
        .collect();
    // `count` comes from a file: the absent shards are listed without walking 0..count.
    let present: BTreeSet<usize> = by_index.keys().copied().collect();
    if let Some(absent) = absent_shards(&present, count) {
        // One missing shard is named as the flag that runs it.
        let how = if absent.contains([',', ' ']) {
            format!("run each with --shard I/{count} (I as listed)")
        } else {
            format!("run it with --shard {absent}")
        };
        return Err(bad(format!(
            "shard {absent} of `{}` missing (no shard manifest for it): {how} --out {}",
            dir.display(),
            dir.display()
        )));
    }
    let item = item_name(first.kind);
    // A whole run (or lot) written into the folder after its shards holds newer results than
    // they do: merging them put back the shards' [dump], lot size or spec with exit 0.
    let whole = dir.join(RUN_MANIFEST);
    if whole.exists() {
        let m = read_manifest(&whole).map_err(|e| {
            bad(format!(
                "`{}` cannot be read ({e}), so whether a run without --shard was written over the shards is unknown: if it is an earlier merge's manifest, delete it and merge again; if a run without --shard wrote it, rerun the shards into this folder with --force",
                whole.display()
            ))
        })?;
        let same = m.kind == first.kind
            && m.config_sha256 == hash
            && m.config_toml == first.config_toml
            && m.points_total == first.points_total;
        if m.shard.is_none() && !same {
            let differs = if m.kind != first.kind {
                format!("it is {}", m.kind.describe())
            } else if m.points_total != first.points_total {
                format!(
                    "{} {item}s against the shards' {} {item}s",
                    m.points_total, first.points_total
                )
            } else if m.config_sha256 != hash {
                format!(
                    "config sha256 {} against the shards' {}",
                    short_sha(&m.config_sha256),
                    short_sha(&hash)
                )
            } else {
                "the same results but another [dump] or other sections the hash leaves out"
                    .to_string()
            };
            return Err(bad(format!(
                "`{}` describes a run without --shard written over the shards ({differs}): \
                 merging them would put back older results. Rerun the shards into this folder \
                 with --force, or merge them in a folder of their own",
                whole.display(),
            )));
        }
    }
    for (i, (_, m)) in &by_index {
        if m.status != "complete" {
            return Err(bad(format!(
                "shard {i}/{count} is {} (its manifest, as last written, lists {} of its {} \
                 {item}s as not done; a killed shard's manifest stops there): rerun it with \
                 --shard {i}/{count} to finish it (it reuses every {item} saved)",
                m.status,
                m.points_missing.len(),
                m.points.len()
            )));
        }
    }
    Ok(Split {
        count,
        kind: first.kind,
        hash,
        first_name,
        first,
        by_index,
    })
}

/// What the items of a kind are called.
fn item_name(kind: RunKind) -> &'static str {
    match kind {
        RunKind::Run => "point",
        RunKind::Montecarlo => "device",
    }
}

impl Split {
    /// Which shard ran each of the `n` items: every item claimed by exactly one shard.
    pub(crate) fn owners(&self, n: usize) -> Result<BTreeMap<usize, usize>, RunError> {
        let (count, item) = (self.count, item_name(self.kind));
        let mut owner: BTreeMap<usize, usize> = BTreeMap::new();
        for (&i, (_, m)) in &self.by_index {
            for &p in &m.points {
                if p >= n {
                    return Err(bad(format!(
                        "shard {i}/{count} lists {item} {p}, but the {} has {n} {item}s",
                        if self.kind == RunKind::Run {
                            "config"
                        } else {
                            "lot"
                        }
                    )));
                }
                if let Some(j) = owner.insert(p, i) {
                    return Err(bad(format!(
                        "{item} {p} is duplicated: shards {j}/{count} and {i}/{count} both ran it"
                    )));
                }
            }
        }
        let unclaimed: Vec<usize> = (0..n).filter(|p| !owner.contains_key(p)).collect();
        if !unclaimed.is_empty() {
            return Err(bad(format!(
                "{item}s {unclaimed:?} are missing: no shard ran them"
            )));
        }
        Ok(owner)
    }

    /// Every item's record of this split's config in `dir`, once each: refuses a file that
    /// is not a record, a record of another config, a duplicated one, and a missing one
    /// (naming its shard). Records of the same config beyond `n` are ignored when
    /// `ignore_beyond` (a lot's devices of a larger lot).
    pub(crate) fn records<R: RecordFile>(
        &self,
        dir: &Path,
        n: usize,
        ignore_beyond: bool,
    ) -> Result<BTreeMap<usize, (PathBuf, R)>, RunError> {
        let owner = self.owners(n)?;
        let scan = scan_records::<R>(dir).map_err(bad)?;
        if let Some((p, why)) = scan.bad.first() {
            // Its index from its name (`<stem>-<i>.json`), to name the shard that computes it.
            let rerun = p
                .file_name()
                .and_then(|n| n.to_str())
                .and_then(|n| n.strip_prefix(&format!("{}-", R::STEM)))
                .and_then(|n| n.strip_suffix(".json"))
                .and_then(|i| i.parse::<usize>().ok())
                .and_then(|i| owner.get(&i).map(|s| (i, s)))
                .map_or(String::new(), |(i, s)| {
                    format!(
                        " and rerun its shard with --shard {s}/{} to compute {} {i} again",
                        self.count,
                        R::STEM
                    )
                });
            return Err(bad(format!(
                "`{}` is not a gyroemu {} file ({why}): remove it{rerun}",
                p.display(),
                R::STEM
            )));
        }
        if let Some((p, f)) = scan
            .files
            .iter()
            .find(|(_, f)| f.config_sha256() != self.hash)
        {
            let h = f.config_sha256();
            return Err(bad(format!(
                "`{}` ({} {}) belongs to another config (sha256 {}): remove it",
                p.display(),
                R::STEM,
                f.index(),
                short_sha(h)
            )));
        }
        let found = scan
            .by_index(&self.hash, n, ignore_beyond)
            .map_err(bad)?
            .into_iter()
            .map(|(i, (p, _))| (i, p.to_path_buf()))
            .collect::<BTreeMap<usize, PathBuf>>();
        let lost: Vec<String> = (0..n)
            .filter(|p| !found.contains_key(p))
            .map(|p| {
                format!(
                    "{} (shard {}/{})",
                    dir.join(R::DIR).join(R::file_name(p)).display(),
                    owner[&p],
                    self.count
                )
            })
            .collect();
        if !lost.is_empty() {
            return Err(bad(format!(
                "{} files missing although their shards are complete: {}; rerun those shards",
                R::STEM,
                lost.join(", ")
            )));
        }
        let mut files = scan.files;
        files.retain(|(_, f)| f.config_sha256() == self.hash && f.index() < n);
        Ok(files
            .into_iter()
            .map(|(p, f)| (f.index(), (p, f)))
            .collect())
    }

    /// Writes the run manifest of the merge: `complete` with `files` listed, or `failed` with
    /// the cause of `result`'s error (the shards' manifests stay as they are).
    pub(crate) fn finish<T>(
        &self,
        dir: &Path,
        n: usize,
        result: Result<T, RunError>,
    ) -> Result<(T, PathBuf), RunError> {
        let all: Vec<usize> = (0..n).collect();
        let done: BTreeMap<usize, ()> = all.iter().map(|&i| (i, ())).collect();
        let mut m = Manifest::new(
            self.kind,
            "complete",
            &self.hash,
            &self.first.config_toml,
            None,
            n,
            &all,
            &done,
        );
        let path = dir.join(RUN_MANIFEST);
        match result {
            Ok(t) => {
                m.next = format!("merged from {} shards", self.count);
                m.write(&path)?;
                Ok((t, path))
            }
            Err(mut e) => {
                if let RunError::Refused { files, .. } = &mut e {
                    files.push(path.clone());
                }
                m.status = "failed".into();
                m.next = match &e {
                    RunError::Refused { .. } => {
                        self.kind.refused_next(&format!(
                            "rerun every shard with --force (or into another --out), then gyroemu merge {}",
                            dir.display()
                        ))
                    }
                    _ => format!(
                        "fix the cause ({e}) and rerun gyroemu merge {}",
                        dir.display()
                    ),
                };
                Err(match m.write(&path) {
                    Ok(()) => e,
                    Err(w) => RunError::Unrecorded {
                        cause: Box::new(e),
                        manifest: path,
                        why: w.to_string(),
                    },
                })
            }
        }
    }
}
