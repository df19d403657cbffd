//! `with_batched_persist`: the files written inside are put in place together when it
//! returns `Ok` (whole, with their contents), none of them if it fails or panics (their
//! temporaries deleted, earlier files at those paths untouched), and nested calls join the
//! outermost.

mod common;
use common::entries;
use gyroemu_io::{batched_files, with_batched_persist, write_atomic, IoError};

#[test]
fn a_batch_puts_its_files_in_place_together() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let got = with_batched_persist(|| {
        for i in 0..6 {
            write_atomic(&d.join(format!("f{i}.txt")), format!("body {i}").as_bytes())?;
        }
        // Nothing at the targets yet: six temporaries, held by the batch.
        assert_eq!(batched_files(), 6);
        assert!(
            entries(d).iter().all(|n| n.starts_with('.')),
            "{:?}",
            entries(d)
        );
        // A nested batch joins this one.
        with_batched_persist(|| write_atomic(&d.join("inner.txt"), b"in"))?;
        assert_eq!(batched_files(), 7);
        assert!(!d.join("inner.txt").exists());
        Ok(42)
    });
    assert_eq!(got.unwrap(), 42);
    assert_eq!(batched_files(), 0);
    let mut want: Vec<String> = (0..6).map(|i| format!("f{i}.txt")).collect();
    want.push("inner.txt".into());
    want.sort();
    assert_eq!(entries(d), want);
    for i in 0..6 {
        let body = std::fs::read_to_string(d.join(format!("f{i}.txt"))).unwrap();
        assert_eq!(body, format!("body {i}"));
    }
    // One file alone is synced without a thread of its own, the same way in the end.
    with_batched_persist(|| write_atomic(&d.join("one.txt"), b"1")).unwrap();
    assert_eq!(std::fs::read(d.join("one.txt")).unwrap(), b"1");
}

#[test]
fn a_failed_or_panicking_batch_puts_nothing_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_atomic(&d.join("kept.txt"), b"old").unwrap();
    let failed: Result<(), IoError> = with_batched_persist(|| {
        write_atomic(&d.join("kept.txt"), b"new")?;
        write_atomic(&d.join("new.txt"), b"x")?;
        // A writer that fails after two files: a missing directory.
        write_atomic(&d.join("no-such-dir/f.txt"), b"y")
    });
    assert!(failed.is_err());
    // The earlier file keeps its contents, the new one never appears, no temporary is left.
    assert_eq!(entries(d), vec!["kept.txt".to_string()]);
    assert_eq!(std::fs::read(d.join("kept.txt")).unwrap(), b"old");
    assert_eq!(batched_files(), 0);
    let caught = std::panic::catch_unwind(|| {
        with_batched_persist(|| -> Result<(), IoError> {
            write_atomic(&d.join("p.txt"), b"p")?;
            panic!("a failed writer");
        })
    });
    assert!(caught.is_err());
    assert_eq!(entries(d), vec!["kept.txt".to_string()]);
    // The thread's batch is closed: the next write is in place at once.
    assert_eq!(batched_files(), 0);
    write_atomic(&d.join("after.txt"), b"a").unwrap();
    assert!(d.join("after.txt").exists());
}
