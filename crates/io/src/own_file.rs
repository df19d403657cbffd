//! Reading back files gyroemu wrote itself (a run's manifest, its point and device files, a
//! folder's lock). They are small and regular; what stands under their names may not be: a
//! symlink to /dev/zero was read until memory ran out, and a FIFO blocked `run` and `merge`
//! forever. So only a regular file of bounded size is read, and anything else is an error
//! naming what it is.

use std::io::{Error, ErrorKind};
use std::path::Path;

/// The largest manifest read: its config text (configs are capped at 16 MiB) and its lists of
/// up to a million items' indices.
pub const MAX_MANIFEST_BYTES: u64 = 64 << 20;
/// The largest point or device file read (they hold about a kilobyte).
pub const MAX_RECORD_BYTES: u64 = 1 << 20;
/// The largest folder lock read (a pid, a host and the command line).
pub const MAX_LOCK_BYTES: u64 = 4 << 20;

/// `path` as UTF-8 text if it is a regular file (symlinks followed) of at most `cap` bytes.
/// A missing file keeps its `NotFound` kind; anything else under the name (a FIFO, a device,
/// a folder) or a longer file is an `InvalidData` error saying so, unread.
pub fn read_own_text(path: &Path, cap: u64) -> std::io::Result<String> {
    // Stat before opening: opening a FIFO blocks until a writer comes, a device may never end.
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a folder"
        } else {
            "not a regular file, but a FIFO or a device, which gyroemu never writes there"
        };
        return Err(Error::new(ErrorKind::InvalidData, what));
    }
    if meta.len() > cap {
        return Err(Error::new(
            ErrorKind::InvalidData,
            format!(
                "{} bytes, more than the {cap} such a file of gyroemu holds",
                meta.len()
            ),
        ));
    }
    // The file may grow between the stat and the read: read one byte past the cap at most.
    let bytes = crate::read_capped(path, cap)?;
    if bytes.len() as u64 > cap {
        return Err(Error::new(
            ErrorKind::InvalidData,
            format!("more than the {cap} bytes such a file of gyroemu holds"),
        ));
    }
    String::from_utf8(bytes).map_err(|_| Error::new(ErrorKind::InvalidData, "not UTF-8 text"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_regular_file_within_the_cap_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.json");
        std::fs::write(&p, "{}").unwrap();
        assert_eq!(read_own_text(&p, 2).unwrap(), "{}");
        // One byte over the cap: refused by its size, unread.
        let e = read_own_text(&p, 1).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::InvalidData);
        assert!(e.to_string().contains("2 bytes, more than the 1"), "{e}");
        // Missing keeps its kind (a missing lock means no lock).
        let e = read_own_text(&dir.path().join("none"), 9).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::NotFound);
        // A folder, and a symlink to a device that never ends.
        let e = read_own_text(dir.path(), 9).unwrap_err();
        assert!(e.to_string().contains("a folder"), "{e}");
        #[cfg(unix)]
        {
            let z = dir.path().join("z.json");
            std::os::unix::fs::symlink("/dev/zero", &z).unwrap();
            let e = read_own_text(&z, 1 << 20).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{e}");
        }
        let b = dir.path().join("b.json");
        std::fs::write(&b, [0xff, 0xfe]).unwrap();
        assert!(read_own_text(&b, 9)
            .unwrap_err()
            .to_string()
            .contains("UTF-8"));
    }

    /// A FIFO is refused without opening it: opening one blocks until a writer comes, so a
    /// read that opened it would never return here (no writer ever comes).
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("point-4.json");
        let made = std::process::Command::new("mkfifo").arg(&f).status();
        assert!(
            made.is_ok_and(|s| s.success()),
            "mkfifo (coreutils) made no FIFO"
        );
        let e = read_own_text(&f, 1 << 20).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
    }
}
