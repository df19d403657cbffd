//! `gyroemu montecarlo CONFIG --devices N [--out DIR] [--shard I/N] [--force]`, and
//! `--print-device I` (one device's config, for `gyroemu selfcal`).

use crate::cmd::out_args::OutArgs;
use crate::input::{
    list_written_with, listing_refused, print_out, read_config, refused, BadInput, ItemFiles,
    SavedCount,
};
use crate::lot_text::summary_text;
use crate::progress::Terminal;
use anyhow::Result;
use gyroemu_analysis::montecarlo::{
    device_config, draw_device, validate_lot, validate_lot_capped, LotRefusal,
};
use gyroemu_runs::device_file::DEVICES_DIR;
use gyroemu_runs::shard::Shard;
use gyroemu_runs::{check_lot, run_lot, LotOutcome, RunRequest};
use std::path::Path;

/// The arguments of `gyroemu montecarlo`.
pub struct MonteCarloArgs<'a> {
    /// The config file (with a `[montecarlo]` section).
    pub config: &'a Path,
    /// `--devices N`: the lot's size.
    pub devices: Option<usize>,
    /// `--out`, `--shard`, `--shard-count`, `--force`.
    pub out: &'a OutArgs,
    /// `--print-device I`: print device I's config instead of running the lot.
    pub print_device: Option<u64>,
}

/// Draws and self-calibrates the devices not yet saved in the output folder, then writes the
/// lot's files and prints its figures.
pub fn montecarlo_command(a: &MonteCarloArgs) -> Result<()> {
    let (cfg, text) = read_config(a.config)?;
    if let Some(i) = a.print_device {
        validate_lot(&cfg, &[i]).map_err(|e| refused(a.config, &text, e))?;
        let mc = cfg
            .montecarlo
            .as_ref()
            .expect("validated: [montecarlo] present");
        let dev = device_config(&cfg, &draw_device(mc, i));
        let head = format!(
            "# Device {i} of the lot of {} (gyroemu montecarlo --print-device {i}):\n\
             # `gyroemu selfcal` on this config self-calibrates it as the lot does.\n\n",
            a.config.display()
        );
        return print_out(&(head + &toml::to_string(&dev)?));
    }
    let n = a
        .devices
        .ok_or_else(|| BadInput("--devices N is required".into()))?;
    let shard = a.out.shard()?;
    // Size, shard count and split before the folder exists: a refusal leaves nothing.
    check_lot(&cfg, &a.out.out, shard.as_ref(), n)?;
    let mine: Vec<u64> = Shard::items(shard.as_ref(), n)
        .into_iter()
        .map(|i| i as u64)
        .collect();
    // The config, its sweeps and every device this process draws, and the cap on their work,
    // before any sample.
    let warnings = validate_lot_capped(&cfg, &mine, a.out.force).map_err(|r| match r {
        LotRefusal::Config(e) => refused(a.config, &text, e),
        LotRefusal::Cap(m) => BadInput(m),
    })?;
    for w in warnings {
        note!("warning: {}: {w}", a.config.display());
    }
    let (cancel, _lock) = a.out.open(shard.as_ref())?;
    let saved = SavedCount::default();
    let on_saved = |k: usize| saved.saved(k);
    let req = RunRequest {
        config: &cfg,
        out: &a.out.out,
        shard,
        force: a.out.force,
        cancel,
        on_saved: Some(&on_saved),
    };
    let devices = || ItemFiles {
        dir: DEVICES_DIR,
        item: "device",
        count: saved.get(),
    };
    let outcome = listing_refused(run_lot(&req, n, &Terminal), &a.out.out, Some(devices()))?;
    let files = match outcome {
        LotOutcome::Complete { files, summary } => {
            print_out(&summary_text(&summary))?;
            files
        }
        LotOutcome::ShardComplete { next, files } => {
            note!("shard complete; {next}");
            files
        }
    };
    list_written_with(&a.out.out, &files, Some(devices()));
    Ok(())
}
