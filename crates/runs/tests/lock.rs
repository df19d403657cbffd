//! The output folder's lock: a second holder is refused naming the first (pid, command, since
//! when), also within one process and against another live process; the lock file goes when
//! its holder drops it; a lock whose process is gone is taken over with a warning; shards of
//! a split lock side by side but not beside a whole-folder command.

use gyroemu_experiment::{Quiet, Reporter, Task};
use gyroemu_runs::{lock_out, utc_text, LockInfo, LockScope, RunError, LOCK_FILE};
use std::path::Path;
use std::process::{Child, Command};
use std::sync::Mutex;

/// Keeps the warnings.
#[derive(Default)]
struct Record(Mutex<Vec<String>>);

impl Reporter for Record {
    fn task(&self, _: &str) -> Box<dyn Task + '_> {
        Box::new(Quiet)
    }
    fn note(&self, _: &str) {}
    fn warn(&self, text: &str) {
        self.0.lock().unwrap().push(text.to_string());
    }
}

fn locked(r: Result<gyroemu_runs::OutLock, RunError>) -> String {
    match r {
        Err(RunError::Locked(m)) => m,
        Err(e) => panic!("expected a lock refusal, got {e}"),
        Ok(l) => panic!("expected a lock refusal, got {l:?}"),
    }
}

/// This process's pid namespace, as the lock records it.
fn own_pid_ns() -> String {
    std::fs::read_link("/proc/self/ns/pid")
        .map(|p| p.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A lock file naming `pid` as its holder, written as another process would.
fn plant(out: &Path, name: &str, pid: u32) {
    plant_in(out, name, pid, &own_pid_ns());
}

/// The same, by a process of the pid namespace `pid_ns`.
fn plant_in(out: &Path, name: &str, pid: u32, pid_ns: &str) {
    let info = LockInfo {
        pid,
        host: std::fs::read_to_string("/proc/sys/kernel/hostname")
            .map(|h| h.trim().to_string())
            .unwrap_or_default(),
        command: "gyroemu run other.toml --out o".into(),
        since_unix_s: 1_700_000_000,
        since_utc: utc_text(1_700_000_000),
        pid_ns: pid_ns.to_string(),
    };
    std::fs::write(out.join(name), serde_json::to_string(&info).unwrap()).unwrap();
}

fn sleeper() -> Child {
    Command::new("sleep").arg("30").spawn().unwrap()
}

#[test]
fn a_second_holder_is_refused_naming_the_first_until_it_is_released() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    let first = lock_out(out, "gyroemu run a.toml --out o", LockScope::Folder, &Quiet).unwrap();
    assert!(out.join(LOCK_FILE).exists());
    let m = locked(lock_out(
        out,
        "gyroemu selfcal b.toml",
        LockScope::Folder,
        &Quiet,
    ));
    let pid = std::process::id();
    for needle in [
        &format!("pid {pid}"),
        "`gyroemu run a.toml --out o`",
        "since ",
        " UTC",
        LOCK_FILE,
    ] {
        assert!(m.contains(needle), "`{needle}` missing from: {m}");
    }
    // A shard of any split stays out too.
    let shard = LockScope::Shard { index: 0, count: 2 };
    locked(lock_out(out, "gyroemu run --shard 0/2", shard, &Quiet));
    drop(first);
    assert!(
        !out.join(LOCK_FILE).exists(),
        "the lock outlived its holder"
    );
    let again = lock_out(out, "gyroemu merge o", LockScope::Folder, &Quiet).unwrap();
    drop(again);
    assert_eq!(std::fs::read_dir(out).unwrap().count(), 0, "files left");
}

#[test]
fn another_live_process_holds_the_lock() {
    let dir = tempfile::tempdir().unwrap();
    let mut holder = sleeper();
    plant(dir.path(), LOCK_FILE, holder.id());
    let m = locked(lock_out(
        dir.path(),
        "gyroemu run",
        LockScope::Folder,
        &Quiet,
    ));
    assert!(m.contains(&format!("pid {} ", holder.id())), "{m}");
    assert!(m.contains("gyroemu run other.toml"), "{m}");
    assert!(m.contains("since 2023-11-14 22:13:20 UTC"), "{m}");
    holder.kill().unwrap();
    holder.wait().unwrap();
    assert!(
        dir.path().join(LOCK_FILE).exists(),
        "a live lock is never removed"
    );
}

#[test]
fn a_lock_whose_process_is_gone_is_taken_over_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let mut gone = Command::new("true").spawn().unwrap();
    gone.wait().unwrap();
    plant(dir.path(), LOCK_FILE, gone.id());
    let rec = Record::default();
    let lock = lock_out(dir.path(), "gyroemu run a.toml", LockScope::Folder, &rec).unwrap();
    let w = rec.0.lock().unwrap().join("\n");
    assert!(
        w.contains("stale") && w.contains(&format!("pid {}", gone.id())),
        "{w}"
    );
    let now: LockInfo =
        serde_json::from_str(&std::fs::read_to_string(lock.path()).unwrap()).unwrap();
    assert_eq!(now.pid, std::process::id());
    assert_eq!(now.command, "gyroemu run a.toml");
    drop(lock);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn shards_lock_side_by_side_but_not_beside_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    let s = |index| LockScope::Shard { index, count: 3 };
    let a = lock_out(out, "gyroemu run --shard 0/3", s(0), &Quiet).unwrap();
    let b = lock_out(out, "gyroemu run --shard 1/3", s(1), &Quiet).unwrap();
    let m = locked(lock_out(out, "gyroemu run --shard 1/3", s(1), &Quiet));
    assert!(m.contains("--shard 1/3"), "{m}");
    let m = locked(lock_out(out, "gyroemu merge o", LockScope::Folder, &Quiet));
    assert!(m.contains("gyroemu-shard-0-of-3.lock"), "{m}");
    // The refused folder lock left nothing behind; the shards' are still held.
    assert!(!out.join(LOCK_FILE).exists());
    drop((a, b));
    assert_eq!(std::fs::read_dir(out).unwrap().count(), 0);
    let whole = lock_out(out, "gyroemu merge o", LockScope::Folder, &Quiet).unwrap();
    drop(whole);
}

