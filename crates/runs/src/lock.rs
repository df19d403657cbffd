//! The lock of an output folder: two commands writing into one folder would both report
//! success over each other's files, so each takes the folder's lock first. The shards of a
//! split run side by side (each its own point files and manifest), so a shard locks only its
//! own index, and stays out of a folder another command holds whole.
//!
//! A lock is a file created atomically (a hard link of a complete temporary, so no reader
//! ever sees it half-written) holding the holder's pid, host, command and start time. The
//! holder removes it when it ends, on every path: return, error, Ctrl-C ([`crate::abort_now`]).
//! A lock whose process is gone (SIGKILL, a crash) is stale: on the same host (Linux:
//! `/proc/<pid>` absent) it is taken over with a warning; from another host it cannot be
//! checked and is honoured.

use crate::abort::{self, remove_if_ours};
use crate::error::RunError;
use crate::manifest::files_like;
use gyroemu_experiment::Reporter;
use serde::{Deserialize, Serialize};
use std::io::{ErrorKind, Write};
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

/// The lock of a whole output folder.
pub const LOCK_FILE: &str = "gyroemu.lock";

/// What a command locks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LockScope {
    /// The whole folder (`run`, `merge`, `selfcal`, `reproduce`).
    Folder,
    /// Shard `index` of `count`: other shards may run beside it.
    Shard { index: usize, count: usize },
}

impl LockScope {
    /// The lock file's name.
    pub fn file_name(&self) -> String {
        match self {
            LockScope::Folder => LOCK_FILE.to_string(),
            LockScope::Shard { index, count } => format!("gyroemu-shard-{index}-of-{count}.lock"),
        }
    }
}

/// What a lock file says about its holder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LockInfo {
    pub pid: u32,
    /// The host name (empty when unknown).
    pub host: String,
    /// The holder's command line.
    pub command: String,
    /// When the holder took the lock, seconds since 1970 UTC.
    pub since_unix_s: u64,
    /// The same, `YYYY-MM-DD HH:MM:SS UTC`.
    pub since_utc: String,
    /// The holder's pid namespace (`/proc/self/ns/pid`'s link, e.g. `pid:[4026531836]`;
    /// empty when unknown or in locks of older versions): a pid is only looked up in its own.
    #[serde(default)]
    pub pid_ns: String,
}

impl LockInfo {
    fn now(command: &str) -> Self {
        let t = unix_now();
        Self {
            pid: std::process::id(),
            host: host_name(),
            command: command.to_string(),
            since_unix_s: t,
            since_utc: utc_text(t),
            pid_ns: pid_namespace(),
        }
    }

    /// `pid 123 (`gyroemu run a.toml --out o`) since 2026-05-01 12:00:00 UTC (40 s ago)`.
    pub fn describe(&self) -> String {
        let host = if self.host.is_empty() || self.host == host_name() {
            String::new()
        } else {
            format!(" on host {}", self.host)
        };
        let ago = unix_now().saturating_sub(self.since_unix_s);
        format!(
            "pid {}{host} (`{}`) since {} ({ago} s ago)",
            self.pid, self.command, self.since_utc
        )
    }
}

/// A held lock; dropping it removes the lock file (if it is still this one).
#[derive(Debug)]
pub struct OutLock {
    path: PathBuf,
    text: String,
    id: u64,
}

