//! `gyroemu run` and `gyroemu config`.

use crate::progress::Progress;
use crate::report::write_run;
use crate::resume::{cancel_flag, previous_points, Interrupted, Manifest, ShardId, RUN_MANIFEST};
use crate::shard::resolve_shard;
use anyhow::{Context, Result};
use gyroemu_experiment::board::LaneResult;
use gyroemu_experiment::checkpoint::{canonical_toml, config_hash, write_point, POINTS_DIR};
use gyroemu_experiment::presets::{preset_text, PRESETS};
use gyroemu_experiment::sweep::{emulated_rates_dps, finish_sweep, run_sweep_with, SweepOptions};
use gyroemu_experiment::{parse_config, Config};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A refusal of the user's input (exit code 2), as opposed to a failure while running.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

/// Reads, parses and validates a config file; prints the warnings.
pub fn load_config(path: &Path) -> Result<Config> {
    let bytes = std::fs::read(path)
        .map_err(|e| BadInput(format!("cannot read config `{}`: {e}", path.display())))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| BadInput(format!("config `{}` is not UTF-8 text", path.display())))?;
    let cfg = parse_config(&text).map_err(|e| BadInput(format!("{}: {e}", path.display())))?;
    check_config(&cfg, &path.display().to_string())?;
    Ok(cfg)
}

/// Validates a config, printing its warnings; errors become [`BadInput`].
pub fn check_config(cfg: &Config, name: &str) -> Result<()> {
    let warnings = cfg
        .validate()
        .map_err(|e| BadInput(format!("{name}: {e}")))?;
    for w in warnings {
        eprintln!("warning: {name}: {w}");
    }
    Ok(())
}

/// Makes sure the output folder exists and is writable before any sample is computed.
pub fn prepare_out(out: &Path) -> Result<()> {
    std::fs::create_dir_all(out).map_err(|e| {
        BadInput(format!(
            "output folder `{}` cannot be created: {e}",
            out.display()
        ))
    })?;
    tempfile_in(out).map_err(|e| {
        BadInput(format!(
            "output folder `{}` is not writable: {e}",
            out.display()
        ))
    })?;
    Ok(())
}

fn tempfile_in(dir: &Path) -> std::io::Result<()> {
    let p = dir.join(format!(".gyroemu-write-test-{}", std::process::id()));
    std::fs::write(&p, b"")?;
    std::fs::remove_file(&p)
}

/// The arguments of `gyroemu run`.
pub struct RunArgs<'a> {
    /// The config file.
    pub config: &'a Path,
    /// The output folder.
    pub out: &'a Path,
    /// `--shard I/N`.
    pub shard: Option<&'a str>,
    /// `--shard-count N` (with `JOB_COMPLETION_INDEX` or a Slurm array).
    pub shard_count: Option<usize>,
    /// `--force`: delete results of another config found in the output folder.
    pub force: bool,
}

/// The plot title of a run.
pub fn run_title(cfg: &Config) -> String {
    format!(
        "{:?} run, f0 = {} Hz, Q = {}",
        cfg.experiment.kind, cfg.device.f0_hz, cfg.device.q
    )
}

/// Test hook: stop (as Ctrl-C does) once this many points are saved by this process.
const STOP_AFTER_ENV: &str = "GYROEMU_TEST_STOP_AFTER_POINTS";

