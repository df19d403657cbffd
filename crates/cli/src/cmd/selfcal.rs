//! `gyroemu selfcal CONFIG --out DIR`.

use crate::input::{command_line, list_written, read_config, refused, BadInput};
use crate::progress::Terminal;
use crate::signals;
use anyhow::Result;
use gyroemu_analysis::selfcal::validate_selfcal;
use gyroemu_analysis::{run_selfcal, selfcal_work};
use gyroemu_experiment::work::{measured_lock_rate, measured_throughput};
use gyroemu_report::{check_problems, write_selfcal};
use gyroemu_runs::{lock_out, prepare_out, LockScope};
use std::path::Path;

/// The scale factor from the rotating excitation alone, checked against the virtual rate
/// table on the same board, plus the analyses the config asks for.
pub fn selfcal_command(config: &Path, out: &Path, force: bool) -> Result<()> {
    let (cfg, text) = read_config(config)?;
    // The config's own rules, as selfcal reads it, and its derived runs' in one refusal.
    let warnings = validate_selfcal(&cfg).map_err(|e| refused(config, &text, e))?;
    for w in &warnings {
        note!("warning: {}: {w}", config.display());
    }
    let work = selfcal_work(&cfg);
    work.check_cap(force).map_err(BadInput)?;
    note!(
        "{}",
        work.describe_at(Some(measured_throughput(&cfg)), measured_lock_rate(&cfg))
    );
    signals::install(false);
    prepare_out(out)?;
    let _lock = lock_out(out, &command_line(), LockScope::Folder, &Terminal)?;
    let report = run_selfcal(&cfg, &Terminal)?;
    // With a [pll], the files name the carrier the sweeps ran at, as `run`'s do.
    let ran = report
        .lock
        .as_ref()
        .map_or_else(|| cfg.clone(), |l| l.hold(&cfg));
    let files = write_selfcal(out, &ran, &cfg, &report)?;
    if !files.removed.is_empty() {
        let names: Vec<String> = files
            .removed
            .iter()
            .map(|p| p.strip_prefix(out).unwrap_or(p).display().to_string())
            .collect();
        note!(
            "deleted {} files of an earlier selfcal whose analyses this config does not run: {}",
            names.len(),
            names.join(", ")
        );
    }
    for w in report.warnings() {
        note!("warning: {w}");
    }
    let m = report.core.modes[0];
    say!(
        "self-calibration (mode 1): rotating slope {} deg per deg/s x lambda {} = predicted Coriolis {}; \
         rate table measured {}; relative error {:+.3e} +- {:.2e} (95 %), averaging {} s",
        slope(m.rotating.slope_deg_per_dps),
        report.core.angular_gain,
        slope(m.predicted_deg_per_dps),
        slope(m.coriolis.slope_deg_per_dps),
        m.relative_error,
        m.relative_error_ci95,
        cfg.experiment.average_s
    );
    let c = report.core.combined;
    say!(
        "self-calibration (both modes, geometric mean): predicted Coriolis {}; rate table measured {}; \
         relative error {:+.3e} +- {:.2e} (95 %), mode 2 alone {:+.3e}",
        slope(c.predicted_deg_per_dps),
        slope(c.coriolis.slope_deg_per_dps),
        c.relative_error,
        c.relative_error_ci95,
        report.core.modes[1].relative_error
    );
    list_written(out, &files.written);
    let problems: Vec<String> = [&report.core.rotating, &report.core.coriolis]
        .iter()
        .flat_map(|r| r.problems.iter().cloned())
        .collect();
    check_problems("selfcal", &problems)?;
    Ok(())
}

/// A slope in deg per deg/s as the headline prints it: nine decimals (the presets' 0.04 read
/// to seven figures), or nine figures in exponent form below 1e-3, where the decimals had
/// read a gain of 1e-9's slopes as 0.000000000.
fn slope(v: f64) -> String {
    if v != 0.0 && v.abs() < 1e-3 {
        format!("{v:.8e}")
    } else {
        format!("{v:.9}")
    }
}

#[cfg(test)]
mod tests {
    use super::slope;

    #[test]
    fn small_slopes_keep_their_figures() {
        assert_eq!(slope(0.0424384), "0.042438400");
        assert_eq!(slope(4.069e-11), "4.06900000e-11");
        assert_eq!(slope(0.0), "0.000000000");
        assert_eq!(slope(f64::NAN), "NaN");
    }
}