impl OutLock {
    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for OutLock {
    fn drop(&mut self) {
        remove_if_ours(&self.path, &self.text);
        abort::forget_lock(self.id);
    }
}

/// Locks `out` (which must exist) for `command` (shown to a second process). Refuses with
/// [`RunError::Locked`], naming the holder, when another live process holds the folder, the
/// same shard, or (for the folder) any shard; takes over stale locks with a warning.
pub fn lock_out(
    out: &Path,
    command: &str,
    scope: LockScope,
    reporter: &dyn Reporter,
) -> Result<OutLock, RunError> {
    let path = out.join(scope.file_name());
    let info = LockInfo::now(command);
    let text = serde_json::to_string_pretty(&info).expect("a lock serialises") + "\n";
    acquire(&path, &text, reporter)?;
    let lock = OutLock {
        id: abort::hold_lock(&path, &text),
        path,
        text,
    };
    // The locks this scope excludes: the folder's (a shard), every shard's (the folder).
    for other in conflicting(out, scope)? {
        if let Some(holder) = live_holder(&other, reporter)? {
            return Err(refusal(out, &other, &holder));
        }
    }
    Ok(lock)
}

fn conflicting(out: &Path, scope: LockScope) -> Result<Vec<PathBuf>, RunError> {
    if let LockScope::Shard { .. } = scope {
        return Ok(vec![out.join(LOCK_FILE)]);
    }
    files_like(out, "gyroemu-shard-", ".lock")
}

fn refusal(out: &Path, lock: &Path, holder: &LockInfo) -> RunError {
    RunError::Locked(format!(
        "output folder `{}` is in use by another gyroemu: {} holds `{}`; wait for it to \
         finish or choose another --out (if that process is gone, delete the lock file)",
        out.display(),
        holder.describe(),
        lock.display()
    ))
}

/// Creates `path` holding `text`, taking over a stale lock; refuses a live one.
fn acquire(path: &Path, text: &str, reporter: &dyn Reporter) -> Result<(), RunError> {
    let out = path.parent().unwrap_or(Path::new("."));
    // A few rounds: a stale lock taken over may be re-taken by another process at once.
    for _ in 0..8 {
        match create_with(path, text) {
            Ok(()) => return Ok(()),
            Err(e) if e.kind() == ErrorKind::AlreadyExists => {}
            // Like `prepare_out`'s probe, a folder this command cannot write into is the
            // user's to fix (exit 2), not a failure of the command.
            Err(e) => {
                return Err(RunError::BadInput(format!(
                    "output folder `{}` is not writable: cannot create the lock `{}`: {e}",
                    out.display(),
                    path.display()
                )))
            }
        }
        if let Some(holder) = live_holder(path, reporter)? {
            return Err(refusal(out, path, &holder));
        }
    }
    Err(RunError::Locked(format!(
        "cannot lock `{}`: other processes keep taking it; retry",
        path.display()
    )))
}

/// The live holder of the lock at `path`: `None` when there is no lock or it was stale (and
/// is now removed, with a warning). An unreadable lock is refused: its holder is unknown.
fn live_holder(path: &Path, reporter: &dyn Reporter) -> Result<Option<LockInfo>, RunError> {
    let text = match gyroemu_io::read_own_text(path, gyroemu_io::MAX_LOCK_BYTES) {
        Ok(t) => t,
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(None),
        // A folder or an unreadable file where the lock goes: the user's to fix (exit 2),
        // like a lock that is not gyroemu's.
        Err(e) => {
            return Err(RunError::Locked(format!(
                "`{}` cannot be read as a gyroemu lock ({e}), so its holder is unknown: if no \
                 gyroemu writes into this folder, remove it",
                path.display()
            )))
        }
    };
    let Ok(info) = serde_json::from_str::<LockInfo>(&text) else {
        return Err(RunError::Locked(format!(
            "`{}` is not a gyroemu lock, so its holder is unknown: if no gyroemu writes into \
             this folder, delete it",
            path.display()
        )));
    };
    if holder_alive(&info, &text) {
        return Ok(Some(info));
    }
    reporter.warn(&format!(
        "taking over the stale lock `{}` of {}: that process is gone",
        path.display(),
        info.describe()
    ));
    take_over(path, &text);
    Ok(None)
}

/// Whether the lock's holder may still run: yes unless it is provably gone (this host,
/// `/proc` present and without its pid, or this very process not holding it).
fn holder_alive(info: &LockInfo, text: &str) -> bool {
    if !info.host.is_empty() && info.host != host_name() {
        return true;
    }
    // Another pid namespace on the same host name: its pid means nothing in our /proc (a
    // live holder there had been taken over as gone), unless it is our own pid too, which is
    // a restarted container's retry (a Kubernetes pod keeps its host name and runs gyroemu as
    // pid 1 in a fresh namespace): that one is taken for the same container, gone.
    if !info.pid_ns.is_empty() && info.pid_ns != pid_namespace() {
        return info.pid != std::process::id();
    }
    if info.pid == std::process::id() {
        return abort::holds(text);
    }
    let proc_fs = Path::new("/proc");
    !proc_fs.join("self").exists() || proc_fs.join(info.pid.to_string()).exists()
}

/// Removes the stale lock at `path` if it still holds `stale`: renamed aside first, so a
/// fresh lock another process created meanwhile is put back, never deleted.
fn take_over(path: &Path, stale: &str) {
    let aside = path.with_extension(format!("stale-{}", std::process::id()));
    if std::fs::rename(path, &aside).is_err() {
        return;
    }
    if gyroemu_io::read_own_text(&aside, gyroemu_io::MAX_LOCK_BYTES).is_ok_and(|t| t != stale) {
        let _ = std::fs::hard_link(&aside, path);
    }
    let _ = std::fs::remove_file(&aside);
}

/// Creates `path` with `text` atomically: fails with `AlreadyExists` if it exists.
fn create_with(path: &Path, text: &str) -> std::io::Result<()> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let tmp = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    std::fs::write(&tmp, text)?;
    let linked = std::fs::hard_link(&tmp, path);
    let _ = std::fs::remove_file(&tmp);
    match linked {
        Err(e) if e.kind() != ErrorKind::AlreadyExists => {
            // No hard links here (some network or FAT file systems): create it in place.
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(path)?;
            f.write_all(text.as_bytes())?;
            f.sync_all()
        }
        r => r,
    }
}

