//! Merging the shards of a lot: the shared checks of [`crate::merge_split`], then one config text
//! across the shards (the spec too: it judges every device), the lot's size agreed, every
//! device's file read back bit for bit, and the lot's files written from them.

use crate::config_diff::{describe_diff, text_diff};
use crate::device_file::{lot_hash, DeviceFile};
use crate::error::RunError;
use crate::lot_run::check_unreliable;
use crate::merge_split::{bad, Split};
use gyroemu_analysis::montecarlo::LotSummary;
use gyroemu_config::parse_config;
use gyroemu_experiment::Reporter;
use gyroemu_report::write_lot;
use std::path::PathBuf;

/// Checks the lot's shards in `dir` and writes its files there; returns them and the lot's
/// figures.
pub(crate) fn merge_lot(
    dir: &std::path::Path,
    split: Split,
    reporter: &dyn Reporter,
) -> Result<(Vec<PathBuf>, LotSummary), RunError> {
    let (first_name, first) = (&split.first_name, &split.first);
    let n = first.points_total;
    // A hand-edited manifest could claim any size; the items are listed from it below.
    crate::lot_run::check_lot_size(n)
        .map_err(|e| bad(format!("`{first_name}`: its manifest claims {e}")))?;
    for (name, m) in split.by_index.values() {
        if m.config_toml != first.config_toml {
            let d = text_diff(&first.config_toml, &m.config_toml).unwrap_or_default();
            return Err(bad(format!(
                "`{name}` ran the lot with other settings than `{first_name}` ({}): every \
                 shard must run the same config",
                describe_diff(&d, 12)
            )));
        }
        if m.points_total != n {
            return Err(bad(format!(
                "`{name}` ran a lot of {} devices, `{first_name}` one of {n}: every shard \
                 must be given the same --devices",
                m.points_total
            )));
        }
    }
    let cfg = parse_config(&first.config_toml)
        .map_err(|e| bad(format!("`{first_name}`: its config does not parse: {e}")))?;
    if lot_hash(&cfg) != split.hash {
        return Err(bad(format!(
            "`{first_name}`: its config text does not match its lot hash"
        )));
    }
    // The config's rules as the lot read them (selfcal's, its `[selfcal]` not run).
    let lot = gyroemu_config::Config {
        selfcal: None,
        ..cfg.clone()
    };
    let warnings = gyroemu_analysis::selfcal::validate_selfcal(&lot)
        .map_err(|e| bad(format!("{first_name}: {e}")))?;
    for w in warnings {
        reporter.warn(&format!("{first_name}: {w}"));
    }
    let records = split.records::<DeviceFile>(dir, n, true)?;
    let devices = records
        .values()
        .map(|(p, f)| {
            f.result().map_err(|e| {
                bad(format!(
                    "`{}` was written by another gyroemu version ({e}): rerun its shard",
                    p.display()
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    // Untrusted devices fail the merge after its files are written: the manifest says so too.
    let mut lot = None;
    let written = write_lot(dir, &cfg, &devices)
        .map_err(RunError::from)
        .and_then(|(files, summary)| {
            let check = check_unreliable(&dir.display().to_string(), &summary, &devices);
            let r = RunError::refused_unless(check, files).map_err(|e| e.with_lot(&summary));
            lot = Some(summary);
            r
        });
    let (mut files, path) = split.finish(dir, n, written)?;
    files.push(path);
    reporter.note(&format!("merged {} shards ({n} devices)", split.count));
    let lot = lot.expect("a lot whose files were written has its summary");
    Ok((files, lot))
}
