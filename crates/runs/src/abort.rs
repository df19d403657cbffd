//! What an abrupt exit (a second Ctrl-C, a signal to a command that cannot stop gracefully)
//! must still do before the process ends: mark the manifest of every run in progress
//! `interrupted` and remove this process's folder locks. Process-wide, as signals are.

use crate::manifest::Manifest;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The locks this process holds: (lock file, its exact content).
static LOCKS: Mutex<Vec<(u64, PathBuf, String)>> = Mutex::new(Vec::new());
/// The manifests of the runs in progress, as an abort would leave them.
static LIVE: Mutex<Vec<(u64, PathBuf, Manifest)>> = Mutex::new(Vec::new());
/// Set by [`abort_now`]: no manifest may be written after it.
static ABORTED: AtomicBool = AtomicBool::new(false);
static NEXT_ID: AtomicU64 = AtomicU64::new(0);

/// A poisoned registry is still the registry (a panicking writer changed nothing half-way).
fn guard<T>(m: &'static Mutex<T>) -> MutexGuard<'static, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

fn next_id() -> u64 {
    NEXT_ID.fetch_add(1, Ordering::Relaxed)
}

/// Marks the manifest of every run in progress `interrupted` (with the points saved so far)
/// and removes the folder locks of this process, for a process about to exit at once.
/// Returns the manifests written; failures are ignored (the process is ending).
pub fn abort_now() -> Vec<PathBuf> {
    let live = guard(&LIVE);
    ABORTED.store(true, Ordering::SeqCst);
    let written = live
        .iter()
        .filter(|(_, path, m)| m.write(path).is_ok())
        .map(|(_, path, _)| path.clone())
        .collect();
    drop(live);
    for (_, path, text) in guard(&LOCKS).iter() {
        remove_if_ours(path, text);
    }
    written
}

/// Registers a lock this process holds.
pub(crate) fn hold_lock(path: &Path, text: &str) -> u64 {
    let id = next_id();
    guard(&LOCKS).push((id, path.to_path_buf(), text.to_string()));
    id
}

/// Forgets a lock (released).
pub(crate) fn forget_lock(id: u64) {
    guard(&LOCKS).retain(|(i, _, _)| *i != id);
}

/// Whether this process holds a lock with exactly this content.
pub(crate) fn holds(text: &str) -> bool {
    guard(&LOCKS).iter().any(|(_, _, t)| t == text)
}

/// Removes the lock at `path` if it still holds `text` (not a lock another process took
/// over after this one was found stale).
pub(crate) fn remove_if_ours(path: &Path, text: &str) {
    if gyroemu_io::read_own_text(path, gyroemu_io::MAX_LOCK_BYTES).is_ok_and(|t| t == text) {
        let _ = std::fs::remove_file(path);
    }
}

/// The manifest of a run in progress, kept as an abort would write it; its final write goes
/// through [`LiveManifest::write_final`] so an abort cannot overwrite it (nor it an abort's).
pub(crate) struct LiveManifest {
    id: u64,
}

impl LiveManifest {
    /// Registers `m` (status `interrupted`, the points saved so far) for `path`.
    pub(crate) fn new(path: &Path, m: Manifest) -> Self {
        let id = next_id();
        guard(&LIVE).push((id, path.to_path_buf(), m));
        Self { id }
    }

    /// Points `done` are saved.
    pub(crate) fn saved(&self, done: &[usize]) {
        if let Some((_, _, m)) = guard(&LIVE).iter_mut().find(|(i, _, _)| *i == self.id) {
            m.mark_done(done);
        }
    }

    /// Writes the run's last manifest, unless an abort already wrote it (the process is then
    /// exiting with `interrupted`); the abort will not write it afterwards.
    pub(crate) fn write_final(&self, path: &Path, m: &Manifest) -> Result<(), crate::RunError> {
        let mut live = guard(&LIVE);
        live.retain(|(i, _, _)| *i != self.id);
        if ABORTED.load(Ordering::SeqCst) {
            return Ok(());
        }
        m.write(path)
    }
}

impl Drop for LiveManifest {
    fn drop(&mut self) {
        guard(&LIVE).retain(|(i, _, _)| *i != self.id);
    }
}
