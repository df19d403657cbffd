//! `gyroemu bench [--preset NAME] [--samples N] [--repeats R]`.

use crate::input::{print_out, BadInput};
use anyhow::Result;

/// The most measurements of each figure `--repeats` asks for (each is kept for the median).
const MAX_REPEATS: usize = 1000;
/// The most input samples per lane group `--samples` asks for: 2^40, hours per measurement.
const MAX_SAMPLES: u64 = 1 << 40;

/// Prints point-samples per second for the chain and each stage.
pub fn bench_command(preset_name: &str, samples: u64, repeats: usize) -> Result<()> {
    let cfg = gyroemu_config::presets::preset(preset_name).map_err(|e| BadInput(e.to_string()))?;
    if !(1..=MAX_REPEATS).contains(&repeats) {
        return Err(BadInput(format!(
            "--repeats = {repeats}: must be from 1 to {MAX_REPEATS}"
        ))
        .into());
    }
    let min = 100 * cfg.decimation() as u64;
    if !(min..=MAX_SAMPLES).contains(&samples) {
        return Err(BadInput(format!(
            "--samples = {samples}: must be at least 100 decimation blocks ({min}) and at \
             most 2^40 (hours per measurement)"
        ))
        .into());
    }
    use gyroemu_experiment::bench::{chains, lane_type};
    let typed = if gyroemu_board::max_lanes() == 8 {
        "rows marked (f64x4) and (f64x8): groups of 4 and 8"
    } else {
        "rows marked (f64x4): the same"
    };
    // Each chain in the lanes a run of it uses on this CPU (they differ by chain where the
    // CPU runs 512-bit operations in halves).
    let widths: Vec<String> = chains(&cfg)
        .iter()
        .map(|(_, c)| {
            let lanes = gyroemu_board::max_lanes_for(&c.board_params());
            format!("{lanes} points in {}", lane_type(lanes))
        })
        .collect();
    // The figures below belong to this CPU: they mean little without it.
    let cpu = gyroemu_board::CpuId::this_cpu()
        .map_or_else(|| "not an x86-64 CPU".to_string(), |c| c.describe());
    let threads = rayon::current_num_threads();
    let s = if threads == 1 { "" } else { "s" };
    note!(
        "cpu: {cpu}; {threads} thread{s}; {}",
        gyroemu_board::vector_paths()
    );
    note!(
        "bench: preset {preset_name}, fs = {} Hz, {samples} input samples per lane group, best and median of {repeats} runs; \
         whole chain (the preset's / with noise / with noise and flicker): {} per group (what a run uses on this CPU), {typed}; the normal generator: the noisy chain's lanes; stages: 4 lanes",
        cfg.fs_hz(),
        widths.join(" / ")
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
