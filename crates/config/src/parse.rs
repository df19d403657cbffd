//! Parsing TOML into a [`Config`]: syntax errors, unknown keys, wrong types and missing keys
//! are all reported at once, each naming the key with the line and column where the text
//! shows it.

use crate::config::Config;
use crate::document::{check_document, location};
use crate::error::ConfigError;
use crate::resolve::Derived;
use serde::Deserialize;
use toml::de::DeTable;

/// Parses TOML text into a config; unknown keys, wrong types and missing keys are errors (all
/// of the file's, in one [`ConfigError`]). Keys with derived defaults that the text leaves
/// out are filled in ([`Config::resolve`]).
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
        return Err(ConfigError::message("the config file is empty"));
    }
    // A syntax error can make the keys after it look missing or mistyped: report only the
    // syntax errors then.
    let (doc, syntax) = DeTable::parse_recoverable(text);
    if let Some(e) =
        ConfigError::from_problems(syntax.iter().map(|e| toml_error(text, e)).collect())
    {
        return Err(e);
    }
    if let Some(e) = ConfigError::from_problems(check_document(text, doc.get_ref())) {
        return Err(e);
    }
    // The schema accepts what serde does (tested), so this fails only if they drift apart.
    Config::deserialize(toml::de::Deserializer::from(doc)).map_err(|e| toml_error(text, &e))
}

/// A TOML error as a located problem in the user's words.
fn toml_error(text: &str, e: &toml::de::Error) -> ConfigError {
    let detail = format!(": {}", plain_words(e.message().trim()));
    match e.span() {
        Some(span) => ConfigError {
            location: Some(location(text, span.start)),
            key: Some(key_at(text, span.start)),
            ..ConfigError::message(detail)
        },
        None => ConfigError::message(detail),
    }
}

/// A serde or TOML message with its Rust type names (`expected usize`, `as i128`) put in the
/// user's words.
pub fn plain_words(message: &str) -> String {
    const WORDS: [(&str, &str); 20] = [
        (" as i128", ""),
        (" as u128", ""),
        ("expected usize", "expected a non-negative integer"),
        ("expected u64", "expected a non-negative integer"),
        ("expected u32", "expected an integer from 0 to 4294967295"),
        ("expected u16", "expected an integer from 0 to 65535"),
        ("expected u8", "expected an integer from 0 to 255"),
        ("expected i128", "expected an integer"),
        ("expected i64", "expected an integer"),
        ("expected i32", "expected an integer"),
        ("expected isize", "expected an integer"),
        ("expected f64", "expected a number"),
        ("expected f32", "expected a number"),
        ("expected a boolean", "expected true or false"),
        ("expected a sequence", "expected a list"),
        ("expected a map", "expected a table"),
        ("floating point `", "number `"),
        ("boolean `", "`"),
        ("invalid type: sequence", "invalid type: list"),
        ("invalid type: map", "invalid type: table"),
    ];
    WORDS
        .iter()
        .fold(message.to_string(), |m, (from, to)| m.replace(from, to))
}

/// The dotted key a TOML syntax error at byte `offset` is about: the table header above it
/// plus the key of its line (or of the nearest `key =` line above, for a multi-line value).
/// Best effort: it only labels the message, the line and column stay exact.
fn key_at(text: &str, offset: usize) -> String {
    let mut table = String::new();
    let mut key = None;
    let mut line_start = 0;
    for raw in text.split_inclusive('\n') {
        if line_start > offset {
            break;
        }
        let l = raw.split('#').next().unwrap_or("").trim();
        if l.starts_with('[') {
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
    match (table.is_empty(), key) {
        (true, Some(k)) => k,
        (false, Some(k)) => format!("{table}.{k}"),
        (false, None) => table,
        (true, None) => "(top level)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Deserialize)]
    #[allow(dead_code)]
    struct Every {
        a: usize,
        b: u64,
        c: u32,
        d: u8,
        e: i64,
        f: f64,
        g: bool,
        h: Vec<f64>,
    }

    #[test]
    fn serde_messages_lose_their_rust_type_names() {
        let ok = [
            "a = 1", "b = 1", "c = 1", "d = 1", "e = 1", "f = 1.0", "g = true", "h = []",
        ];
        let bad = [
            "-1",
            "1.5",
            "\"x\"",
            "99999999999999999999",
            "4294967296",
            "[1]",
            "true",
        ];
        let mut seen = 0;
        for i in 0..ok.len() {
            for v in bad {
                let mut lines = ok.to_vec();
                let line = format!("{} = {v}", &ok[i][..1]);
                lines[i] = &line;
                let Err(e) = toml::from_str::<Every>(&lines.join("\n")) else {
                    continue;
                };
                let raw = e.message().to_string();
                let words = plain_words(&raw);
                for t in [
                    "usize", "u64", "u32", "u8", "i64", "i128", "f64", "boolean", "sequence",
                ] {
                    assert!(
                        !words
                            .split(|c: char| !c.is_ascii_alphanumeric())
                            .any(|w| w == t),
                        "{raw} -> {words}"
                    );
                }
                seen += 1;
            }
        }
        assert!(seen >= 40, "{seen}");
    }
}
