//! `selfcal` with a `[pll]`: it says where the lock ended, as `run` does, and `selfcal.json`
//! names the carrier its sweeps ran at (it named the nominal start, 10 Hz from the run).

mod common;

use common::*;

#[test]
fn selfcal_with_a_pll_names_the_carrier_it_ran_at() {
    let dir = tempfile::tempdir().unwrap();
    let text = small_board(
        "[experiment]\nkind = \"rotating\"\nrates_dps = [900.0, 1800.0, 2700.0]\n\
         average_s = 0.2\n[pll]\nmode = 1\n",
    )
    .replace("q = 1000.0", "q = 2000.0")
    .replace("f2 = 1.0", "f2 = 1.0\ncarrier_hz = 15010.0");
    let cfg = config(dir.path(), "c.toml", &text);
    let out = dir.path().join("out");
    let o = ok(gyroemu(&["selfcal", s(&cfg), "--out", s(&out)], &[]));
    let err = stderr(&o);
    let note = err
        .lines()
        .find(|l| l.starts_with("pll: locked the carrier at "))
        .unwrap_or_else(|| panic!("no lock note: {err}"));
    let locked: f64 = note["pll: locked the carrier at ".len()..]
        .split_once(" Hz")
        .unwrap()
        .0
        .parse()
        .unwrap();
    // Q = 2000 at 15 kHz: a half-bandwidth of 3.75 Hz; the lock lands within 1e-3 of it.
    assert!((locked - 15000.0).abs() < 3.75e-3, "{note}");
    let j = json(&out.join("selfcal.json"));
    assert_eq!(j["config"]["drive"]["carrier_hz"].as_f64(), Some(locked));
    assert!(j["config"]["pll"].is_null(), "{}", j["config"]);
}
