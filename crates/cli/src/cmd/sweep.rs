//! `gyroemu sweep CONFIG --out DIR`.

use crate::input::{command_line, list_written, read_config, refused, BadInput};
use crate::progress::Terminal;
use crate::signals;
use anyhow::Result;
use gyroemu_analysis::{run_frequency_response, stepped_sine_work};
use gyroemu_report::{check_problems, write_freq_sweep};
use gyroemu_runs::{lock_out, prepare_out, LockScope};
use std::path::Path;

/// The stepped-sine frequency response of each mode through the board, its resonance fits
/// and their check against the configured device.
pub fn sweep_command(config: &Path, out: &Path, force: bool) -> Result<()> {
    let (cfg, text) = read_config(config)?;
    let warnings = cfg
        .validate_sweep()
        .map_err(|e| refused(config, &text, e))?;
    for w in warnings {
        note!("warning: {}: {w}", config.display());
    }
    let work = stepped_sine_work(&cfg);
    work.check_cap_with(
        force,
        "lower sweep.points, sweep.settle_s or sweep.average_s (the default settling is 16 mechanical time constants Q/(pi f0) per frequency)",
    )
    .map_err(BadInput)?;
    note!(
        "{} (each mode driven alone at {} frequencies)",
        work.describe(None),
        work.points / 2
    );
    signals::install(false);
    prepare_out(out)?;
    let _lock = lock_out(out, &command_line(), LockScope::Folder, &Terminal)?;
    let r = run_frequency_response(&cfg, &Terminal)?;
    let files = write_freq_sweep(out, &cfg, &r)?;
    for w in &r.measured.warnings {
        note!("warning: {w}");
    }
    let (split, split_sigma) = r.mode_split_hz();
    let part = |k: usize| {
        let m = &r.modes[k];
        match m.fit {
            Some(f) => format!(
                "mode {}: f0 {:.6} Hz (configured {}, {:+.3e}), Q {:.2} (configured {}, {:+.3e})",
                k + 1,
                f.f0_hz,
                m.configured_f0_hz,
                m.f0_error_hz(),
                f.q,
                m.configured_q,
                m.q_rel_error()
            ),
            None => format!("mode {}: no resonance found", k + 1),
        }
    };
    say!(
        "sweep: {}; {}; split {:.6} +- {:.1e} Hz (configured {}, the coupled plant's {:.6})",
        part(0),
        part(1),
        split,
        split_sigma,
        r.modes[1].configured_f0_hz - r.modes[0].configured_f0_hz,
        r.modes[1].coupled_f0_hz - r.modes[0].coupled_f0_hz
    );
    list_written(out, &files);
    check_problems("sweep", &r.measured.problems)?;
    Ok(())
}