#[test]
fn a_folder_where_the_lock_goes_is_refused_as_input_naming_it() {
    // Refused as the user's to fix (`Locked`: exit 2), not as a failure while running.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    std::fs::create_dir(out.join(LOCK_FILE)).unwrap();
    let m = locked(lock_out(
        out,
        "gyroemu run a.toml",
        LockScope::Folder,
        &Quiet,
    ));
    assert!(m.contains(LOCK_FILE) && m.contains("remove it"), "{m}");
    assert!(out.join(LOCK_FILE).is_dir());
}

#[test]
fn a_lock_of_another_pid_namespace_is_never_taken_for_gone() {
    // A container on the same host name: its holder's pid is not this namespace's, so a
    // missing /proc entry proves nothing (a live holder had been taken over and both ran).
    let dir = tempfile::tempdir().unwrap();
    let mut gone = Command::new("true").spawn().unwrap();
    gone.wait().unwrap();
    plant_in(dir.path(), LOCK_FILE, gone.id(), "pid:[1]");
    let m = locked(lock_out(
        dir.path(),
        "gyroemu run",
        LockScope::Folder,
        &Quiet,
    ));
    assert!(m.contains(&format!("pid {} ", gone.id())), "{m}");
    // A lock of this very pid from another namespace is a restarted container's own
    // (Kubernetes' retry: same host name, pid 1 in a fresh namespace): taken over.
    plant_in(dir.path(), LOCK_FILE, std::process::id(), "pid:[1]");
    let rec = Record::default();
    drop(lock_out(dir.path(), "gyroemu run", LockScope::Folder, &rec).unwrap());
    assert_eq!(rec.0.lock().unwrap().len(), 1);
    // The same lock from this namespace is stale and taken over.
    plant(dir.path(), LOCK_FILE, gone.id());
    let rec = Record::default();
    drop(lock_out(dir.path(), "gyroemu run", LockScope::Folder, &rec).unwrap());
    assert_eq!(rec.0.lock().unwrap().len(), 1);
}
