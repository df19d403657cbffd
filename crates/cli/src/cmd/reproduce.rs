//! `gyroemu reproduce --out DIR [--quick]`.

use crate::input::{list_written, BadInput};
use crate::progress::Terminal;
use anyhow::Result;
use gyroemu_report::{plan_reproduce, reproduce, ReportError};
use gyroemu_runs::prepare_out;
use std::path::Path;

/// Reproduces the paper's figures from the embedded presets into `out`.
pub fn reproduce_command(out: &Path, quick: bool) -> Result<()> {
    // Every preset validated before the first sample.
    let plan = plan_reproduce(quick).map_err(|e| match e {
        ReportError::Config(c) => anyhow::Error::new(BadInput(c.to_string())),
        e => e.into(),
    })?;
    for w in &plan.warnings {
        eprintln!("warning: {w}");
    }
    let rate = gyroemu_experiment::work::measured_throughput(plan.first_config());
    eprintln!("{}", plan.work().describe(Some(rate)));
    prepare_out(out)?;
    let files = reproduce(&plan, out, &Terminal)?;
    list_written(out, &files);
    Ok(())
}
