//! `gyroemu config [--preset NAME] [--list]`.

use crate::input::{print_out, read_config_text, refused, BadInput};
use anyhow::Result;
use gyroemu_config::parse_config_explained;
use gyroemu_config::presets::{preset_text, PRESETS};
use std::path::Path;

/// `gyroemu config --resolved FILE`: the config with every key filled in, each derived value
/// listed with its rule, and the settling time used.
pub fn resolved_command(path: &Path) -> Result<()> {
    let text = read_config_text(path)?;
    let (cfg, derived) =
        parse_config_explained(&text).map_err(|e| BadInput(format!("{}: {e}", path.display())))?;
    let warnings = cfg.validate().map_err(|e| refused(path, &text, e))?;
    let mut out = format!(
        "# {} with every key filled in (gyroemu config --resolved).\n",
        path.display()
    );
    if derived.is_empty() {
        out.push_str("# Every key with a derived default was set in the file.\n");
    } else {
        out.push_str("# Derived from the device and the rates (docs/user-guide.md):\n");
        for d in &derived {
            out.push_str(&format!("#   {} = {}: {}\n", d.key, d.value, d.rule));
        }
    }
    if cfg.experiment.settle_s.is_none() {
        out.push_str(&format!(
            "# experiment.settle_s is not set: {} s are discarded (16 mechanical time constants Q/(pi f0) plus 40 of the low-pass, 1/(2 pi lpf_cutoff_hz), times sin(pi/8)/sin(pi/(2 lpf_order)) above order 4).\n",
            cfg.settle_s()
        ));
    }
    for w in warnings {
        out.push_str(&format!("# warning: {w}\n"));
    }
    out.push('\n');
    out.push_str(&toml::to_string(&cfg)?);
    print_out(&out)
}

/// Prints a preset's commented TOML, or the list of presets.
pub fn config_command(preset: Option<&str>, list: bool) -> Result<()> {
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
