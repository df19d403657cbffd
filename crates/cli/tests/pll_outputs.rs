//! `run` and `selfcal` with a `[pll]`: each says where the lock ended, its JSON names the
//! carrier its sweeps ran at (`selfcal.json` named the nominal start, 10 Hz from the run),
//! and keeps the config's warnings as stderr gave them before the run.

mod common;

use common::*;

/// A small board of `kind` locked from 10 Hz above its resonance, with an 8-bit DAC (so a
/// Coriolis sweep's config warns): the config's path.
fn locked_config(dir: &std::path::Path, kind: &str) -> std::path::PathBuf {
    let text = small_board(&format!(
        "[experiment]\nkind = \"{kind}\"\nrates_dps = [900.0, 1800.0, 2700.0]\n\
         average_s = 0.2\n[pll]\nmode = 1\n"
    ))
    .replace("q = 1000.0", "q = 2000.0")
    .replace(
        "decimation = 100",
        "decimation = 100\ndac_bits = 8\ndac_full_scale = 1.5",
    )
    .replace("f2 = 1.0", "f2 = 1.0\ncarrier_hz = 15010.0");
    config(dir, "c.toml", &text)
}

/// Checks `cmd`'s stderr and its JSON `file` in `out`: the lock note, the locked carrier in
/// the config in place of the `[pll]`, the config's warnings as stderr gave them.
fn check_locked(cmd: &str, kind: &str, file: &str) {
    let dir = tempfile::tempdir().unwrap();
    let cfg = locked_config(dir.path(), kind);
    let out = dir.path().join("out");
    let o = ok(gyroemu(&[cmd, s(&cfg), "--out", s(&out)], &[]));
    let err = stderr(&o);
    let note = err
        .lines()
        .find(|l| l.starts_with("pll: locked the carrier at "))
        .unwrap_or_else(|| panic!("{cmd}: no lock note: {err}"));
    let locked: f64 = note["pll: locked the carrier at ".len()..]
        .split_once(" Hz")
        .unwrap()
        .0
        .parse()
        .unwrap();
    // Q = 2000 at 15 kHz: a half-bandwidth of 3.75 Hz; the lock lands within 1e-3 of it.
    assert!((locked - 15000.0).abs() < 3.75e-3, "{note}");
    let j = json(&out.join(file));
    assert_eq!(j["config"]["drive"]["carrier_hz"].as_f64(), Some(locked));
    assert!(j["config"]["pll"].is_null(), "{}", j["config"]);
    // The config's warnings are those stderr gave before the run (judged for the lock to
    // come), not the held carrier's again: they disagreed where a rule judges the two apart.
    let said = config_warnings(&err, &cfg);
    assert!(!said.is_empty(), "{cmd}: the case must warn: {err}");
    let kept = strings(&j["warnings"]);
    assert_eq!(
        &kept[..said.len().min(kept.len())],
        &said[..],
        "{cmd}: {kept:?}"
    );
}

#[test]
fn selfcal_with_a_pll_names_the_carrier_it_ran_at() {
    check_locked("selfcal", "rotating", "selfcal.json");
}

#[test]
fn run_with_a_pll_names_the_carrier_it_ran_at() {
    check_locked("run", "coriolis", "summary.json");
}
