//! Checks a parsed TOML document against the [schema](crate::schema) and collects every
//! problem: unknown keys and sections, missing required ones, values of the wrong kind. Each
//! names the key, shows the value as written and gives the line and column.

use crate::error::ConfigError;
use crate::schema::{closest, one_of, Field, Kind, Section, SECTIONS};
use std::ops::Range;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// Every problem of `doc` (parsed from `text`), in the order of the text; a missing section,
/// which no line shows, comes last.
pub(crate) fn check_document(text: &str, doc: &DeTable) -> Vec<ConfigError> {
    let mut found = Found { text, list: vec![] };
    let names: Vec<&str> = SECTIONS.iter().map(|s| s.name).collect();
    for (key, value) in doc.iter() {
        match SECTIONS.iter().find(|s| s.name == key.get_ref().as_ref()) {
            Some(section) => found.section(section, value),
            None => {
                found.unknown(key, "", &names);
            }
        }
    }
    found.list.sort_by_key(|(at, _)| *at);
    for s in SECTIONS.iter().filter(|s| s.required) {
        if !doc.keys().any(|k| k.get_ref().as_ref() == s.name) {
            let keys: Vec<&str> = s
                .fields
                .iter()
                .filter(|f| f.required)
                .map(|f| f.name)
                .collect();
            found.list.push((
                usize::MAX,
                ConfigError::at(
                    None,
                    s.name,
                    format!(
                        " is missing: the config requires the section [{}] (with {})",
                        s.name,
                        keys.join(", ")
                    ),
                ),
            ));
        }
    }
    found.list.into_iter().map(|(_, e)| e).collect()
}

/// The problems found so far, each with the byte offset that orders them.
struct Found<'t> {
    text: &'t str,
    list: Vec<(usize, ConfigError)>,
}

impl Found<'_> {
    fn push(&mut self, at: usize, key: &str, detail: String) {
        let location = Some(location(self.text, at));
        self.list.push((at, ConfigError::at(location, key, detail)));
    }

    /// A key that `table` (`""` at the top level) does not take; returns the known key it
    /// suggests instead, if any.
    fn unknown<'k>(
        &mut self,
        key: &Spanned<std::borrow::Cow<'_, str>>,
        table: &str,
        known: &[&'k str],
    ) -> Option<&'k str> {
        let name = key.get_ref().as_ref();
        let path = if table.is_empty() {
            name.to_string()
        } else {
            format!("{table}.{name}")
        };
        let suggestion = closest(name, known);
        let hint = suggestion
            .map(|k| format!(" (did you mean `{k}`?)"))
            .unwrap_or_default();
        let detail = format!(": unknown key{hint}, expected {}", one_of(known, "`"));
        self.push(key.span().start, &path, detail);
        suggestion
    }

    fn section(&mut self, section: &Section, value: &Spanned<DeValue<'_>>) {
        let Some(table) = value.get_ref().as_table() else {
            let shown = shown(self.text, value.span());
            let detail = format!(
                " = {shown}: expected a table (a [{}] section)",
                section.name
            );
            self.push(value.span().start, section.name, detail);
            return;
        };
        let names: Vec<&str> = section.fields.iter().map(|f| f.name).collect();
        let mut suggested = vec![];
        for (key, v) in table.iter() {
            match section
                .fields
                .iter()
                .find(|f| f.name == key.get_ref().as_ref())
            {
                Some(field) => self.value(section.name, field, v),
                None => suggested.extend(self.unknown(key, section.name, &names)),
            }
        }
        // A required key that a misspelling's "did you mean" already names is not repeated.
        for f in section.fields.iter().filter(|f| f.required) {
            if !table.keys().any(|k| k.get_ref().as_ref() == f.name) && !suggested.contains(&f.name)
            {
                let detail = format!(" is missing: [{}] requires it", section.name);
                self.push(
                    value.span().start,
                    &format!("{}.{}", section.name, f.name),
                    detail,
                );
            }
        }
    }

    fn value(&mut self, section: &str, field: &Field, v: &Spanned<DeValue<'_>>) {
        let key = format!("{section}.{}", field.name);
        let list_of = |item: Kind| -> Option<Vec<(String, Range<usize>, String)>> {
            let items = v.get_ref().as_array()?;
            Some(
                items
                    .iter()
                    .enumerate()
                    .filter_map(|(i, x)| {
                        let rule = rule(item, x.get_ref())?;
                        Some((format!("{key}[{i}]"), x.span(), rule))
                    })
                    .collect(),
            )
        };
        let problems = match field.kind {
            Kind::Numbers => list_of(Kind::Number),
            Kind::Names => list_of(Kind::Text),
            _ => Some(vec![]),
        };
        let problems = match problems {
            Some(p) if !p.is_empty() => p,
            // A list whose items are fine, or a single value: judge it whole.
            _ => match rule(field.kind, v.get_ref()) {
                Some(r) => vec![(key, v.span(), r)],
                None => vec![],
            },
        };
        for (key, span, rule) in problems {
            let detail = format!(" = {}: {rule}", shown(self.text, span.clone()));
            self.push(span.start, &key, detail);
        }
    }
}

