//! The collector validation writes its rules into: every broken rule is kept (not just the
//! first), and a rule whose inputs already broke one is skipped, so one bad value does not
//! bring a cascade of follow-on errors.

use crate::error::ConfigError;
use std::fmt::Display;

/// The problems found so far, and which keys they are about.
#[derive(Default)]
pub(crate) struct Rules {
    list: Vec<ConfigError>,
    /// (derived key, key it was derived from): a derived key is as bad as its source.
    links: Vec<(&'static str, &'static str)>,
}

/// `experiment.rates_dps` for `experiment.rates_dps[3]`.
fn base(key: &str) -> &str {
    key.split('[').next().unwrap_or(key)
}

impl Rules {
    /// Declares that `key` holds a value derived from `source` (not written by the user): its
    /// rules are skipped once `source` broke one.
    pub fn derived_from(&mut self, key: &'static str, source: &'static str) {
        self.links.push((key, source));
    }

    /// What a broken rule on `key` adds when its value is a derived default: parsing fills
    /// such keys in, so the user may never have written the value the message quotes.
    fn default_note(&self, key: &str) -> String {
        let sources: Vec<&str> = self
            .links
            .iter()
            .filter(|&&(d, _)| d == key)
            .map(|&(_, s)| s)
            .collect();
        if sources.is_empty() {
            return String::new();
        }
        format!(
            " (this is the default derived from {}: set {key}, or change those)",
            sources.join(", ")
        )
    }

    /// Whether `key` itself (exactly) has a problem.
    fn failed(&self, key: &str) -> bool {
        self.list.iter().any(|e| e.key.as_deref() == Some(key))
    }

    /// Whether `key` (any element of it) has a problem, or was derived from one that has.
    fn bad(&self, key: &str) -> bool {
        let key = base(key);
        self.list
            .iter()
            .any(|e| e.key.as_deref().map(base) == Some(key))
            || self
                .links
                .iter()
                .any(|&(derived, source)| derived == key && self.bad(source))
    }

    /// Whether every key of `keys` is free of problems (their values can feed another rule).
    pub fn clean(&self, keys: &[&str]) -> bool {
        !keys.iter().any(|k| self.bad(k))
    }

    /// Whether no key of `[section]` has a problem.
    pub fn section_clean(&self, section: &str) -> bool {
        let prefix = format!("{section}.");
        !self
            .list
            .iter()
            .any(|e| e.key.as_ref().is_some_and(|k| k.starts_with(&prefix)))
    }

    /// Whether nothing was found yet.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Keeps a problem found elsewhere (unless its key already has one).
    pub fn push(&mut self, e: ConfigError) {
        if !e.key.as_deref().is_some_and(|k| self.failed(k)) {
            self.list.push(e);
        }
    }

    /// The rule `ok` about `key = value`; returns `ok`. A key with a problem already, or
    /// derived from a bad one, is not judged again (returns `false`).
    pub fn check(
        &mut self,
        ok: bool,
        key: &str,
        value: impl Display + 'static,
        rule: impl Display,
    ) -> bool {
        if self.failed(key) || self.links.iter().any(|&(d, s)| d == key && self.bad(s)) {
            return false;
        }
        if !ok {
            let rule = format!("{rule}{}", self.default_note(key));
            self.list.push(ConfigError::key(key, value, rule));
        }
        ok
    }

    pub fn positive(&mut self, key: &str, v: f64) -> bool {
        self.check(
            v.is_finite() && v > 0.0,
            key,
            v,
            "must be a finite number > 0",
        )
    }

    pub fn finite(&mut self, key: &str, v: f64) -> bool {
        self.check(v.is_finite(), key, v, "must be a finite number")
    }

    pub fn non_negative(&mut self, key: &str, v: f64) -> bool {
        self.check(
            v.is_finite() && v >= 0.0,
            key,
            v,
            "must be a finite number >= 0",
        )
    }

    /// Every problem found, as one error.
    pub fn finish(self) -> Result<(), ConfigError> {
        match ConfigError::from_problems(self.list) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rule_on_a_bad_or_derived_from_bad_key_is_skipped() {
        let mut r = Rules::default();
        r.derived_from("board.fs_hz", "device.f0_hz");
        assert!(!r.positive("device.f0_hz", 0.0));
        // Derived from the bad f0: skipped, no second problem.
        assert!(!r.positive("board.fs_hz", 0.0));
        // A second rule on the same key: skipped.
        assert!(!r.check(false, "device.f0_hz", 0.0, "another rule"));
        // Elements of a list are judged one by one, the list is bad as a whole.
        assert!(!r.finite("experiment.rates_dps[0]", f64::NAN));
        assert!(!r.finite("experiment.rates_dps[2]", f64::INFINITY));
        assert!(!r.clean(&["experiment.rates_dps"]));
        assert!(r.clean(&["device.q"]));
        assert!(!r.section_clean("device") && r.section_clean("board"));
        let e = r.finish().unwrap_err();
        let keys: Vec<_> = e.problems().into_iter().map(|p| p.key.unwrap()).collect();
        assert_eq!(
            keys,
            [
                "device.f0_hz",
                "experiment.rates_dps[0]",
                "experiment.rates_dps[2]"
            ]
        );
    }
}
