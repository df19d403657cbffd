//! Parsing TOML into a [`Config`]: unknown keys, wrong types and missing keys are errors that
//! name the key, with the line and column where TOML parsing located it.

use crate::config::Config;
use crate::resolve::Derived;
use thiserror::Error;

/// A config the emulator refuses.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("config error: {}{}{}", .location.as_ref().map(|l| format!("{l}: ")).unwrap_or_default(), .key.as_ref().map(|k| format!("key `{k}`")).unwrap_or_default(), .detail)]
pub struct ConfigError {
    /// `line L, column C` where TOML parsing knows it.
    pub location: Option<String>,
    /// Dotted key path, e.g. `device.q`.
    pub key: Option<String>,
    /// What is wrong and the allowed range.
    pub detail: String,
}

impl ConfigError {
    /// An error about one key's value.
    pub fn key(key: &str, value: impl std::fmt::Display, rule: impl std::fmt::Display) -> Self {
        Self {
            location: None,
            key: Some(key.to_string()),
            detail: format!(" = {}: {rule}", readable(value.to_string())),
        }
    }
}

/// A number as the user would write it: very large or very small magnitudes in exponent
/// form (`1e300`, `-1e-9`) instead of hundreds of digits; anything else unchanged.
fn readable(value: String) -> String {
    match value.parse::<f64>() {
        Ok(x) if x.is_finite() && x != 0.0 && !(1e-5..1e16).contains(&x.abs()) => {
            format!("{x:e}")
        }
        _ => value,
    }
}

/// Parses TOML text into a config; unknown keys, wrong types and missing keys are errors.
/// Keys with derived defaults that the text leaves out are filled in ([`Config::resolve`]).
pub fn parse_config(text: &str) -> Result<Config, ConfigError> {
    parse_config_explained(text).map(|(c, _)| c)
}

/// [`parse_config`], also saying which keys were derived and how.
pub fn parse_config_explained(text: &str) -> Result<(Config, Vec<Derived>), ConfigError> {
    let mut cfg = parse_raw(text)?;
    let derived = cfg.resolve();
    Ok((cfg, derived))
}

/// The TOML text as written, nothing derived.
fn parse_raw(text: &str) -> Result<Config, ConfigError> {
    if text.trim().is_empty() {
        return Err(ConfigError {
            location: None,
            key: None,
            detail: "the config file is empty".into(),
        });
    }
    toml::from_str::<Config>(text).map_err(|e| {
        let message = e.message().trim().to_string();
        let Some(span) = e.span() else {
            return ConfigError {
                location: None,
                key: None,
                detail: message,
            };
        };
        let start = floor_char_boundary(text, span.start);
        let before = &text[..start];
        let line = before.matches('\n').count() + 1;
        let col = before[before.rfind('\n').map(|i| i + 1).unwrap_or(0)..]
            .chars()
            .count()
            + 1;
        ConfigError {
            location: Some(format!("line {line}, column {col}")),
            key: Some(key_at(text, start, &message)),
            detail: format!(": {message}"),
        }
    })
}

/// The largest char boundary at or below `i` (TOML spans are byte offsets).
fn floor_char_boundary(text: &str, i: usize) -> usize {
    let mut i = i.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// The dotted key a TOML error at byte `offset` is about: the table header above it plus the
/// key of its line (or of the nearest `key =` line above, for a multi-line value), or the
/// field a "missing field" / "unknown field" message names. Best effort: it only labels
/// the message, the line and column stay exact.
fn key_at(text: &str, offset: usize, message: &str) -> String {
    let mut table = String::new();
    let mut key = None;
    let mut on_header = false;
    let mut line_start = 0;
    for raw in text.split_inclusive('\n') {
        if line_start > offset {
            break;
        }
        let l = raw.split('#').next().unwrap_or("").trim();
        on_header = l.starts_with('[');
        if on_header {
            table = l.trim_matches(|c| c == '[' || c == ']').trim().to_string();
            key = None;
        } else if let Some((k, _)) = l.split_once('=') {
            let k = k.trim().trim_matches('"');
            if !k.is_empty() && !k.contains(char::is_whitespace) {
                key = Some(k.to_string());
            }
        }
        line_start += raw.len();
    }
    let named = ["missing field `", "unknown field `"]
        .iter()
        .find_map(|p| message.strip_prefix(p))
        .and_then(|rest| rest.split('`').next())
        .map(str::to_string);
    // A missing field's span is its table, so the key is the table's child.
    let leaf = named.or(key);
    // An unknown table is reported at its own header: the key is the table itself.
    if on_header && leaf.as_deref() == table.rsplit('.').next() {
        return table;
    }
    match (table.is_empty(), leaf) {
        (true, Some(k)) => k,
        (false, Some(k)) => format!("{table}.{k}"),
        (false, None) => table,
        (true, None) => "(top level)".into(),
    }
}