/// What is wrong with `v` as a value of `kind` (`None`: nothing). Accepts exactly what serde's `f64`, `u32`, `u64`, `usize`, `bool`, `Vec` and the
/// config's enums accept from TOML.
fn rule(kind: Kind, v: &DeValue<'_>) -> Option<String> {
    let int = v.as_integer().map(|i| (i.as_str(), i.radix()));
    match kind {
        Kind::Number => match (int, v.as_float()) {
            (Some((s, radix)), _) => {
                let fits =
                    i64::from_str_radix(s, radix).is_ok() || u64::from_str_radix(s, radix).is_ok();
                (!fits).then(|| {
                    "an integer this large is out of range (-9223372036854775808 to 18446744073709551615): write it with an exponent, e.g. 1e20".into()
                })
            }
            (_, Some(f)) => {
                let s = f.as_str();
                let ok = s
                    .parse::<f64>()
                    .is_ok_and(|x| !x.is_infinite() || s.contains("inf"));
                (!ok).then(|| "is too large: numbers must lie within about ±1.8e308".into())
            }
            _ => Some(expected("a number", v)),
        },
        Kind::Count { max, range } => {
            let what = match range {
                Some(r) => r.what(),
                None if max > u64::from(u32::MAX) => "a non-negative integer".to_string(),
                None => format!("an integer from 0 to {max}"),
            };
            match (int, v.as_float()) {
                (Some((s, radix)), _) => {
                    // Digits past i128 are a (positive) integer too large for any key.
                    let negative = s.starts_with('-');
                    let n = i128::from_str_radix(s, radix).ok();
                    let ok = n.is_some_and(|n| (0..=max as i128).contains(&n));
                    (!ok).then(|| match range {
                        _ if negative => format!("expected {what}"),
                        // The key's own range: the type's limit is no rule of it.
                        Some(r) => format!("too large: {}", r.rule()),
                        None => format!("too large: at most {max}"),
                    })
                }
                (_, Some(f)) => {
                    let whole = f
                        .as_str()
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite() && x.fract() == 0.0 && *x >= 0.0);
                    Some(match whole {
                        Some(x) => format!("expected {what} (write {x} without a decimal point)"),
                        None => format!("expected {what}"),
                    })
                }
                _ => Some(expected(&what, v)),
            }
        }
        Kind::Bool => (!v.is_bool()).then(|| expected("true or false", v)),
        Kind::Numbers => (!v.is_array()).then(|| expected("a list of numbers, in [ ]", v)),
        Kind::Names => (!v.is_array()).then(|| expected("a list of names, in [ ]", v)),
        Kind::Text => (!v.is_str()).then(|| expected("a name in quotes", v)),
        Kind::Choice(names) => match v.as_str() {
            Some(s) if names.contains(&s) => None,
            _ => Some(format!("expected {}", one_of(names, "\""))),
        },
    }
}

