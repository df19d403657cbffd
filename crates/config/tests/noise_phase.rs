//! The noise-dominance warning: a run whose white noise scatters each phase reading by more
//! than a tenth of the smallest phase it measures is told so before it runs (a noise ten
//! times the signal once printed phases of 122 and -93 deg against a theory of 4.2 deg, exit 0,
//! no warning). The stated scatter itself is checked against the board's read-out in
//! `tests/noise_physics.rs`; here: where the warning starts, what it says past a radian, and
//! that no shipped preset trips it.

use gyroemu_config::presets::{preset, PRESETS};
use gyroemu_config::{Config, NoiseConfig, NOISE_PHASE_WARN_FRACTION};

/// A Coriolis sweep at 100 deg/s (4.236 deg by theory), the TIA's input noise `i_n`.
fn coriolis(i_n: f64) -> Config {
    let mut c = preset("m2tfg-coriolis").unwrap();
    c.experiment.rates_dps = vec![100.0];
    c.experiment.average_s = 0.2;
    c.noise = Some(NoiseConfig {
        seed: 1,
        tia_current_noise_a_per_rthz: i_n,
        ..Default::default()
    });
    c
}

fn noise_warnings(c: &Config) -> Vec<String> {
    c.validate()
        .unwrap()
        .into_iter()
        .filter(|w| w.contains("the noise at the carrier"))
        .collect()
}

#[test]
fn the_warning_starts_at_a_tenth_of_the_smallest_phase() {
    // The scatter is linear in the density: scaled to just under and just over the limit.
    let theory_rad = 4.236_394_799_058_84_f64.to_radians();
    let sigma = |c: &Config| c.noise_phase_sigma_rad().unwrap()[0].0;
    let per_unit = sigma(&coriolis(1e-10)) / 1e-10;
    let limit = NOISE_PHASE_WARN_FRACTION * theory_rad / per_unit;
    assert!(noise_warnings(&coriolis(0.97 * limit)).is_empty());
    let w = noise_warnings(&coriolis(1.03 * limit));
    assert_eq!(w.len(), 2, "one per mode: {w:?}");
    for (k, w) in w.iter().enumerate() {
        assert!(w.contains(&format!("mode {}", k + 1)), "{w}");
        assert!(
            w.contains("scatters each phase reading") && w.contains("4.236e0 deg at 100 deg/s"),
            "{w}"
        );
        assert!(w.contains("experiment.average_s = 0.2 s"), "{w}");
    }
    // Averaging 4 times longer halves the scatter: under the limit again.
    let mut longer = coriolis(1.03 * limit);
    longer.experiment.average_s = 0.8;
    assert!(noise_warnings(&longer).is_empty());
}

#[test]
fn past_a_radian_the_warning_says_the_readings_are_noise() {
    let w = noise_warnings(&coriolis(1e-7));
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w[0].contains("buries the signal") && w[0].contains("each phase reading is noise"));
}

#[test]
fn no_shipped_preset_is_noise_dominated() {
    for (name, _, _) in PRESETS {
        let c = preset(name).unwrap();
        assert!(noise_warnings(&c).is_empty(), "{name}");
    }
}
