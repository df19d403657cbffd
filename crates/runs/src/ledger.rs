//! The manifest side of a sweep or a lot in progress, shared by both: the manifest `running`
//! at the start, what an abrupt exit leaves (`interrupted` with the items saved so far), and
//! the last write, `complete`, `interrupted` or `failed` with its cause, never overwriting an
//! abort's.

use crate::abort::LiveManifest;
use crate::error::RunError;
use crate::manifest::{Manifest, RunKind, ShardId};
use crate::shard::{manifest_path, Shard};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The manifest of one run (or shard) of a sweep or lot, from its start to its end.
pub(crate) struct Ledger<'a> {
    kind: RunKind,
    hash: &'a str,
    config_toml: &'a str,
    shard: Option<ShardId>,
    total: usize,
    mine: &'a [usize],
    path: PathBuf,
    live: LiveManifest,
}

impl<'a> Ledger<'a> {
    /// Writes the manifest `running` into `out` (`manifest.json`, or the shard's) for the
    /// items `mine` of `total`, those in `done` finished, and keeps what an abort would write.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn start<V>(
        kind: RunKind,
        hash: &'a str,
        config_toml: &'a str,
        out: &Path,
        shard: Option<&Shard>,
        total: usize,
        mine: &'a [usize],
        done: &BTreeMap<usize, V>,
    ) -> Result<Self, RunError> {
        let path = manifest_path(out, shard);
        let shard = shard.map(|s| ShardId {
            index: s.index,
            count: s.count,
        });
        let m =
            |status: &str| Manifest::new(kind, status, hash, config_toml, shard, total, mine, done);
        m("running").write(&path)?;
        let mut aborted = m("interrupted");
        aborted.next = "stopped at once by a second Ctrl-C or SIGTERM: rerun the same command \
                        to resume"
            .into();
        let live = LiveManifest::new(&path, aborted);
        Ok(Self {
            kind,
            hash,
            config_toml,
            shard,
            total,
            mine,
            path,
            live,
        })
    }

    /// The manifest file.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// The manifest of `status` with the items of `done` finished (`next` empty).
    pub(crate) fn manifest<V>(&self, status: &str, done: &BTreeMap<usize, V>) -> Manifest {
        Manifest::new(
            self.kind,
            status,
            self.hash,
            self.config_toml,
            self.shard,
            self.total,
            self.mine,
            done,
        )
    }

    /// Item `i` is saved (what an abort now writes).
    pub(crate) fn saved(&self, i: usize) {
        self.live.saved(&[i]);
    }

    /// Writes the last manifest `m`; a failure of that write is returned as `cause` made
    /// [`RunError::Unrecorded`].
    fn finish(&self, m: &Manifest, cause: RunError) -> RunError {
        match self.live.write_final(&self.path, m) {
            Ok(()) => cause,
            Err(w) => RunError::Unrecorded {
                cause: Box::new(cause),
                manifest: self.path.clone(),
                why: w.to_string(),
            },
        }
    }

    /// The run failed with `e`: the manifest says `failed`, with the cause and what to do
    /// (for refused numbers, [`RunKind::refused_next`]: rerunning unchanged cannot help).
    pub(crate) fn fail<V>(&self, e: RunError, done: &BTreeMap<usize, V>) -> RunError {
        let mut m = self.manifest("failed", done);
        m.next = match &e {
            RunError::Refused { .. } => self
                .kind
                .refused_next("rerun with --force (or into another --out)"),
            _ => format!("fix the cause ({e}) and rerun the same command"),
        };
        self.finish(&m, e)
    }

    /// The run stopped before every item of its own was saved (`done` holds the saved ones,
    /// in `dir`, each an `item`): the manifest says `interrupted`; returns the error saying so.
    pub(crate) fn interrupted<V>(
        &self,
        done: &BTreeMap<usize, V>,
        item: &str,
        dir: &Path,
    ) -> RunError {
        let missing = self.mine.iter().filter(|i| !done.contains_key(i)).count();
        let mut m = self.manifest("interrupted", done);
        m.next = "rerun the same command to resume".into();
        let e = RunError::Interrupted(format!(
            "interrupted: {} of {} {item}s saved in `{}`, {missing} missing (listed in `{}`); \
             rerun the same command to resume",
            self.mine.len() - missing,
            self.mine.len(),
            dir.display(),
            self.path.display()
        ));
        self.finish(&m, e)
    }

    /// Every item of a shard is saved: the manifest says `complete` and how to merge (in
    /// `out`); returns that hint.
    pub(crate) fn shard_complete<V>(
        &self,
        done: &BTreeMap<usize, V>,
        out: &Path,
    ) -> Result<String, RunError> {
        let mut m = self.manifest("complete", done);
        m.next = format!(
            "when all {} shards are complete: gyroemu merge {}",
            self.shard.map_or(1, |s| s.count),
            out.display()
        );
        self.live
            .write_final(&self.path, &m)
            .map_err(|e| self.fail(e, done))?;
        Ok(m.next)
    }

    /// A whole run wrote its results: the manifest says `complete`.
    pub(crate) fn complete<V>(&self, done: &BTreeMap<usize, V>) -> Result<(), RunError> {
        let m = self.manifest("complete", done);
        self.live
            .write_final(&self.path, &m)
            .map_err(|e| self.fail(e, done))
    }
}
