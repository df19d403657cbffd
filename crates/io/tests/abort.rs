//! The abort path's clean-up, alone in its test binary: `remove_temporaries` acts on every
//! temporary file of the process, so no other test may be writing beside it.

fn entries(dir: &std::path::Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

/// An abort in the middle of a write (Ctrl-C exits without running destructors) removes the
/// temporary file being written: reproduce had left `.fig_ratetable.png.tmpXXXXXX.png` behind.
#[test]
fn an_abort_removes_the_temporaries_being_written() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("fig.png");
    let mut removed = 0;
    let r = gyroemu_io::write_atomic_via(&target, |tmp| {
        std::fs::write(tmp, b"half")?;
        // What the signal handler does before exiting.
        removed = gyroemu_io::remove_temporaries();
        Ok(())
    });
    assert_eq!(removed, 1);
    assert!(r.is_err(), "the write must fail: its temporary is gone");
    assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
    // Once a write is over, nothing of it is registered any more.
    gyroemu_io::write_atomic(&target, b"whole").unwrap();
    assert_eq!(gyroemu_io::remove_temporaries(), 0);
    assert_eq!(std::fs::read(&target).unwrap(), b"whole");
}
