//! Atomic replacement of a file: write a hidden temporary sibling, sync it, rename it over the
//! target. Readers never see a half-written file, and a failed write leaves the target untouched.

use crate::IoError;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use tempfile::NamedTempFile;

/// Directory and file name of `path` (a bare name lives in `.`).
fn split(path: &Path) -> Result<(PathBuf, String), IoError> {
    let name = path
        .file_name()
        .ok_or_else(|| IoError::NoFileName {
            path: path.to_path_buf(),
        })?
        .to_string_lossy()
        .into_owned();
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((dir, name))
}

/// The temporary files being written, so that an abort (Ctrl-C exits at once, skipping the
/// destructors that delete them) can remove them: they were left behind as `.x.tmpXXXXXX`.
static LIVE: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Keeps a temporary file's path in [`LIVE`] while it exists.
struct Registered(PathBuf);

impl Registered {
    fn new(path: &Path) -> Self {
        live().push(path.to_path_buf());
        Self(path.to_path_buf())
    }
}

impl Drop for Registered {
    fn drop(&mut self) {
        live().retain(|p| p != &self.0);
    }
}

fn live() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    // A writer that panicked left the list as it was: still the right list.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Deletes every temporary file this process is writing (for an exit that skips their
/// destructors); returns how many. The targets are untouched.
pub fn remove_temporaries() -> usize {
    let list = live();
    list.iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count()
}

/// Creates `.<name>.tmpXXXXXX<suffix>` in the target's directory (same filesystem, so the final
/// rename is atomic). The temp file is deleted on drop unless persisted.
fn temp_sibling(path: &Path, suffix: &str) -> Result<NamedTempFile, IoError> {
    let (dir, name) = split(path)?;
    tempfile::Builder::new()
        .prefix(&format!(".{name}.tmp"))
        .suffix(suffix)
        .tempfile_in(&dir)
        .map_err(|source| IoError::TempCreate {
            path: path.to_path_buf(),
            reason: source,
        })
}

/// Syncs the temporary file's content to disk, renames it onto `path`, then (Unix) syncs the
/// directory so the rename itself survives a crash. Inside [`with_batched_persist`] on this
/// thread, the file joins the batch instead (its sync and rename wait for the batch's end).
fn persist(tmp: NamedTempFile, path: &Path, live: Registered) -> Result<(), IoError> {
    let pending = Pending {
        tmp,
        path: path.to_path_buf(),
        _live: live,
    };
    let Some(pending) = BATCH.with_borrow_mut(|b| match b.as_mut() {
        Some(batch) => {
            batch.1.push(pending);
            None
        }
        None => Some(pending),
    }) else {
        return Ok(());
    };
    let Some(pending) = to_background(pending)? else {
        return Ok(());
    };
    sync_file(&pending)?;
    rename_into_place(pending)
}

/// The thread that syncs and renames files while [`with_background_persist`] runs.
struct Background {
    /// Calls of [`with_background_persist`] running (nested or on several threads).
    depth: usize,
    /// Where writers hand their files; `None` when no thread takes them.
    queue: Option<std::sync::mpsc::Sender<Pending>>,
    /// The thread, which returns its first failure.
    worker: Option<std::thread::JoinHandle<Option<IoError>>>,
}
static BACKGROUND: std::sync::Mutex<Background> = std::sync::Mutex::new(Background {
    depth: 0,
    queue: None,
    worker: None,
});

fn background() -> std::sync::MutexGuard<'static, Background> {
    BACKGROUND.lock().unwrap_or_else(|e| e.into_inner())
}

/// The first failure of the background thread, as text, while [`with_background_persist`]
/// runs: the writes after it fail at once, naming it, so a run stops as it did when the
/// writer itself met the failure.
static BACKGROUND_FAILED: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

fn background_failed() -> std::sync::MutexGuard<'static, Option<String>> {
    BACKGROUND_FAILED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Hands `p` to the background thread, if one runs (`None`), else gives it back; refuses it
/// (its temporary deleted) once a file before it could not be put in place.
fn to_background(p: Pending) -> Result<Option<Pending>, IoError> {
    let b = background();
    let Some(queue) = b.queue.as_ref() else {
        return Ok(Some(p));
    };
    if let Some(earlier) = background_failed().as_ref() {
        return Err(IoError::Write {
            path: p.path.clone(),
            reason: std::io::Error::other(format!(
                "not put in place, since an earlier file could not be: {earlier}"
            )),
        });
    }
    Ok(queue.send(p).err().map(|e| e.0))
}

