//! Which keys differ between the config that wrote an output folder and the one now run, so
//! a refusal can say what changed instead of two hashes.

use crate::device_file::lot_config;
use crate::manifest::RunKind;
use crate::points::result_config;
use gyroemu_config::{parse_config, Config};
use std::collections::BTreeMap;

/// The keys of the result part of a config ([`result_config`]) whose values differ between
/// the canonical TOML `old` (a manifest's `config_toml`) and `new`, in key order, as
/// `key: old -> new` (`(unset)` on the side that lacks the key).
pub fn config_diff(old: &str, new: &Config) -> Result<Vec<String>, String> {
    let mut old: toml::Table = toml::from_str(old).map_err(|e| e.to_string())?;
    for ignored in ["dump", "selfcal", "sweep", "montecarlo"] {
        old.remove(ignored);
    }
    let new = toml::Table::try_from(result_config(new)).map_err(|e| e.to_string())?;
    Ok(diff_tables(&old, &new))
}

/// [`config_diff`] for a folder of `kind`: a lot's identity is [`lot_config`], and `old`
/// must parse as a config of this version.
pub fn config_diff_for(kind: RunKind, old: &str, new: &Config) -> Result<Vec<String>, String> {
    match kind {
        RunKind::Run => config_diff(old, new),
        RunKind::Montecarlo => {
            let old = parse_config(old).map_err(|e| e.to_string())?;
            let table =
                |c: &Config| toml::Table::try_from(lot_config(c)).map_err(|e| e.to_string());
            Ok(diff_tables(&table(&old)?, &table(new)?))
        }
    }
}

/// The keys whose values differ between two canonical config texts, all of their keys
/// compared.
pub(crate) fn text_diff(old: &str, new: &str) -> Result<Vec<String>, String> {
    let table = |t: &str| toml::from_str::<toml::Table>(t).map_err(|e| e.to_string());
    Ok(diff_tables(&table(old)?, &table(new)?))
}

/// The keys whose values differ between two config tables, as `key: old -> new`.
fn diff_tables(old: &toml::Table, new: &toml::Table) -> Vec<String> {
    let (mut a, mut b) = (BTreeMap::new(), BTreeMap::new());
    flatten("", old, &mut a);
    flatten("", new, &mut b);
    let show = |v: Option<&toml::Value>| v.map_or("(unset)".to_string(), render);
    let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
    keys.into_iter()
        .filter(|k| a.get(*k) != b.get(*k))
        .map(|k| format!("{k}: {} -> {}", show(a.get(k)), show(b.get(k))))
        .collect()
}

/// A value as a user writes it (floats in Rust's shortest round-trip form, e.g. `1e-13`).
fn render(v: &toml::Value) -> String {
    match v {
        toml::Value::Float(f) => format!("{f:?}"),
        toml::Value::Array(a) => {
            format!("[{}]", a.iter().map(render).collect::<Vec<_>>().join(", "))
        }
        v => v.to_string(),
    }
}

fn flatten(prefix: &str, t: &toml::Table, out: &mut BTreeMap<String, toml::Value>) {
    for (k, v) in t {
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(sub) => flatten(&key, sub, out),
            v => {
                out.insert(key, v.clone());
            }
        }
    }
}

/// The differences as one clause for a message (at most `max` keys listed).
pub(crate) fn describe_diff(diff: &[String], max: usize) -> String {
    let mut s = diff
        .iter()
        .take(max)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if diff.len() > max {
        s.push_str(&format!(" and {} more", diff.len() - max));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::canonical_toml;

    #[test]
    fn lists_changed_added_and_removed_keys_but_not_the_dump() {
        let mut base = gyroemu_config::presets::preset("m2tfg-coriolis").unwrap();
        base.device.q = 2000.0;
        base.experiment.rates_dps = vec![25.0, 50.0, 75.0];
        base.noise = Some(gyroemu_config::NoiseConfig {
            seed: 7,
            temperature_k: 300.0,
            effective_mass_kg: None,
            tia_current_noise_a_per_rthz: 1e-13,
            tia_voltage_noise_v_per_rthz: 0.0,
            ..Default::default()
        });
        let old = canonical_toml(&base);
        assert_eq!(config_diff(&old, &base).unwrap(), Vec::<String>::new());
        let mut new = base.clone();
        new.device.q = 2100.0;
        new.experiment.rates_dps = vec![25.0, 50.0];
        new.noise = None;
        new.dump = Some(gyroemu_config::DumpConfig {
            rate_dps: None,
            start_s: None,
            duration_s: None,
            nodes: None,
        });
        let d = config_diff(&old, &new).unwrap();
        assert_eq!(
            d,
            [
                "device.q: 2000.0 -> 2100.0",
                "experiment.rates_dps: [25.0, 50.0, 75.0] -> [25.0, 50.0]",
                "noise.seed: 7 -> (unset)",
                "noise.temperature_k: 300.0 -> (unset)",
                "noise.tia_current_noise_a_per_rthz: 1e-13 -> (unset)",
                "noise.tia_voltage_noise_v_per_rthz: 0.0 -> (unset)",
            ]
        );
        assert_eq!(
            describe_diff(&d, 2),
            format!("{}, {} and 4 more", d[0], d[1])
        );
    }
}