/// `expected WHAT`, with a hint when the value is the right thing in quotes.
fn expected(what: &str, v: &DeValue<'_>) -> String {
    let unquoted = v.as_str().map(|s| format!("x = {s}"));
    let quoted = unquoted.as_deref().is_some_and(|line| {
        DeTable::parse(line)
            .ok()
            .and_then(|t| t.get_ref().get("x").map(|x| !x.get_ref().is_str()))
            .unwrap_or(false)
    });
    if quoted {
        format!("expected {what} (remove the quotes)")
    } else {
        format!("expected {what}")
    }
}

/// `line L, column C` of byte `offset` (columns count characters).
pub(crate) fn location(text: &str, offset: usize) -> String {
    let mut i = offset.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    let before = &text[..i];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |j| j + 1);
    format!(
        "line {line}, column {}",
        before[start..].chars().count() + 1
    )
}

/// The value as written (shortened when long).
fn shown(text: &str, span: Range<usize>) -> String {
    let s = text.get(span).unwrap_or("").trim();
    if s.chars().count() > 60 {
        format!("{}...", s.chars().take(57).collect::<String>())
    } else {
        s.to_string()
    }
}

impl ConfigError {
    /// The same problems in the order of `text`, each one about a key that `text` sets given
    /// the line and column of its value (validation works on the parsed config, which no
    /// longer knows them). Keys the text leaves to their defaults stay unlocated, and last.
    pub fn with_locations(self, text: &str) -> Self {
        let Ok(doc) = DeTable::parse(text) else {
            return self;
        };
        let mut list: Vec<(Option<usize>, ConfigError)> = self
            .problems()
            .into_iter()
            .map(|p| {
                let at = match (&p.location, &p.key) {
                    (None, Some(key)) => offset_of(doc.get_ref(), key),
                    _ => None,
                };
                let location = at.map(|at| location(text, at)).or(p.location.clone());
                (at, ConfigError { location, ..p })
            })
            .collect();
        // In the order of the text (the ones it does not show last).
        list.sort_by_key(|(at, _)| at.unwrap_or(usize::MAX));
        Self::from_problems(list.into_iter().map(|(_, e)| e).collect()).unwrap_or(self)
    }
}

/// Where the value of dotted `key` (`section`, `section.key` or `section.key[i]`) starts.
fn offset_of(doc: &DeTable<'_>, key: &str) -> Option<usize> {
    let (path, index) = match key.split_once('[') {
        Some((p, i)) => (p, i.trim_end_matches(']').parse::<usize>().ok()),
        None => (key, None),
    };
    let mut parts = path.split('.');
    let section = doc.get(parts.next()?)?;
    let Some(name) = parts.next() else {
        return Some(section.span().start);
    };
    let value = section.get_ref().as_table()?.get(name)?;
    match index {
        Some(i) => value.get_ref().as_array()?.get(i).map(|x| x.span().start),
        None => Some(value.span().start),
    }
}

#[cfg(test)]
mod tests {
    //! The schema against serde, the independent truth: the keys serde's structs list, the
    //! ones they require, and the values they accept.
    use super::*;
    use crate::config::Config;

    /// A value of `kind` that serde accepts (it need not validate).
    fn valid(kind: Kind) -> String {
        match kind {
            Kind::Number => "1.5".into(),
            Kind::Count { .. } => "4".into(),
            Kind::Bool => "true".into(),
            Kind::Numbers => "[25.0, 50]".into(),
            Kind::Names => "[\"tia\"]".into(),
            Kind::Text => "\"tia\"".into(),
            Kind::Choice(names) => format!("\"{}\"", names[0]),
        }
    }

    /// A config setting every key of the schema, but for `skip` (a section, or a section's
    /// key), plus `extra` (section, key, value; section "" for the top level).
    fn text(skip: (&str, &str), extra: Option<(&str, &str, &str)>) -> String {
        let mut t = String::new();
        if let Some(("", k, v)) = extra {
            t += &format!("{k} = {v}\n");
        }
        for s in SECTIONS.iter().filter(|s| skip != (s.name, "")) {
            t += &format!("[{}]\n", s.name);
            for f in s.fields.iter().filter(|f| skip != (s.name, f.name)) {
                let v = match extra {
                    Some((sec, k, v)) if sec == s.name && k == f.name => v.to_string(),
                    _ => valid(f.kind),
                };
                t += &format!("{} = {v}\n", f.name);
            }
            match extra {
                Some((sec, k, v)) if sec == s.name && !s.fields.iter().any(|f| f.name == k) => {
                    t += &format!("{k} = {v}\n")
                }
                _ => {}
            }
        }
        t
    }