/// Puts in place, now, every file [`with_background_persist`] is holding, and leaves the
/// files written from here on to their writers: for an exit that skips its end (Ctrl-C),
/// which would otherwise delete finished files still waiting as temporaries.
pub fn flush_background_persist() {
    let worker = close_queue(&mut background());
    if let Some(w) = worker {
        drop(join_worker(w));
    }
}

/// Closes the background queue (the thread ends after the last file in it) and gives the
/// thread to wait for; later files are synced and renamed by their writers.
fn close_queue(b: &mut Background) -> Option<std::thread::JoinHandle<Option<IoError>>> {
    b.queue = None;
    b.worker.take()
}

/// Waits for the background thread: its first failure, if any.
fn join_worker(w: std::thread::JoinHandle<Option<IoError>>) -> Option<IoError> {
    w.join().unwrap_or_else(|_| {
        Some(IoError::Write {
            path: PathBuf::from("<background persist>"),
            reason: std::io::Error::other("the thread putting files in place panicked"),
        })
    })
}

/// Runs `f` with the sync and rename of every file written atomically (outside
/// [`with_batched_persist`]) done by a thread of their own, in the order written, instead of
/// by the writer, which goes on at once; when `f` returns (the outermost of nested calls),
/// waits for the last of them. Each file is still synced before its rename, so a reader never
/// sees a partial file, and a failed one is deleted, its target untouched; the first failure
/// is returned then, if `f` succeeded (the other files are still put in place). Why: a sync
/// waits for the filesystem's journal, and `reproduce`'s workers, which write its figures and
/// tables between lane groups, waited for about 20 ms of them in all, their core idle.
///
/// The mode is the process's: while it runs, a file written atomically on any thread is not
/// at its path when its writer returns, only when this returns, so nothing may read back what
/// it wrote meanwhile (a dump, which its figures read, is written in a batch, which puts its
/// files in place before returning). For a command's whole run, not inside other work. Once
/// a file could not be put in place, later writes fail at once, naming it; if `f` fails, its
/// own error is returned (the first such write's names the file). A path written here and
/// then again in a batch may end with the first contents (the batch's rename is immediate,
/// the queued one later): write each path once, as `reproduce` does.
pub fn with_background_persist<R, E: From<IoError>>(
    f: impl FnOnce() -> Result<R, E>,
) -> Result<R, E> {
    {
        let mut b = background();
        b.depth += 1;
        if b.queue.is_none() && b.depth == 1 {
            *background_failed() = None;
            let (tx, rx) = std::sync::mpsc::channel::<Pending>();
            let worker = std::thread::Builder::new()
                .name("persist".into())
                .spawn(move || {
                    let mut first = None;
                    for p in rx {
                        if let Err(e) = sync_file(&p).and_then(|()| rename_into_place(p)) {
                            background_failed().get_or_insert_with(|| e.to_string());
                            first.get_or_insert(e);
                        }
                    }
                    first
                });
            // No thread: each writer syncs and renames its own files, as outside this.
            if let Ok(worker) = worker {
                (b.queue, b.worker) = (Some(tx), Some(worker));
            }
        }
    }
    // The files are waited for if `f` panics too.
    match then_leave(f, leave_background) {
        (Err(e), _) => Err(e),
        (Ok(_), Some(e)) => Err(e.into()),
        (Ok(v), None) => Ok(v),
    }
}

/// Leaves one level of [`with_background_persist`]: the outermost closes the queue and waits
/// for the thread, returning the first failure.
fn leave_background() -> Option<IoError> {
    let worker = {
        let mut b = background();
        b.depth -= 1;
        if b.depth > 0 {
            return None;
        }
        close_queue(&mut b)
    }?;
    join_worker(worker)
}

/// A temporary file written whole, waiting for its sync and rename onto `path`.
struct Pending {
    tmp: NamedTempFile,
    path: PathBuf,
    _live: Registered,
}

fn write_error(path: &Path) -> impl FnOnce(std::io::Error) -> IoError + '_ {
    move |source| IoError::Write {
        path: path.to_path_buf(),
        reason: source,
    }
}

/// Syncs a pending file's content to disk.
fn sync_file(p: &Pending) -> Result<(), IoError> {
    // Re-open by path: a producer may have recreated the file instead of writing our handle.
    File::open(p.tmp.path())
        .and_then(|f| f.sync_all())
        .map_err(write_error(&p.path))
}

