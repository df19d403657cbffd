//! `with_deferred_dir_sync`: the files written inside are whole at their paths at once, their
//! directories are owed one sync each until the outermost call returns (a panic included),
//! and outside it nothing is owed. Alone in this test binary, so no other test's writes join
//! the set.

use gyroemu_io::{deferred_dir_syncs, with_deferred_dir_sync, write_atomic};
use std::path::PathBuf;

#[test]
fn directory_syncs_wait_for_the_outermost_call_and_a_panic_pays_them() {
    let root = tempfile::tempdir().unwrap();
    let (a, b) = (root.path().join("a"), root.path().join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    assert!(deferred_dir_syncs().is_empty());
    let mut sorted = vec![a.clone(), b.clone()];
    sorted.sort();
    with_deferred_dir_sync(|| {
        for (dir, n) in [(&a, 3), (&b, 2)] {
            for i in 0..n {
                let path = dir.join(format!("f{i}.txt"));
                write_atomic(&path, format!("file {i}").as_bytes()).unwrap();
                // Atomic as ever: the whole file is at its path when the call returns.
                assert_eq!(std::fs::read_to_string(&path).unwrap(), format!("file {i}"));
            }
        }
        // One sync owed per directory, however many files went into it.
        assert_eq!(deferred_dir_syncs(), sorted);
        with_deferred_dir_sync(|| write_atomic(&a.join("inner.txt"), b"x").unwrap());
        // The inner call's end pays nothing: the outer one still owes both.
        assert_eq!(deferred_dir_syncs(), sorted);
    });
    assert!(deferred_dir_syncs().is_empty());
    // Outside, a write syncs its own directory: nothing is owed.
    write_atomic(&a.join("after.txt"), b"y").unwrap();
    assert!(deferred_dir_syncs().is_empty());
    // A panic inside still pays what is owed, and leaves no scope open.
    let c: PathBuf = root.path().join("c");
    std::fs::create_dir_all(&c).unwrap();
    let caught = std::panic::catch_unwind(|| {
        with_deferred_dir_sync(|| {
            write_atomic(&c.join("f.txt"), b"z").unwrap();
            assert_eq!(deferred_dir_syncs(), vec![c.clone()]);
            panic!("a failed run");
        })
    });
    assert!(caught.is_err());
    assert!(deferred_dir_syncs().is_empty());
    write_atomic(&c.join("g.txt"), b"w").unwrap();
    assert!(deferred_dir_syncs().is_empty());
}