    fn serde_ok(text: &str) -> bool {
        toml::from_str::<Config>(text).is_ok()
    }

    fn schema_ok(text: &str) -> bool {
        let doc = DeTable::parse(text).unwrap();
        check_document(text, doc.get_ref()).is_empty()
    }

    /// The names serde lists after "expected" in its unknown-field message.
    fn serde_names(text: &str) -> Vec<String> {
        let e = toml::from_str::<Config>(text).unwrap_err();
        let msg = e.message();
        let list = &msg[msg.find("expected").unwrap()..];
        list.split('`')
            .skip(1)
            .step_by(2)
            .map(String::from)
            .collect()
    }

    #[test]
    fn the_schema_names_the_keys_serde_takes() {
        let top: Vec<&str> = SECTIONS.iter().map(|s| s.name).collect();
        assert_eq!(serde_names(&text(("", ""), Some(("", "zz", "1")))), top);
        for s in SECTIONS {
            let names: Vec<&str> = s.fields.iter().map(|f| f.name).collect();
            let t = text(("", ""), Some((s.name, "zz", "1")));
            assert_eq!(serde_names(&t), names, "[{}]", s.name);
            assert!(!schema_ok(&t));
        }
    }

    #[test]
    fn the_schema_requires_what_serde_requires() {
        let all = text(("", ""), None);
        assert!(serde_ok(&all) && schema_ok(&all), "{all}");
        for s in SECTIONS {
            let t = text((s.name, ""), None);
            assert_eq!(serde_ok(&t), !s.required, "[{}]", s.name);
            assert_eq!(schema_ok(&t), !s.required, "[{}]", s.name);
            for f in s.fields {
                let t = text((s.name, f.name), None);
                assert_eq!(serde_ok(&t), !f.required, "{}.{}", s.name, f.name);
                assert_eq!(schema_ok(&t), !f.required, "{}.{}", s.name, f.name);
            }
        }
    }

    #[test]
    fn the_schema_accepts_exactly_the_values_serde_accepts() {
        let probes = [
            "0",
            "-0",
            "4",
            "-1",
            "0x10",
            "4294967295",
            "4294967296",
            "9223372036854775807",
            "-9223372036854775808",
            "18446744073709551615",
            "18446744073709551616",
            "-99999999999999999999",
            "1.5",
            "16.0",
            "-2.0",
            "1_000.5",
            "1e-400",
            "1e400",
            "-1e400",
            "nan",
            "-nan",
            "inf",
            "+inf",
            "true",
            "\"1.0\"",
            "\"tia\"",
            "\"coriolis\"",
            "\"rotating\"",
            "\"Coriolis\"",
            "\"boxcar\"",
            "\"hann\"",
            "\"constant\"",
            "\"sinusoid\"",
            "\"normal\"",
            "\"uniform\"",
            "[]",
            "[1, 2.5]",
            "[1, \"x\"]",
            "[1e400]",
            "[\"tia\", \"stage2\"]",
            "[\"tia\", 1]",
            "[[1.0]]",
            "{ a = 1 }",
            "1979-05-27",
        ];
        let mut n = 0;
        for s in SECTIONS {
            for f in s.fields {
                for p in probes {
                    let t = text(("", ""), Some((s.name, f.name, p)));
                    assert_eq!(
                        schema_ok(&t),
                        serde_ok(&t),
                        "{}.{} = {p}: {:?}",
                        s.name,
                        f.name,
                        toml::from_str::<Config>(&t).err()
                    );
                    n += 1;
                }
            }
            // A section that is not a table.
            let t = text((s.name, ""), Some(("", s.name, "1")));
            assert!(!schema_ok(&t) && !serde_ok(&t));
        }
        assert!(n > 1000);
    }
}
