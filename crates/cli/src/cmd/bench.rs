//! `gyroemu bench [--preset NAME] [--samples N] [--repeats R]`.

use crate::input::{print_out, BadInput};
use anyhow::Result;

/// Prints point-samples per second for the chain and each stage.
pub fn bench_command(preset_name: &str, samples: u64, repeats: usize) -> Result<()> {
    let cfg = gyroemu_config::presets::preset(preset_name).map_err(|e| BadInput(e.to_string()))?;
    if repeats == 0 {
        return Err(BadInput("--repeats = 0: must be at least 1".into()).into());
    }
    if samples < 100 * cfg.decimation() as u64 {
        return Err(BadInput(format!(
            "--samples = {samples}: must be at least 100 decimation blocks ({})",
            100 * cfg.decimation()
        ))
        .into());
    }
    let lanes = gyroemu_board::max_lanes();
    let lane_type = gyroemu_experiment::bench::lane_type;
    let typed = if lanes == 8 {
        "rows marked (f64x4) and (f64x8): groups of 4 and 8"
    } else {
        "rows marked (f64x4): the same"
    };
    eprintln!(
        "bench: preset {preset_name}, fs = {} Hz, {samples} input samples per lane group, best and median of {repeats} runs; \
         whole chain: {lanes} operating points per group in {} lanes (what a run uses on this CPU), {typed}; stages: 4 lanes",
        cfg.fs_hz(),
        lane_type(lanes)
    );
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