fn unix_now() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

/// This process's pid namespace, as `/proc/self/ns/pid` names it (empty without it).
fn pid_namespace() -> String {
    std::fs::read_link("/proc/self/ns/pid")
        .map(|p| p.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Another process's live lock in `out` (the folder's or any shard's), if one is held: what
/// `--force` must not delete under it (a shard's --force had deleted a running shard's
/// files). Stale locks are taken over as [`lock_out`] does; this process's own are skipped.
pub(crate) fn live_other_lock(
    out: &Path,
    reporter: &dyn Reporter,
) -> Result<Option<(PathBuf, LockInfo)>, RunError> {
    let mut locks = files_like(out, "gyroemu-shard-", ".lock")?;
    locks.push(out.join(LOCK_FILE));
    for p in locks {
        let Ok(text) = gyroemu_io::read_own_text(&p, gyroemu_io::MAX_LOCK_BYTES) else {
            continue;
        };
        let ours = serde_json::from_str::<LockInfo>(&text).is_ok_and(|i| {
            i.pid == std::process::id() && i.pid_ns == pid_namespace() && abort::holds(&text)
        });
        if ours {
            continue;
        }
        if let Some(holder) = live_holder(&p, reporter)? {
            return Ok(Some((p, holder)));
        }
    }
    Ok(None)
}

fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .or_else(|_| std::env::var("HOSTNAME"))
        .unwrap_or_default()
}

/// `YYYY-MM-DD HH:MM:SS UTC` of `t` seconds since 1970 (the proleptic Gregorian calendar:
/// days to civil date as in H. Hinnant, "chrono-Compatible Low-Level Date Algorithms").
pub fn utc_text(t: u64) -> String {
    let (days, s) = ((t / 86_400) as i64, t % 86_400);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02}:{:02} UTC",
        s / 3600,
        s / 60 % 60,
        s % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_text_matches_known_dates() {
        assert_eq!(utc_text(0), "1970-01-01 00:00:00 UTC");
        // 2000-02-29 (a leap day of a century leap year), `date -u -d @951782400`.
        assert_eq!(utc_text(951_782_400), "2000-02-29 00:00:00 UTC");
        // The last second of 1999 and of 2100-02-28 (2100 is no leap year).
        assert_eq!(utc_text(946_684_799), "1999-12-31 23:59:59 UTC");
        assert_eq!(utc_text(4_107_542_399), "2100-02-28 23:59:59 UTC");
        assert_eq!(utc_text(4_107_542_400), "2100-03-01 00:00:00 UTC");
    }
}
