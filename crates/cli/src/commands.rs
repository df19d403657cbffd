//! `gyroemu run` and `gyroemu config`.

use crate::progress::Progress;
use crate::report::write_run;
use anyhow::{Context, Result};
use gyroemu_experiment::presets::{preset_text, PRESETS};
use gyroemu_experiment::{parse_config, run_sweep, Config};
use std::path::Path;

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

/// `gyroemu run CONFIG --out DIR`.
pub fn run(config: &Path, out: &Path) -> Result<()> {
    let cfg = load_config(config)?;
    prepare_out(out)?;
    let progress = Progress::new("run");
    let r =
        run_sweep(&cfg, &|d, t| progress.update(d, t), Some(out)).context("emulation failed")?;
    progress.finish(r.point_samples);
    let title = format!(
        "{:?} run, f0 = {} Hz, Q = {}",
        cfg.experiment.kind, cfg.device.f0_hz, cfg.device.q
    );
    write_run(out, &cfg, &r, &title)?;
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
pub fn bench(preset_name: &str, samples: u64) -> Result<()> {
    let cfg =
        gyroemu_experiment::presets::preset(preset_name).map_err(|e| BadInput(e.to_string()))?;
    if samples < 100 * cfg.board.decimation as u64 {
        return Err(BadInput(format!(
            "--samples = {samples}: must be at least 100 decimation blocks ({})",
            100 * cfg.board.decimation
        ))
        .into());
    }
    eprintln!(
        "bench: preset {preset_name}, fs = {} Hz, {samples} input samples per lane group, 4 operating points per group",
        cfg.board.fs_hz
    );
    println!(
        "{:<48} {:>7} {:>14}",
        "what", "threads", "M point-samples/s"
    );
    for t in gyroemu_experiment::bench::all(&cfg, samples) {
        println!(
            "{:<48} {:>7} {:>14.1}",
            t.name,
            t.threads,
            t.point_samples_per_s / 1e6
        );
    }
    Ok(())
}