/// Renames a synced pending file onto its target (readable by all, as any result file), then
/// syncs the directory, or leaves that to [`with_deferred_dir_sync`].
fn rename_into_place(p: Pending) -> Result<(), IoError> {
    let path = &p.path;
    // Temporary files are created 0600; a result file is for sharing like any other (0644).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(p.tmp.path(), std::fs::Permissions::from_mode(0o644))
            .map_err(write_error(path))?;
    }
    p.tmp.persist(path).map_err(|e| IoError::Persist {
        path: path.to_path_buf(),
        reason: e.error,
    })?;
    #[cfg(unix)]
    if let Ok((dir, _)) = split(path) {
        sync_dir_now_or_later(dir);
    }
    Ok(())
}

thread_local! {
    /// The open [`with_batched_persist`] calls on this thread (how many) and their files.
    static BATCH: std::cell::RefCell<Option<(usize, Vec<Pending>)>> =
        const { std::cell::RefCell::new(None) };
}

/// Runs `f`, which writes files atomically on this thread, and puts its files in place
/// together when it returns `Ok`: their syncs run at once, on a thread each, then each is
/// renamed onto its target in the order written. A sync waits for a commit of the
/// filesystem's journal, and a file's writer blocked on it; a group of files synced together
/// shares the commits (a dump's eight files, synced one after another, held a worker thread
/// blocked for about 5 ms). If `f` fails, or a sync does, none of its files is put in place
/// (their temporaries are deleted, the targets untouched); a rename that fails stops the
/// rest. Until it returns, the files are not at their paths: `f` must not read them back.
/// Nested calls join the outermost one. The batch belongs to the thread, so `f` must not wait
/// on a thread pool that may run other work on this thread meanwhile (rayon's `join` or a
/// parallel iterator: a job taken up there would write into this batch, and find its files
/// missing if it read them back); a dump's writers run on their own.
pub fn with_batched_persist<R>(f: impl FnOnce() -> Result<R, IoError>) -> Result<R, IoError> {
    BATCH.with_borrow_mut(|b| b.get_or_insert_with(|| (0, Vec::new())).0 += 1);
    // If `f` panics, the outermost level drops its files (their temporaries deleted,
    // nothing put in place).
    let (result, files) = then_leave(f, close_batch);
    let value = result?;
    // An inner call's files wait for the outermost.
    let Some(files) = files else {
        return Ok(value);
    };
    // Every sync at once; the first error (in the order written) stops the batch.
    let synced: Vec<Result<(), IoError>> = match files.len() {
        0 => Vec::new(),
        1 => vec![sync_file(&files[0])],
        _ => std::thread::scope(|s| {
            // A thread that cannot be started leaves its sync to this one, after the others.
            let jobs: Vec<_> = files
                .iter()
                .map(|p| std::thread::Builder::new().spawn_scoped(s, || sync_file(p)))
                .collect();
            jobs.into_iter()
                .zip(&files)
                .map(|(j, p)| match j {
                    Ok(j) => j.join().unwrap_or_else(|_| {
                        Err(IoError::Write {
                            path: p.path.clone(),
                            reason: std::io::Error::other("the sync's thread panicked"),
                        })
                    }),
                    Err(_) => sync_file(p),
                })
                .collect()
        }),
    };
    synced.into_iter().collect::<Result<Vec<()>, IoError>>()?;
    for p in files {
        rename_into_place(p)?;
    }
    Ok(value)
}

/// Runs `f`, then `leave`, which also runs (its value dropped) if `f` panics: a scope's level
/// is left on every way out.
fn then_leave<R, L>(f: impl FnOnce() -> R, leave: fn() -> L) -> (R, L) {
    struct OnUnwind<L>(fn() -> L);
    impl<L> Drop for OnUnwind<L> {
        fn drop(&mut self) {
            drop((self.0)());
        }
    }
    let guard = OnUnwind(leave);
    let result = f();
    std::mem::forget(guard);
    (result, leave())
}

/// Leaves one level of [`with_batched_persist`] on this thread: the batch's files when it was
/// the outermost, else `None`.
fn close_batch() -> Option<Vec<Pending>> {
    BATCH.with_borrow_mut(|b| {
        let (depth, _) = b.as_mut()?;
        *depth -= 1;
        if *depth > 0 {
            return None;
        }
        b.take().map(|(_, files)| files)
    })
}

/// How many files [`with_batched_persist`] holds on this thread now (for tests).
pub fn batched_files() -> usize {
    BATCH.with_borrow(|b| b.as_ref().map_or(0, |(_, files)| files.len()))
}

