//! A low-pass whose cutoff is a tiny fraction of the sample rate rounds its direct-form states
//! far more coarsely than the signal, unevenly on I and Q: a Coriolis phase moved with no
//! warning (1.7 mdeg at fc/fs = 1.7e-7, 77.5 at 2e-8). The warning's figure is the rounding's
//! reach, which the emulated error must stay within, and the presets are not warned.

mod common;

use common::{finished, number_after};
use gyroemu_config::{presets::preset, Config};

/// The Coriolis preset behind a 0.4 Hz low-pass at 240 kHz (fc/fs = 1.7e-6), read at 1 Hz.
fn narrow() -> Config {
    let mut c = preset("m2tfg-coriolis").unwrap();
    c.board.lpf_cutoff_hz = Some(0.4);
    c.board.decimation = Some(240_000);
    c.experiment.rates_dps = vec![100.0, 150.0];
    c.experiment.average_s = 1.0;
    c
}

fn stated(warnings: &[String]) -> Option<f64> {
    let w = warnings
        .iter()
        .find(|w| w.contains("direct-form sections"))?;
    Some(number_after(w, "by up to about "))
}

#[test]
fn the_rounding_of_a_narrow_lowpass_is_warned_and_bounds_the_run() {
    let cfg = narrow();
    let warnings = cfg.validate().unwrap();
    let res = finished(&cfg);
    let moved = res
        .points
        .iter()
        .flat_map(|p| (0..2).map(move |k| (p.phase_deg[k] - p.theory_deg[k]).abs() * 1e3))
        .fold(0.0, f64::max);
    // The board's own arithmetic moves the phase past the warning threshold (0.01 mdeg) ...
    assert!(moved > 0.01, "{moved} mdeg");
    // ... the warning says so, and its reach holds what the run read, within two decades.
    let s = stated(&warnings).unwrap_or_else(|| panic!("not warned: {warnings:?}"));
    assert!(
        s >= moved && s < 100.0 * moved,
        "stated {s} mdeg, the run moved {moved}"
    );
    // The presets' low-passes (fc/fs 8e-4 and 4e-5) are far from it.
    for name in ["m2tfg-coriolis", "baw-coriolis", "m2tfg-ratetable"] {
        let w = preset(name).unwrap().validate().unwrap();
        assert!(stated(&w).is_none(), "{name}: {w:?}");
    }
}
