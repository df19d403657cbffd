//! Complete, commented configs embedded in the binary: `gyroemu config --preset NAME` prints
//! one, and `gyroemu reproduce` runs them.

use crate::config::Config;
use crate::error::ConfigError;
use crate::parse::parse_config;

/// (name, what it reproduces, TOML text).
pub const PRESETS: [(&str, &str, &str); 9] = [
    (
        "m2tfg-coriolis",
        "Fig. 8: Coriolis run on an M^2-TFG-like gyroscope (default)",
        include_str!("../presets/m2tfg-coriolis.toml"),
    ),
    (
        "m2tfg-rotating",
        "Fig. 9: rotating excitation, 500 s averaging",
        include_str!("../presets/m2tfg-rotating.toml"),
    ),
    (
        "baw-coriolis",
        "Fig. 4: Coriolis run on a BAW disk (n = 3, lambda = 0.6)",
        include_str!("../presets/baw-coriolis.toml"),
    ),
    (
        "baw-rotating",
        "Fig. 5: rotating excitation on the BAW disk",
        include_str!("../presets/baw-rotating.toml"),
    ),
    (
        "m2tfg-ratetable",
        "Mechanical bandwidth: sinusoidal rate table at Q = 36 000",
        include_str!("../presets/m2tfg-ratetable.toml"),
    ),
    (
        "m2tfg-selfcal",
        "`gyroemu selfcal` example: imperfect, noisy device, Allan deviation, drift",
        include_str!("../presets/m2tfg-selfcal.toml"),
    ),
    (
        "m2tfg-pll",
        "Carrier PLL: a drive started 10 Hz off the resonance, locked before the sweep",
        include_str!("../presets/m2tfg-pll.toml"),
    ),
    (
        "m2tfg-sweep",
        "`gyroemu sweep` example: stepped-sine response, 0.5 Hz mode split, Q mismatch, quadrature coupling",
        include_str!("../presets/m2tfg-sweep.toml"),
    ),
    (
        "m2tfg-montecarlo",
        "`gyroemu montecarlo` example: a lot drawn from tolerances, yield within 2 %",
        include_str!("../presets/m2tfg-montecarlo.toml"),
    ),
];

/// The TOML text of a preset.
pub fn preset_text(name: &str) -> Option<&'static str> {
    PRESETS.iter().find(|p| p.0 == name).map(|p| p.2)
}

/// A preset parsed into a config.
pub fn preset(name: &str) -> Result<Config, ConfigError> {
    let text = preset_text(name).ok_or_else(|| {
        ConfigError::message(format!(
            "unknown preset `{name}`; presets: {}",
            PRESETS.iter().map(|p| p.0).collect::<Vec<_>>().join(", ")
        ))
    })?;
    parse_config(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_parses_and_validates() {
        for (name, _, _) in PRESETS {
            let c = preset(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            c.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
            // At least 16 samples per carrier period on the embedded defaults.
            assert!(c.fs_hz() >= 16.0 * c.device.f0_hz, "{name}");
        }
    }
}