/// Syncs a directory (best effort: some filesystems refuse fsync on directories).
fn sync_dir(dir: &Path) {
    let _ = File::open(dir).and_then(|d| d.sync_all());
}

/// The directories whose sync [`with_deferred_dir_sync`] owes, while one runs (`None`
/// otherwise), with how many run at once.
static DEFERRED: std::sync::Mutex<(usize, Option<std::collections::BTreeSet<PathBuf>>)> =
    std::sync::Mutex::new((0, None));

fn deferred() -> std::sync::MutexGuard<'static, (usize, Option<std::collections::BTreeSet<PathBuf>>)>
{
    DEFERRED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Syncs `dir` after a rename into it, or, while [`with_deferred_dir_sync`] runs, leaves it
/// to that. The check and the insertion hold the lock the drain takes, so a rename either
/// joins a set that will be synced or syncs its directory itself.
#[cfg_attr(not(unix), allow(dead_code))]
fn sync_dir_now_or_later(dir: PathBuf) {
    {
        let mut d = deferred();
        if let Some(set) = d.1.as_mut() {
            set.insert(dir);
            return;
        }
    }
    sync_dir(&dir);
}

/// Runs `f` with the directory syncs of the files it writes atomically deferred to its end:
/// each directory is synced once when `f` returns (the outermost of nested calls), instead of
/// after every rename into it. Every file is still synced before its rename, so a reader
/// never sees a partial file; only the durability of the names waits, until this returns.
/// Why: `reproduce` writes 74 files into 6 directories, and a directory sync per file (about
/// 0.3 ms each) held a worker thread blocked for tens of milliseconds. The owed set is the
/// process's: while calls on several threads overlap, every sync waits for the last of them
/// to return. An exit that skips destructors (a second Ctrl-C) leaves the syncs unpaid: the
/// files are whole, their names not yet durable.
pub fn with_deferred_dir_sync<R>(f: impl FnOnce() -> R) -> R {
    {
        let mut d = deferred();
        d.0 += 1;
        d.1.get_or_insert_with(Default::default);
    }
    // Drained on the way out, a panic included.
    struct Drain;
    impl Drop for Drain {
        fn drop(&mut self) {
            let owed = {
                let mut d = deferred();
                d.0 -= 1;
                if d.0 == 0 {
                    d.1.take().unwrap_or_default()
                } else {
                    Default::default()
                }
            };
            for dir in &owed {
                sync_dir(dir);
            }
        }
    }
    let _drain = Drain;
    f()
}

/// The directories [`with_deferred_dir_sync`] owes a sync now (for tests).
pub fn deferred_dir_syncs() -> Vec<PathBuf> {
    deferred()
        .1
        .as_ref()
        .map_or_else(Vec::new, |s| s.iter().cloned().collect())
}

/// Streams into a temporary sibling of `path` through a buffered writer, then atomically
/// replaces `path`. Used by every writer of this crate.
pub(crate) fn atomic_stream<F>(path: &Path, fill: F) -> Result<(), IoError>
where
    F: FnOnce(&mut BufWriter<&mut File>) -> Result<(), IoError>,
{
    let mut tmp = temp_sibling(path, "")?;
    let live = Registered::new(tmp.path());
    {
        let mut w = BufWriter::new(tmp.as_file_mut());
        fill(&mut w)?;
        w.flush().map_err(|source| IoError::Write {
            path: path.to_path_buf(),
            reason: source,
        })?;
    }
    persist(tmp, path, live)
}

/// Atomically replaces `path` with `bytes` (temp sibling, flush, fsync, rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    atomic_stream(path, |w| {
        w.write_all(bytes).map_err(|source| IoError::Write {
            path: path.to_path_buf(),
            reason: source,
        })
    })
}

/// Atomically produces `path` with a tool that insists on writing to a path itself (e.g. an image
/// encoder). `produce` receives the temporary sibling's path, which keeps the target's extension
/// so format detection by extension works; on success the file is synced and renamed onto
/// `path`, on failure it is deleted and `path` is left untouched.
pub fn write_atomic_via<F>(path: &Path, produce: F) -> Result<(), IoError>
where
    F: FnOnce(&Path) -> Result<(), Box<dyn std::error::Error + Send + Sync>>,
{
    let suffix = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let tmp = temp_sibling(path, &suffix)?;
    let live = Registered::new(tmp.path());
    produce(tmp.path()).map_err(|source| IoError::Producer {
        path: path.to_path_buf(),
        reason: source,
    })?;
    persist(tmp, path, live)
}
