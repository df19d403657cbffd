//! What the emulator says about a config it refuses: every problem of the file at once, each
//! naming the key, the value and the rule (and the line and column where the text shows it).

use std::fmt;

/// A config the emulator refuses: its first problem, and every further one in `more`.
///
/// A caller that handles one problem reads `location`, `key` and `detail` (the first problem);
/// [`ConfigError::problems`] lists them all. `Display` writes a single problem on one line and
/// several as a count followed by one indented line each.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigError {
    /// `line L, column C` where the text shows it.
    pub location: Option<String>,
    /// Dotted key path, e.g. `device.q` (a section: `drive`).
    pub key: Option<String>,
    /// What is wrong and the allowed range (after the key: `: rule` or ` = value: rule`).
    pub detail: String,
    /// The file's further problems, each with an empty `more`.
    pub more: Vec<ConfigError>,
}

impl std::error::Error for ConfigError {}

impl ConfigError {
    /// A problem with no key (an empty file, an unknown preset).
    pub fn message(detail: impl Into<String>) -> Self {
        Self {
            location: None,
            key: None,
            detail: detail.into(),
            more: Vec::new(),
        }
    }

    /// An error about one key's value (an integer is shown with all its digits, a float
    /// in exponent form when very large or small).
    pub fn key(key: &str, value: impl fmt::Display + 'static, rule: impl fmt::Display) -> Self {
        let shown = if is_integer(&value) {
            value.to_string()
        } else {
            readable(value.to_string())
        };
        Self {
            location: None,
            key: Some(key.to_string()),
            detail: format!(" = {shown}: {rule}"),
            more: Vec::new(),
        }
    }

    /// An error about a key, located in the text, with no value to show (`detail` starts
    /// with `: `) or with one (` = value: rule`).
    pub(crate) fn at(location: Option<String>, key: &str, detail: String) -> Self {
        Self {
            location,
            key: Some(key.to_string()),
            detail,
            more: Vec::new(),
        }
    }

    /// One error holding every problem of `list` (in that order), or `None` for none.
    pub fn from_problems(list: Vec<ConfigError>) -> Option<Self> {
        let mut all = list.into_iter().flat_map(|e| e.problems());
        let mut first = all.next()?;
        first.more = all.collect();
        Some(first)
    }

    /// Every problem, the first one first, each on its own (with an empty `more`).
    pub fn problems(&self) -> Vec<ConfigError> {
        let first = ConfigError {
            more: Vec::new(),
            ..self.clone()
        };
        std::iter::once(first).chain(self.more.clone()).collect()
    }

    /// The same problems with `f` applied to each one's `detail` (e.g. to say which derived
    /// config they come from).
    pub fn map_details(self, f: impl Fn(&str) -> String) -> Self {
        let list = self
            .problems()
            .into_iter()
            .map(|p| ConfigError {
                detail: f(&p.detail),
                ..p
            })
            .collect();
        Self::from_problems(list).unwrap_or(self)
    }

    /// One problem on one line: `line L, column C: key `k` = value: rule`.
    fn write_one(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(l) = &self.location {
            write!(f, "{l}: ")?;
        }
        if let Some(k) = &self.key {
            write!(f, "key `{k}`")?;
        }
        write!(f, "{}", self.detail)
    }
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "config error: ")?;
        if self.more.is_empty() {
            return self.write_one(f);
        }
        write!(f, "{} problems:", 1 + self.more.len())?;
        for p in std::iter::once(self).chain(&self.more) {
            write!(f, "\n  ")?;
            p.write_one(f)?;
        }
        Ok(())
    }
}

/// Whether `v` is of an integer type: its digits are the value as written (through f64,
/// 9223372036854775807 came out as 9.223372036854776e18).
fn is_integer(v: &dyn std::any::Any) -> bool {
    use std::any::TypeId;
    [
        TypeId::of::<u8>(),
        TypeId::of::<u16>(),
        TypeId::of::<u32>(),
        TypeId::of::<u64>(),
        TypeId::of::<u128>(),
        TypeId::of::<usize>(),
        TypeId::of::<i8>(),
        TypeId::of::<i16>(),
        TypeId::of::<i32>(),
        TypeId::of::<i64>(),
        TypeId::of::<i128>(),
        TypeId::of::<isize>(),
    ]
    .contains(&v.type_id())
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