/// `gyroemu run CONFIG --out DIR [--shard I/N]`: runs the points not yet saved in `DIR/points`
/// (all, or the shard's), saving each as it finishes; then (whole sweep) writes the results.
pub fn run(a: &RunArgs) -> Result<()> {
    let cfg = load_config(a.config)?;
    let shard = resolve_shard(a.shard, a.shard_count, &|k| std::env::var(k).ok())?;
    let out = a.out;
    prepare_out(out)?;
    let hash = config_hash(&cfg);
    let config_toml = canonical_toml(&cfg);
    let n = emulated_rates_dps(&cfg).len();
    let rates = emulated_rates_dps(&cfg);
    let mine: Vec<usize> = match &shard {
        Some(s) => s.points(n),
        None => (0..n).collect(),
    };
    let prev = previous_points(out, &hash, n, a.force)?;
    let reused = mine.iter().filter(|i| prev.contains_key(i)).count();
    let what = match &shard {
        Some(s) => format!(
            "shard {}/{} ({}): {} of the {n} points",
            s.index,
            s.count,
            s.source,
            mine.len()
        ),
        None => format!("{n} points"),
    };
    if reused == mine.len() {
        eprintln!(
            "{what}: all already computed for this config (sha256 {}) in `{}`: reusing them",
            &hash[..12],
            out.join(POINTS_DIR).display()
        );
    } else if reused > 0 {
        eprintln!(
            "{what}: resuming, {reused} already computed for this config in `{}`",
            out.join(POINTS_DIR).display()
        );
    } else {
        eprintln!("{what}");
    }
    let shard_id = shard.as_ref().map(|s| ShardId {
        index: s.index,
        count: s.count,
    });
    let manifest_path = match &shard {
        Some(s) => out.join(s.manifest_name()),
        None => out.join(RUN_MANIFEST),
    };
    let manifest = |status: &str, done: &BTreeMap<usize, LaneResult>| {
        Manifest::new(status, &hash, &config_toml, shard_id, n, &mine, done)
    };
    manifest("running", &prev).write(&manifest_path)?;

    let cancel = cancel_flag();
    let stop_after: Option<usize> = std::env::var(STOP_AFTER_ENV)
        .ok()
        .and_then(|v| v.parse().ok());
    if stop_after == Some(0) {
        cancel.store(true, Ordering::SeqCst);
    }
    let saved = AtomicUsize::new(0);
    let on_group = |pts: &[(usize, LaneResult)]| -> Result<(), String> {
        for (i, lane) in pts {
            write_point(out, &hash, *i, rates[*i], lane)?;
        }
        let k = saved.fetch_add(pts.len(), Ordering::SeqCst) + pts.len();
        if stop_after.is_some_and(|s| k >= s) {
            cancel.store(true, Ordering::SeqCst);
        }
        Ok(())
    };
    let progress = Progress::new("run");
    let opts = SweepOptions {
        done: prev,
        only: shard.as_ref().map(|_| mine.clone()),
        cancel: Some(cancel.clone()),
        on_group: Some(&on_group),
    };
    let swept = run_sweep_with(&cfg, &|d, t| progress.update(d, t), Some(out), opts);
    let swept = match swept {
        Ok(s) => s,
        Err(e) => {
            // What finished is saved; the manifest says the rest is missing.
            let done = gyroemu_experiment::checkpoint::scan_points(out)
                .ok()
                .and_then(|s| s.lanes(&hash, n).ok())
                .unwrap_or_default();
            let mut m = manifest("failed", &done);
            m.next = format!("fix the cause ({e}) and rerun the same command");
            m.write(&manifest_path)?;
            return Err(anyhow::Error::new(e).context("emulation failed"));
        }
    };
    progress.finish(swept.point_samples);
    let missing = mine.iter().filter(|i| !swept.lanes.contains_key(i)).count();
    if swept.cancelled || missing > 0 {
        let mut m = manifest("interrupted", &swept.lanes);
        m.next = "rerun the same command to resume".into();
        m.write(&manifest_path)?;
        return Err(Interrupted(format!(
            "interrupted: {} of {} points saved in `{}`, {missing} missing (listed in `{}`); \
             rerun the same command to resume",
            mine.len() - missing,
            mine.len(),
            out.join(POINTS_DIR).display(),
            manifest_path.display()
        ))
        .into());
    }
    let mut m = manifest("complete", &swept.lanes);
    if let Some(s) = &shard {
        m.next = format!(
            "when all {} shards are complete: gyroemu merge {}",
            s.count,
            out.display()
        );
        m.write(&manifest_path)?;
        eprintln!(
            "shard {}/{} complete: {} points in `{}`; {}",
            s.index,
            s.count,
            mine.len(),
            out.join(POINTS_DIR).display(),
            m.next
        );
        return Ok(());
    }
    let r = finish_sweep(&cfg, &swept.lanes).context("emulation failed")?;
    write_run(out, &cfg, &r, &run_title(&cfg))?;
    m.write(&manifest_path)?;
    eprintln!(
        "wrote {}/results.csv, summary.json, plot.png",
        out.display()
    );
    Ok(())
}

/// Writes to stdout; a reader that closed the pipe early (`| head`) ends the output quietly.
fn print_out(text: &str) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

/// `gyroemu config [--preset NAME] [--list]`.
pub fn config(preset: Option<&str>, list: bool) -> Result<()> {
    if list {
        let list: String = PRESETS
            .iter()
            .map(|(name, what, _)| format!("{name:18} {what}\n"))
            .collect();
        return print_out(&list);
    }
    let name = preset.unwrap_or("m2tfg-coriolis");
    let text = preset_text(name).ok_or_else(|| {
        BadInput(format!(
            "unknown preset `{name}`; presets: {}",
            PRESETS.iter().map(|p| p.0).collect::<Vec<_>>().join(", ")
        ))
    })?;
    print_out(text)
}

/// `gyroemu bench`: prints point-samples per second for the chain and each stage.
pub fn bench(preset_name: &str, samples: u64, repeats: usize) -> Result<()> {
    let cfg =
        gyroemu_experiment::presets::preset(preset_name).map_err(|e| BadInput(e.to_string()))?;
    if repeats == 0 {
        return Err(BadInput("--repeats = 0: must be at least 1".into()).into());
    }
    if samples < 100 * cfg.board.decimation as u64 {
        return Err(BadInput(format!(
            "--samples = {samples}: must be at least 100 decimation blocks ({})",
            100 * cfg.board.decimation
        ))
        .into());
    }
    eprintln!(
        "bench: preset {preset_name}, fs = {} Hz, {samples} input samples per lane group, 4 operating points per group, best and median of {repeats} runs",
        cfg.board.fs_hz
    );
    // A closed pipe (`| head`) ends the output quietly.
    print_out(&format!(
        "{:<48} {:>7} {:>10} {:>10}\n",
        "what (M point-samples/s)", "threads", "best", "median"
    ))?;
    for t in gyroemu_experiment::bench::all(&cfg, samples, repeats) {
        print_out(&format!(
            "{:<48} {:>7} {:>10.1} {:>10.1}\n",
            t.name,
            t.threads,
            t.point_samples_per_s / 1e6,
            t.median_point_samples_per_s / 1e6
        ))?;
    }
    Ok(())
}
