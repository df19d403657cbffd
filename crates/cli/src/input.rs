//! The program's side of input and output: reading a config file, refusals (exit code 2), and
//! printing to a stdout that a reader may close early.

use anyhow::Result;
use gyroemu_config::{parse_config, Config, ConfigError};
use std::path::Path;

/// A refusal of the user's input (exit code 2), as opposed to a failure while running.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

/// The largest config file read: far above any real one (a preset is about 3 kB), and a
/// bound on what a path to an endless stream (`/dev/zero`, a pipe that never ends) reads.
pub const MAX_CONFIG_BYTES: u64 = 16 << 20;

/// Reads a config file's text: readable, at most [`MAX_CONFIG_BYTES`], UTF-8.
pub fn read_config_text(path: &Path) -> Result<String> {
    let bytes = gyroemu_io::read_capped(path, MAX_CONFIG_BYTES)
        .map_err(|e| BadInput(format!("cannot read config `{}`: {e}", path.display())))?;
    if bytes.len() as u64 > MAX_CONFIG_BYTES {
        return Err(BadInput(format!(
            "config `{}` is larger than {} MiB: not a gyroemu config (a preset is about 3 kB)",
            path.display(),
            MAX_CONFIG_BYTES >> 20
        ))
        .into());
    }
    Ok(String::from_utf8(bytes)
        .map_err(|_| BadInput(format!("config `{}` is not UTF-8 text", path.display())))?)
}

/// Reads and parses a config file (every problem of its text in one refusal), not yet
/// validated; returns it with its text.
pub fn read_config(path: &Path) -> Result<(Config, String)> {
    let text = read_config_text(path)?;
    let cfg = parse_config(&text).map_err(|e| BadInput(format!("{}: {e}", path.display())))?;
    Ok((cfg, text))
}

/// The refusal of a config that parsed but broke rules: each problem located in its text.
pub fn refused(path: &Path, text: &str, e: ConfigError) -> BadInput {
    BadInput(format!("{}: {}", path.display(), e.with_locations(text)))
}

/// Reads, parses and validates a config file (every broken rule in one refusal); prints its
/// warnings.
pub fn load_config(path: &Path) -> Result<Config> {
    let (cfg, text) = read_config(path)?;
    let warnings = cfg.validate().map_err(|e| refused(path, &text, e))?;
    for w in warnings {
        note!("warning: {}: {w}", path.display());
    }
    Ok(cfg)
}

/// Writes to stdout; a reader that closed the pipe early (`| head`) ends the output quietly.
pub fn print_out(text: &str) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(anyhow::anyhow!("cannot write to the standard output: {e}"))
        }
        _ => Ok(()),
    }
}

/// This process's command line, for the output folder's lock (arguments with spaces quoted).
pub fn command_line() -> String {
    // `args_os`: `args` panics on an argument that is not UTF-8 (a path of Latin-1 bytes).
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .map(|a| {
            if a.contains(char::is_whitespace) || a.is_empty() {
                format!("'{a}'")
            } else {
                a
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Per-item files a command saved in one folder of its output (a sweep's points, a lot's
/// devices): listed as the folder and their count, since there may be thousands.
#[derive(Clone, Copy, Debug)]
pub struct ItemFiles<'a> {
    /// The folder, relative to the output folder (`points`).
    pub dir: &'a str,
    /// What each file holds (`point`).
    pub item: &'a str,
    /// How many this command wrote.
    pub count: usize,
}

/// Lists the files a command wrote, one per line on stderr, relative to `out` where inside it.
pub fn list_written(out: &Path, files: &[std::path::PathBuf]) {
    list_written_with(out, files, None);
}

/// `r`, having listed the files a run wrote before refusing numbers in them
/// ([`gyroemu_runs::RunError::Refused`]): its list, as a run that completes ends with, and a
/// lot's figures on stdout.
pub fn listing_refused<T>(
    r: Result<T, gyroemu_runs::RunError>,
    out: &Path,
    items: Option<ItemFiles>,
) -> Result<T, gyroemu_runs::RunError> {
    if let Err(gyroemu_runs::RunError::Refused { files, lot, .. }) = &r {
        // A lot's figures over its trusted devices, as a completed lot prints them; the
        // command fails with its error next, so a closed stdout changes nothing here.
        if let Some(lot) = lot {
            let _ = print_out(&crate::lot_text::summary_text(lot));
        }
        list_written_with(out, files, items);
    }
    r
}

/// [`list_written`], then the per-item files `items` as one line: `points/ (3 point files)`.
pub fn list_written_with(out: &Path, files: &[std::path::PathBuf], items: Option<ItemFiles>) {
    let items = items.filter(|i| i.count > 0);
    let total = files.len() + items.map_or(0, |i| i.count);
    let s = if total == 1 { "" } else { "s" };
    note!("wrote {total} file{s} in `{}`:", out.display());
    for f in files {
        let shown = f.strip_prefix(out).unwrap_or(f);
        note!("  {}", shown.display());
    }
    if let Some(i) = items {
        let s = if i.count == 1 { "" } else { "s" };
        note!("  {}/ ({} {} file{s})", i.dir, i.count, i.item);
    }
}

/// Counts the items a run saves, from its `on_saved` reports (each the running total, which
/// parallel groups may report out of order).
#[derive(Debug, Default)]
pub struct SavedCount(std::sync::atomic::AtomicUsize);

impl SavedCount {
    /// Records a report of `k` items saved so far.
    pub fn saved(&self, k: usize) {
        self.0.fetch_max(k, std::sync::atomic::Ordering::Relaxed);
    }

    /// The items saved.
    pub fn get(&self) -> usize {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}
