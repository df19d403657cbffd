//! `gyroemu config [--preset NAME] [--list]`.

use crate::input::{print_out, BadInput};
use anyhow::Result;
use gyroemu_config::presets::{preset_text, PRESETS};

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
