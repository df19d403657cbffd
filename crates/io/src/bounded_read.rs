//! Reading a file whole only if it is what it should be and within a bound ([`read_bounded`]):
//! a dump a user hands `inspect` (which may come through a FIFO), and files gyroemu wrote
//! itself ([`read_own_text`]: a run's manifest, its point and device files, a folder's lock).
//! Those are small and regular; what stands under their names may not be: a symlink to
//! /dev/zero was read until memory ran out, and a FIFO blocked `run` and `merge` forever. So
//! only a regular file of bounded size is read there, and anything else is an error naming
//! what it is.

use std::io::{Error, ErrorKind};
use std::path::Path;

/// The largest manifest read: its config text (configs are capped at 16 MiB) and its lists of
/// up to a million items' indices.
pub const MAX_MANIFEST_BYTES: u64 = 64 << 20;
/// The largest point or device file read (they hold about a kilobyte).
pub const MAX_RECORD_BYTES: u64 = 1 << 20;
/// The largest folder lock read (a pid, a host and the command line).
pub const MAX_LOCK_BYTES: u64 = 4 << 20;

/// Reads `path` up to `cap` + 1 bytes: a longer file, or a stream that never ends, comes back
/// one byte over `cap`, which tells the caller it is too long without reading the rest. Room
/// for a regular file's bytes is reserved at once (out of memory is an error, not an abort).
pub fn read_capped(path: &Path, cap: u64) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let file = std::fs::File::open(path)?;
    let want = file.metadata()?.len().min(cap.saturating_add(1));
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(usize::try_from(want).unwrap_or(usize::MAX))
        .map_err(|_| {
            std::io::Error::new(
                std::io::ErrorKind::OutOfMemory,
                format!("{want} bytes do not fit in memory"),
            )
        })?;
    file.take(cap.saturating_add(1)).read_to_end(&mut bytes)?;
    Ok(bytes)
}

#[cfg(unix)]
fn is_fifo(t: &std::fs::FileType) -> bool {
    std::os::unix::fs::FileTypeExt::is_fifo(t)
}

#[cfg(not(unix))]
fn is_fifo(_: &std::fs::FileType) -> bool {
    false
}

/// Why [`read_bounded`] read nothing, or all it read.
pub(crate) enum Unread {
    /// The file system's own error (a missing file keeps its `NotFound` kind).
    Io(Error),
    /// Not a file it reads: a folder (`true`), or a device or (when not taken) a FIFO.
    NotRegular { folder: bool },
    /// Longer than the cap: its size when a regular file says it, `None` when the bytes read
    /// passed it (a FIFO, or a file that grew).
    TooBig(Option<u64>),
}

/// `path`'s bytes if it is a regular file (symlinks followed), or with `fifo` a FIFO (`<(...)`),
/// of at most `cap` bytes. Stats before opening: opening a FIFO blocks until a writer comes,
/// and a device such as /dev/zero may never end. A regular file is refused by its size,
/// unread; a FIFO's size is unknown until it ends, hence the cap on the bytes read too.
pub(crate) fn read_bounded(path: &Path, cap: u64, fifo: bool) -> Result<Vec<u8>, Unread> {
    let meta = std::fs::metadata(path).map_err(Unread::Io)?;
    if !(meta.is_file() || fifo && is_fifo(&meta.file_type())) {
        return Err(Unread::NotRegular {
            folder: meta.is_dir(),
        });
    }
    if meta.len() > cap {
        return Err(Unread::TooBig(Some(meta.len())));
    }
    let bytes = read_capped(path, cap).map_err(Unread::Io)?;
    if bytes.len() as u64 > cap {
        return Err(Unread::TooBig(None));
    }
    Ok(bytes)
}

/// `path` as UTF-8 text if it is a regular file (symlinks followed) of at most `cap` bytes.
/// A missing file keeps its `NotFound` kind; anything else under the name (a FIFO, a device,
/// a folder) or a longer file is an `InvalidData` error saying so, unread.
pub fn read_own_text(path: &Path, cap: u64) -> std::io::Result<String> {
    let invalid = |what: String| Error::new(ErrorKind::InvalidData, what);
    let bytes = read_bounded(path, cap, false).map_err(|e| match e {
        Unread::Io(e) => e,
        Unread::NotRegular { folder: true } => invalid("a folder".into()),
        Unread::NotRegular { folder: false } => invalid(
            "not a regular file, but a FIFO or a device, which gyroemu never writes there".into(),
        ),
        Unread::TooBig(Some(len)) => invalid(format!(
            "{len} bytes, more than the {cap} such a file of gyroemu holds"
        )),
        Unread::TooBig(None) => invalid(format!(
            "more than the {cap} bytes such a file of gyroemu holds"
        )),
    })?;
    String::from_utf8(bytes).map_err(|_| invalid("not UTF-8 text".into()))
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
