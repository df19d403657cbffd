//! The noise-dominance warning: a run whose white noise scatters a phase reading by more than
//! a tenth of the phase measured there is told so before it runs (a noise ten times the
//! signal once printed phases of 122 and -93 deg against a theory of 4.2 deg, exit 0, no
//! warning). The stated scatter itself is checked against the board's read-out in
//! `tests/noise_physics.rs`; here: where the warning starts, what it says once the noise
//! outgrows the signal, that an undithered ADC's rounding is left to its own rule, and that no
//! shipped preset's sweep trips it.

use gyroemu_config::presets::{preset, PRESETS};
use gyroemu_config::{Config, NoiseConfig, WARN_NOISE_PHASE_FRACTION};

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
    let sigma = |c: &Config| c.noise_phase().unwrap()[0].sigma_rad[0];
    let per_unit = sigma(&coriolis(1e-10)) / 1e-10;
    let limit = WARN_NOISE_PHASE_FRACTION * theory_rad / per_unit;
    assert!(noise_warnings(&coriolis(0.97 * limit)).is_empty());
    let w = noise_warnings(&coriolis(1.03 * limit));
    assert_eq!(w.len(), 2, "one per mode: {w:?}");
    for (k, w) in w.iter().enumerate() {
        assert!(w.contains(&format!("mode {}", k + 1)), "{w}");
        assert!(
            w.contains("scatters its phase reading") && w.contains("4.236e0 deg measured there"),
            "{w}"
        );
        assert!(
            w.contains("at 100 deg/s") && w.contains("experiment.average_s"),
            "{w}"
        );
    }
    // Averaging 4 times longer halves the scatter: under the limit again.
    let mut longer = coriolis(1.03 * limit);
    longer.experiment.average_s = 0.8;
    assert!(noise_warnings(&longer).is_empty());
}

#[test]
fn once_the_noise_outgrows_the_signal_the_warning_says_the_readings_are_noise() {
    let w = noise_warnings(&coriolis(1e-7));
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("buries the signal") && w[0].contains("each phase reading there is noise")
    );
}

#[test]
fn an_undithered_adcs_rounding_is_not_taken_for_noise() {
    // A [noise] section with no analog source and a 12-bit ADC: the rounding is systematic
    // (the same error on every seed), which the ADC-LSB rule states; this one stays silent.
    let mut c = coriolis(0.0);
    c.experiment.rates_dps = vec![1.0, 25.0];
    c.board.adc_bits = Some(12);
    assert!(noise_warnings(&c).is_empty());
    assert_eq!(c.noise_phase().unwrap()[0].sigma_rad, [0.0; 2]);
    // With noise of an LSB or more it dithers: its rounding counts as white noise.
    let step = c.board.adc_full_scale_v / 2048.0;
    let mut dithered = c.clone();
    dithered
        .noise
        .as_mut()
        .unwrap()
        .tia_current_noise_a_per_rthz = 5e-12;
    let mut quiet = dithered.clone();
    quiet.board.adc_bits = None;
    let (with, without) = (
        dithered.noise_phase().unwrap(),
        quiet.noise_phase().unwrap(),
    );
    assert!(
        with[0].sigma_rad[0] > without[0].sigma_rad[0],
        "{with:?} {without:?} {step}"
    );
}

#[test]
fn no_shipped_presets_sweep_is_noise_dominated() {
    for (name, _, _) in PRESETS {
        let c = preset(name).unwrap();
        assert!(noise_warnings(&c).is_empty(), "{name}");
    }
}
