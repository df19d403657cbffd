//! `with_background_persist`: files written inside, on any thread, are in place (whole, their
//! contents the last written, readable by all) when it returns, with no temporary left; a file
//! that cannot be put in place is reported then, the others still put in place; `f`'s own
//! error wins; a panic still waits for the files; nested calls wait for the outermost; a
//! batch inside puts its files in place before it returns (a dump's figures read them back).
//!
//! The mode is the process's, so these tests take turns (`SERIAL`).

mod common;
use common::entries;
use gyroemu_io::{with_background_persist, with_batched_persist, write_atomic, IoError};
use std::path::Path;
use std::sync::Mutex;

static SERIAL: Mutex<()> = Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// A target the rename cannot replace: a directory holding a file.
fn blocked(d: &Path) -> std::path::PathBuf {
    let t = d.join("blocked");
    std::fs::create_dir(&t).unwrap();
    std::fs::write(t.join("inside"), b"x").unwrap();
    t
}

#[test]
fn files_from_every_thread_are_in_place_when_it_returns() {
    let _s = serial();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let got: Result<usize, IoError> = with_background_persist(|| {
        std::thread::scope(|s| {
            for t in 0..4 {
                s.spawn(move || {
                    for i in 0..25 {
                        let body = format!("thread {t} file {i}");
                        write_atomic(&d.join(format!("t{t}_{i}.txt")), body.as_bytes()).unwrap();
                    }
                });
            }
        });
        // The same path twice on one thread: the later contents win.
        write_atomic(&d.join("twice.txt"), b"first")?;
        write_atomic(&d.join("twice.txt"), b"second")?;
        Ok(7)
    });
    assert_eq!(got.unwrap(), 7);
    let names = entries(d);
    assert_eq!(names.len(), 101, "{names:?}");
    assert!(names.iter().all(|n| !n.starts_with('.')));
    for t in 0..4 {
        for i in 0..25 {
            let body = std::fs::read_to_string(d.join(format!("t{t}_{i}.txt"))).unwrap();
            assert_eq!(body, format!("thread {t} file {i}"));
        }
    }
    assert_eq!(std::fs::read(d.join("twice.txt")).unwrap(), b"second");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(d.join("t0_0.txt"))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o777, 0o644);
    }
}

#[test]
fn a_file_that_cannot_be_put_in_place_is_reported_at_the_end() {
    let _s = serial();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let target = blocked(d);
    let got: Result<(), IoError> = with_background_persist(|| {
        write_atomic(&d.join("before.txt"), b"a")?;
        // Outside the mode this write fails at once; here its writer goes on.
        write_atomic(&target, b"cannot replace a directory")
    });
    match got {
        Err(IoError::Persist { path, .. }) => assert_eq!(path, target),
        other => panic!("expected the blocked target's error, got {other:?}"),
    }
    // The other file is in place, the directory untouched, no temporary left.
    assert_eq!(entries(d), vec!["before.txt", "blocked"]);
    assert_eq!(entries(&target), vec!["inside"]);
    assert!(
        write_atomic(&target, b"x").is_err(),
        "outside the mode it fails at once"
    );
}

#[test]
fn writes_after_a_failure_fail_at_once_naming_it() {
    let _s = serial();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let target = blocked(d);
    let mut written = 0;
    let got: Result<(), IoError> = with_background_persist(|| {
        write_atomic(&target, b"x")?;
        // Until the thread has met the failure, writes go on; then the next one is refused.
        for i in 0..20_000 {
            write_atomic(&d.join(format!("n{i:05}.txt")), b"n")?;
            written += 1;
            std::thread::sleep(std::time::Duration::from_micros(200));
        }
        Ok(())
    });
    let e = got.expect_err("a write after the failure is refused");
    assert!(matches!(e, IoError::Write { .. }), "{e:?}");
    assert!(e.to_string().contains("blocked"), "{e}");
    // The writes before it are in place, the refused one is not, no temporary is left.
    let names = entries(d);
    assert_eq!(names.len(), written + 1, "{names:?}");
    assert!(names.iter().all(|n| !n.starts_with('.')));
}

#[test]
fn a_flush_puts_the_files_in_place_and_leaves_the_rest_to_their_writers() {
    let _s = serial();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let got: Result<(), IoError> = with_background_persist(|| {
        for i in 0..5 {
            write_atomic(&d.join(format!("q{i}.txt")), b"q")?;
        }
        gyroemu_io::flush_background_persist();
        assert_eq!(
            entries(d),
            vec!["q0.txt", "q1.txt", "q2.txt", "q3.txt", "q4.txt"]
        );
        // After the flush a write is in place when it returns.
        write_atomic(&d.join("later.txt"), b"l")?;
        assert!(d.join("later.txt").exists());
        Ok(())
    });
    got.unwrap();
}

#[test]
fn the_callers_error_wins_and_a_panic_still_waits_for_the_files() {
    let _s = serial();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let target = blocked(d);
    #[derive(Debug)]
    enum Failure {
        Io(#[allow(dead_code)] IoError),
        Own,
    }
    impl From<IoError> for Failure {
        fn from(e: IoError) -> Self {
            Failure::Io(e)
        }
    }
    // The failing file last: no write after it can meet its failure and be refused.
    let got: Result<(), Failure> = with_background_persist(|| {
        write_atomic(&d.join("written.txt"), b"w")?;
        write_atomic(&target, b"x")?;
        Err(Failure::Own)
    });
    assert!(matches!(got, Err(Failure::Own)), "{got:?}");
    assert_eq!(std::fs::read(d.join("written.txt")).unwrap(), b"w");
    let panicked = std::panic::catch_unwind(|| {
        let _: Result<(), IoError> = with_background_persist(|| {
            write_atomic(&d.join("before_panic.txt"), b"p").unwrap();
            panic!("a writer panics");
        });
    });
    assert!(panicked.is_err());
    assert_eq!(std::fs::read(d.join("before_panic.txt")).unwrap(), b"p");
    // The mode ended with the panic: a write is in place when it returns.
    write_atomic(&d.join("plain.txt"), b"q").unwrap();
    assert!(d.join("plain.txt").exists());
    assert!(entries(d).iter().all(|n| !n.starts_with('.')));
}

#[test]
fn nested_calls_report_at_the_outermost_and_batches_inside_are_in_place_at_once() {
    let _s = serial();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let target = blocked(d);
    let got: Result<(), IoError> = with_background_persist(|| {
        let inner: Result<(), IoError> = with_background_persist(|| write_atomic(&target, b"x"));
        assert!(
            inner.is_ok(),
            "the inner call leaves the files to the outermost"
        );
        // A batch puts its files in place before it returns: they can be read back here.
        with_batched_persist(|| {
            write_atomic(&d.join("b1.txt"), b"1")?;
            write_atomic(&d.join("b2.txt"), b"2")
        })?;
        assert_eq!(std::fs::read(d.join("b1.txt")).unwrap(), b"1");
        assert_eq!(std::fs::read(d.join("b2.txt")).unwrap(), b"2");
        Ok(())
    });
    assert!(matches!(got, Err(IoError::Persist { .. })), "{got:?}");
}
