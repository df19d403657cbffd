//! Self-calibration: the Coriolis scale factor predicted from the rotating excitation
//! (lambda times its phase slope) against the one measured on the virtual rate table, on
//! the same emulated board; its drift behaviour against the closed form (scale factor
//! 2 Q lambda / w0); the averaging-time reading against the sweep; and noisy runs whose
//! spread matches the confidence they report.

mod common;

use gyroemu::analysis::selfcal::{linearised_slope, run_selfcal_core, validate_selfcal};
use gyroemu::analysis::selfcal_analyses::{drift_analysis, drift_tracking_design, tau_analysis};
use gyroemu::analysis::selfcal_work;
use gyroemu::config::presets::preset;
use gyroemu::config::{Config, NoiseConfig, SelfcalConfig};

fn quiet(_: u64, _: u64) {}

/// White TIA current noise of `a_per_rthz` alone (300 K, no Brownian mass), seeded.
fn tia_noise(seed: u64, a_per_rthz: f64) -> Option<NoiseConfig> {
    Some(NoiseConfig {
        seed,
        temperature_k: 300.0,
        effective_mass_kg: None,
        tia_current_noise_a_per_rthz: a_per_rthz,
        tia_voltage_noise_v_per_rthz: 0.0,
        ..Default::default()
    })
}

fn fast_cfg(rates: &[f64], average_s: f64) -> Config {
    let mut c = preset("m2tfg-rotating").unwrap();
    c.experiment.rates_dps = rates.to_vec();
    c.experiment.average_s = average_s;
    c.experiment.settle_s = Some(0.8);
    c
}

#[test]
fn ideal_noiseless_selfcal_error_is_below_1e_4_for_lambda_1_and_0_6() {
    for lambda in [1.0, 0.6] {
        let mut c = fast_cfg(&[50.0, 100.0, 150.0, 175.0], 7.2);
        c.device.angular_gain = lambda;
        validate_selfcal(&c).unwrap();
        let r = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
        for m in r.modes {
            assert!(
                m.relative_error.abs() < 1e-4,
                "lambda {lambda}: relative error {:e}",
                m.relative_error
            );
            // The predicted slope is also the small-angle theory 2 Q lambda / w0.
            let w0 = 2.0 * std::f64::consts::PI * c.device.f0_hz;
            // deg per deg/s is the same number as rad per rad/s.
            let theory = 2.0 * c.device.q * lambda / w0;
            assert!((m.predicted_deg_per_dps / theory - 1.0).abs() < 1e-4);
        }
    }
}

/// `c` with the drift scenario's temperature coefficients: f0 -30 ppm/K, Q -3000 ppm/K.
fn drifting(mut c: Config) -> Config {
    c.selfcal = Some(SelfcalConfig {
        f0_tc_ppm_per_k: -30.0,
        q_tc_ppm_per_k: -3000.0,
        ..Default::default()
    });
    c
}

/// At -200 K (f0 -30 ppm/K: 90 Hz, 24 half-bandwidths above the carrier the loop starts
/// from) the drift loop cannot pull in within its lock run: that temperature's tracked half
/// is null with a warning naming it, and the scenario goes on (it failed the whole selfcal
/// after its sweeps, advising a key the drift loop does not read). A temperature it can pull
/// in is tracked as before.
#[test]
fn a_drift_temperature_the_loop_cannot_lock_is_null_and_said() {
    let c = drifting(fast_cfg(&[50.0, 100.0, 150.0, 175.0], 7.2));
    let seen = std::sync::Mutex::new(Vec::new());
    let record = |d: u64, t: u64| seen.lock().unwrap().push((d, t));
    let d = drift_analysis(&c, &[-200.0, 40.0], 0.04, None, &record).unwrap();
    let &(most, total) = seen.into_inner().unwrap().iter().max().unwrap();
    assert_eq!(most, total, "the scenario reached {most} of {total}");
    assert!(
        d[0].pll.is_none() && d[0].pll_lock_time_s.is_none(),
        "{:?}",
        d[0]
    );
    let w = d[0].pll_warning.as_deref().expect("said");
    assert!(w.contains("dT = -200 K") && w.contains("null"), "{w}");
    assert!(d[0].open_loop.measured_deg_per_dps.is_finite());
    assert!(
        d[1].pll.is_some() && d[1].pll_warning.is_none(),
        "{:?}",
        d[1]
    );
}

#[test]
fn drift_selfcal_tracks_the_scale_factor_and_a_stale_one_misses_by_the_q_over_f0_ratio() {
    let c = drifting(fast_cfg(&[50.0, 100.0, 150.0, 175.0], 7.2));
    let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
    let nominal = core.modes[0].coriolis.slope_deg_per_dps;
    let deltas = [-30.0, 40.0];
    let seen = std::sync::Mutex::new(Vec::new());
    let record = |d: u64, t: u64| seen.lock().unwrap().push((d, t));
    let d = drift_analysis(&c, &deltas, nominal, None, &record).unwrap();
    // The offsets and their four sweeps run side by side, their reports in any order:
    // progress still never passes its total, and reaches it.
    let seen = seen.into_inner().unwrap();
    let &(most, total) = seen.iter().max().expect("the scenario reports progress");
    assert!(seen.iter().all(|&(d, t)| t == total && d <= t), "{seen:?}");
    assert_eq!(most, total, "the scenario reached {most} of {total}");
    // The plan counts what the scenario runs: per offset, the nominal sweeps' windows
    // (the drift moves f0 and Q, not the windows) open loop and again PLL-tracked.
    let plan = |deltas: &[f64]| {
        let mut p = c.clone();
        p.selfcal.as_mut().unwrap().drift_delta_t_k = deltas.to_vec();
        selfcal_work(&p)
    };
    let (with, without) = (plan(&deltas), plan(&[]));
    let sweeps = core.rotating.point_samples + core.coriolis.point_samples;
    assert_eq!(
        with.point_samples - without.point_samples,
        2 * deltas.len() as u64 * sweeps
    );
    for (p, dt) in d.iter().zip(deltas) {
        // PLL-tracked: the carrier sits on the drifted resonance.
        let pll = p.pll.as_ref().expect("the default loop fits this board");
        assert!((pll.carrier_hz / p.f0_hz - 1.0).abs() < 1e-7, "{p:?}");
        assert!(pll.selfcal_relative_error.abs() < 1e-4, "{p:?}");
        assert!(pll.combined_selfcal_relative_error.abs() < 1e-4, "{p:?}");
        // Scale factor 2 Q lambda / w0: the stale calibration is off by (Q/f0)/(Q'/f0') - 1.
        let ratio = (1.0 - 30e-6 * dt) / (1.0 - 3000e-6 * dt);
        assert!(
            (pll.stale_relative_error - (ratio - 1.0)).abs() < 1e-4,
            "{p:?}, expected stale error {}",
            ratio - 1.0
        );
        // Open loop: the carrier stays at the nominal f0, detuned from the drifted mode by
        // -30 ppm/K; both sweeps read a detuned drive, as the exact theory of a drive at that
        // carrier says (its slopes read like the sweeps').
        let open = gyroemu::analysis::selfcal::drifted(&c, dt);
        assert_eq!(p.open_loop.carrier_hz, c.device.f0_hz);
        let dev = open.driven_device();
        let rates = &c.experiment.rates_dps;
        let deg = |r: [f64; 2]| r[0].to_degrees();
        let rot: Vec<f64> = rates
            .iter()
            .map(|&r| deg(dev.rotating_psi_rad(r.to_radians())))
            .collect();
        let cor: Vec<f64> = rates
            .iter()
            .map(|&r| deg(dev.coriolis_phase_rad(r.to_radians())))
            .collect();
        let slope = |ph: &[f64]| linearised_slope(rates, ph).slope_deg_per_dps;
        let want = c.device.angular_gain * slope(&rot) / slope(&cor) - 1.0;
        assert!(
            (p.open_loop.selfcal_relative_error - want).abs() < 1e-4,
            "{p:?}: theory {want}"
        );
        // Detuned by 4.8 (at -40 K) half-bandwidths, the open loop's error is far from 0.
        assert!(p.open_loop.selfcal_relative_error.abs() > 1e-2, "{p:?}");
    }
}

#[test]
fn averaging_time_reading_at_the_sweep_time_equals_the_sweep() {
    let c = fast_cfg(&[50.0, 100.0, 150.0, 175.0], 7.2);
    let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
    let m = core.modes[0];
    let taus = |group_threads| {
        tau_analysis(
            &c,
            14.4,
            &m.coriolis,
            &core.combined.coriolis,
            group_threads,
            &quiet,
        )
        .unwrap()
    };
    let t = taus(None);
    // Lane groups sized for one thread (selfcal runs its analyses side by side) give the
    // same readings, bit for bit, and so do the sweeps.
    assert_eq!(t, taus(Some(1)));
    assert_eq!(core, run_selfcal_core(&c, &quiet, &quiet, Some(1)).unwrap());
    let at = t
        .iter()
        .find(|p| p.tau_s == 7.2)
        .expect("7.2 s is on the grid");
    assert!((at.predicted_deg_per_dps / m.predicted_deg_per_dps - 1.0).abs() < 1e-12);
    let comb = core.combined;
    assert!((at.combined_predicted_deg_per_dps / comb.predicted_deg_per_dps - 1.0).abs() < 1e-12);
    assert!((at.combined_relative_error - comb.relative_error).abs() < 1e-12);
    // At 1 s (under half a period of the slowest rate) the window is truncated; its leak of the
    // 2 Omega products is known exactly and removed, so the
    // noiseless reading stays as good as the full one.
    let one = t.iter().find(|p| p.tau_s == 1.0).unwrap();
    assert!(one.relative_error.abs() < 1e-7, "{one:?}");
    assert!(at.relative_error.abs() < 1e-7, "{at:?}");
}

#[test]
fn averaging_time_readings_of_a_hann_config_are_boxcar_reads_and_right() {
    // The readings are early reads of one run, which only a boxcar window has. A Hann config
    // had them take Hann leaks never applied: +27.75 at 1 s and -2.55 at 10 s on this
    // noiseless ideal device, where the self-calibration is exact (THEORY.md section 4:
    // lambda times the rotating slope is the Coriolis slope).
    let mut c = fast_cfg(&[50.0, 100.0, 150.0, 175.0], 7.2);
    c.experiment.window = gyroemu::config::WindowKind::Hann;
    c.validate().unwrap();
    let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
    let m = core.modes[0];
    assert!(m.relative_error.abs() < 1e-6, "{:?}", m.relative_error);
    let t = tau_analysis(&c, 14.4, &m.coriolis, &core.combined.coriolis, None, &quiet).unwrap();
    for p in &t {
        assert!(p.relative_error.abs() < 1e-6, "{p:?}");
        assert!(p.combined_relative_error.abs() < 1e-6, "{p:?}");
    }
}

#[test]
fn an_averaging_time_reading_carries_the_rate_tables_error_and_its_own_theory() {
    // Noisy, with unequal drives and Q: at the sweep's own averaging time the reading is the
    // self-calibration itself, so it must carry the same interval (it left out the rate-table
    // slope's error, and covered the noiseless value in 3 of 12 seeds).
    let mut c = fast_cfg(&[100.0, 125.0, 150.0, 175.0], 3.6);
    c.drive.f2 = Some(1.01);
    c.device.q_mode2 = Some(1950.0);
    c.noise = tia_noise(3, 3e-11);
    let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
    let (m, comb) = (core.modes[0], core.combined);
    let taus = tau_analysis(&c, 7.2, &m.coriolis, &comb.coriolis, None, &quiet).unwrap();
    let at = taus
        .iter()
        .find(|p| p.tau_s == 3.6)
        .expect("3.6 s is on the grid");
    let same = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-9;
    assert!(
        same(at.relative_error_ci95, m.relative_error_ci95),
        "{at:?} against {m:?}"
    );
    assert!(same(
        at.combined_relative_error_ci95,
        comb.relative_error_ci95
    ));
    // Noiseless, the reading against the rotating sweep's own theory is noise and truncation
    // only: about 0, where the small-angle Coriolis theory it was compared with gave
    // F1/F2 - 1 = -0.0099 (the drive ratio the rotating reading never sees).
    c.noise = None;
    let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
    let m = core.modes[0];
    let taus = tau_analysis(&c, 7.2, &m.coriolis, &core.combined.coriolis, None, &quiet).unwrap();
    for p in &taus {
        assert!(p.relative_error_vs_theory.abs() < 1e-6, "{p:?}");
    }
    // Mode 1's Coriolis phase follows mode 2's response: 2 lambda Q2 F2 / (F1 w0), which the
    // noiseless rate table measures (with Q1 instead it was 2.6 % off).
    let w0 = 2.0 * std::f64::consts::PI * c.device.f0_hz;
    let theory = 2.0 * 1950.0 * c.device.angular_gain / w0 * 1.01;
    assert!((m.theory_coriolis_deg_per_dps / theory - 1.0).abs() < 1e-15);
    assert!(
        (m.coriolis.slope_deg_per_dps / theory - 1.0).abs() < 1e-3,
        "{m:?}"
    );
}

#[test]
fn averaging_time_progress_ends_at_its_total_whatever_the_lane_groups() {
    // Five points on one thread: one lane group of eight where the CPU has AVX-512, two of
    // four elsewhere; the canonical grouping the results report is two of four either way.
    // Progress must count the groups that run: never past its total, and reaching it.
    let c = fast_cfg(&[25.0, 50.0, 100.0, 150.0, 175.0], 2.0);
    let seen = std::sync::Mutex::new(Vec::new());
    let record = |d: u64, t: u64| seen.lock().unwrap().push((d, t));
    // 2 s: the shortest averaging-time run validation lets through. The slopes it compares
    // with do not matter here.
    let core = run_selfcal_core(&c, &quiet, &quiet, Some(1)).unwrap();
    let (cor, comb) = (core.modes[0].coriolis, core.combined.coriolis);
    let taus = tau_analysis(&c, 2.0, &cor, &comb, Some(1), &record).unwrap();
    assert_eq!(taus.len(), 2, "read at 1 and 2 s: {taus:?}");
    let seen = seen.into_inner().unwrap();
    // Groups report side by side, so the highest report, not the last one, is the total.
    let &(most, total) = seen.iter().max().expect("the run reports progress");
    assert!(seen.iter().all(|&(d, t)| t == total && d <= t), "{seen:?}");
    assert_eq!(most, total, "the run reached {most} of {total} samples");
}

#[test]
fn an_open_loop_drift_error_carries_an_interval_as_wide_as_its_smaller_slope_makes_it() {
    // Noise-dominated (TIA current noise), 20 K warmer: the open-loop carrier is then x
    // half-bandwidths off the drifted resonance, so the Coriolis slope falls by 1 + x^2 and the
    // signal by sqrt(1 + x^2) against a TIA noise that does not fall: the self-calibration's
    // relative error, and its 95 % interval, grow by about (1 + x^2)^1.5, the slope ratio to
    // the power 1.5. The drift cases had reported no interval at all. Each interval rests on
    // its fits' residuals (6 degrees of freedom), so the widening is averaged (in logs) over
    // seeds.
    let rates = [60.0, 75.0, 90.0, 105.0, 120.0, 135.0, 150.0, 175.0];
    let (mut log_widening, mut log_ratio) = (0.0, 0.0);
    let seeds = 0..6u64;
    let n = seeds.clone().count() as f64;
    for seed in seeds {
        let mut c = drifting(fast_cfg(&rates, 3.6));
        c.noise = tia_noise(seed, 5e-12);
        let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
        let m = core.modes[0];
        let nominal = m.coriolis.slope_deg_per_dps;
        let d = drift_analysis(&c, &[20.0], nominal, None, &quiet).unwrap();
        let open = &d[0].open_loop;
        log_ratio += (nominal / open.measured_deg_per_dps).ln() / n;
        log_widening += (open.selfcal_relative_error_ci95 / m.relative_error_ci95).ln() / n;
        assert!(open.combined_selfcal_relative_error_ci95.is_finite());
    }
    let (ratio, widening) = (log_ratio.exp(), log_widening.exp());
    assert!(ratio > 5.0, "the carrier is off resonance: {ratio}");
    let expected = ratio.powf(1.5);
    assert!(
        widening > expected / 1.5 && widening < 1.5 * expected,
        "intervals widened {widening}x for a slope {ratio}x smaller ({expected}x expected)"
    );
}

#[test]
fn noisy_selfcal_errors_scatter_as_their_reported_confidence() {
    // Ideal device, TIA noise raised so noise dominates: 8 seeds. The errors must centre on
    // zero and scatter like the standard error each run reports (from its fit residuals).
    let mut errs = Vec::new();
    let mut reported = Vec::new();
    let mut comb_errs = Vec::new();
    let mut comb_reported = Vec::new();
    for seed in 0..8 {
        let mut c = fast_cfg(&[100.0, 125.0, 150.0, 175.0], 3.6);
        c.noise = tia_noise(seed, 3e-11);
        let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
        let comb = core.combined;
        comb_errs.push(comb.relative_error);
        comb_reported.push(comb.rotating.rel_std_err.hypot(comb.coriolis.rel_std_err));
        let m = core.modes[0];
        errs.push(m.relative_error);
        let rel =
            |s: &gyroemu::analysis::selfcal::SlopeFit| s.std_err_deg_per_dps / s.slope_deg_per_dps;
        reported.push(rel(&m.rotating).hypot(rel(&m.coriolis)));
    }
    // Mode 1 alone, then both modes combined (geometric mean; its reported error counts the
    // two modes' correlation).
    for (errs, reported) in [(&errs, &reported), (&comb_errs, &comb_reported)] {
        let n = errs.len() as f64;
        let mean = errs.iter().sum::<f64>() / n;
        let sd = (errs.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let typical = (reported.iter().map(|r| r * r).sum::<f64>() / n).sqrt();
        assert!(sd > 0.0 && typical > 0.0);
        assert!(mean.abs() < 4.0 * sd / n.sqrt(), "mean {mean:e}, sd {sd:e}");
        // Two-point fits per sweep (dof 2) make each reported error rough: a factor 3 either
        // way.
        assert!(
            sd / typical > 1.0 / 3.0 && sd / typical < 3.0,
            "scatter {sd:e}, reported {typical:e}"
        );
    }
    // Same seed, same bits.
    let mut c = fast_cfg(&[100.0, 125.0, 150.0, 175.0], 3.6);
    c.noise = tia_noise(0, 3e-11);
    let again = run_selfcal_core(&c, &quiet, &quiet, None).unwrap().modes[0].relative_error;
    assert_eq!(again.to_bits(), errs[0].to_bits());
}

#[test]
fn selfcal_refuses_too_few_distinct_rates_naming_the_key() {
    // One rate: no slope; two: a slope without a confidence interval; zero and repeats do not
    // count. Three distinct non-zero rates pass.
    for rates in [
        &[100.0][..],
        &[0.0, 100.0, 100.0],
        &[50.0, 100.0],
        &[0.0, 50.0, 100.0, 50.0],
    ] {
        // selfcal runs both sweeps whatever the kind; as a Coriolis config rate 0 is not the
        // rotating run's own refusal.
        let mut c = fast_cfg(rates, 7.2);
        c.experiment.kind = gyroemu::config::ExperimentKind::Coriolis;
        let e = validate_selfcal(&c).unwrap_err();
        assert_eq!(
            e.key.as_deref(),
            Some("experiment.rates_dps"),
            "{rates:?}: {e}"
        );
        assert!(
            e.detail.contains("at least 3 distinct non-zero rates"),
            "{e}"
        );
    }
    validate_selfcal(&fast_cfg(&[50.0, 100.0, 150.0], 7.2)).unwrap();
}

#[test]
fn a_too_short_averaging_time_run_is_refused_under_its_own_key() {
    // The run of tau_max_s must span half a modulation period of the slowest rate (25 deg/s:
    // 7.2 s); the refusal named experiment.average_s, which the user had set right.
    let mut c = fast_cfg(&[25.0, 100.0, 150.0], 7.2);
    c.selfcal = Some(SelfcalConfig {
        tau_max_s: Some(7.0),
        ..Default::default()
    });
    let e = validate_selfcal(&c).unwrap_err();
    assert_eq!(e.key.as_deref(), Some("selfcal.tau_max_s"), "{e}");
    assert!(e.detail.contains("7.2 s"), "{e}");
    c.selfcal.as_mut().unwrap().tau_max_s = Some(7.2);
    validate_selfcal(&c).unwrap();
}

#[test]
fn rate_0_is_refused_in_a_rotating_run_and_left_out_of_selfcals_rotating_sweep() {
    // A rotating run at rate 0 has no sidebands: it ran and came out NaN, blamed on an
    // overflow. Refused before any sample; selfcal's rotating sweep leaves it out.
    let c = fast_cfg(&[0.0, 50.0, 100.0, 150.0], 7.2);
    let e = c.validate().unwrap_err();
    assert_eq!(e.key.as_deref(), Some("experiment.rates_dps[0]"), "{e}");
    let mut cor = c.clone();
    cor.experiment.kind = gyroemu::config::ExperimentKind::Coriolis;
    let (rot, table) = gyroemu::analysis::selfcal::sweep_configs(&cor);
    assert_eq!(rot.experiment.rates_dps, [50.0, 100.0, 150.0]);
    assert_eq!(table.experiment.rates_dps, [0.0, 50.0, 100.0, 150.0]);
    validate_selfcal(&cor).unwrap();
}

#[test]
fn selfcal_judges_the_config_as_it_reads_it_not_the_parts_it_ignores() {
    // `run` refuses each of these; selfcal ignores what it refuses on (its rotating sweep
    // leaves rate 0 out whatever `kind` says; `[dump]`, `rate_table` and `table_freq_hz` are
    // not its), so it must accept them with the warnings of the config without them.
    use gyroemu::config::{DumpConfig, RateTable};
    let clean = fast_cfg(&[50.0, 100.0, 150.0], 7.2);
    let want = validate_selfcal(&clean).unwrap();
    let mut with_zero = clean.clone();
    with_zero.experiment.rates_dps.insert(0, 0.0);
    let mut dumped = clean.clone();
    dumped.dump = Some(DumpConfig {
        rate_dps: Some(60.0),
        start_s: None,
        duration_s: None,
        nodes: None,
    });
    let mut table = clean.clone();
    table.experiment.rate_table = RateTable::Sinusoid;
    table.experiment.table_freq_hz = Some(1.0);
    for (what, c) in [("rate 0", &with_zero), ("dump", &dumped), ("table", &table)] {
        assert!(c.validate().is_err(), "{what}: run refuses it");
        assert_eq!(validate_selfcal(c).unwrap(), want, "{what}");
        let (rot, _) = gyroemu::analysis::selfcal::sweep_configs(c);
        assert_eq!(rot.experiment.rates_dps, [50.0, 100.0, 150.0], "{what}");
    }
    // The drift scenario's tracking loop is judged on the config as selfcal reads it too
    // (rate 0 had left it out as "not fitting the board").
    let drift = |c: &Config| {
        let mut c = c.clone();
        c.selfcal = Some(SelfcalConfig {
            drift_delta_t_k: vec![10.0],
            ..Default::default()
        });
        c
    };
    let want = validate_selfcal(&drift(&clean)).unwrap();
    assert!(drift_tracking_design(&drift(&clean)).is_some());
    for c in [&with_zero, &dumped, &table] {
        assert_eq!(validate_selfcal(&drift(c)).unwrap(), want);
        assert!(drift_tracking_design(&drift(c)).is_some());
    }
    // A refused rate is named by its index in the user's list, rate 0 counted (the rotating
    // sweep's list leaves it out: index 2, the 50 in the file, was named for the 1e8).
    // The rate keys a refusal names: it must name `named` and not `not`.
    let names = |c: &Config, named: usize, not: usize| {
        let e = validate_selfcal(c).unwrap_err();
        let keys: Vec<Option<String>> = e.problems().into_iter().map(|p| p.key).collect();
        let key = |i: usize| Some(format!("experiment.rates_dps[{i}]"));
        assert!(
            keys.contains(&key(named)) && !keys.contains(&key(not)),
            "{e}"
        );
    };
    let mut far = with_zero.clone();
    far.experiment.rates_dps = vec![0.0, 50.0, 100.0, 1e8, 150.0];
    names(&far, 3, 2);
    // A Coriolis config keeps rate 0 as selfcal reads it: its own index stands, for its own
    // rules and its rotating sweep's alike.
    far.experiment.kind = gyroemu::config::ExperimentKind::Coriolis;
    names(&far, 3, 4);
    // What selfcal does read is judged still: the same parts beside a too short average.
    for c in [&with_zero, &dumped, &table] {
        let mut short = c.clone();
        short.experiment.average_s = 2.0;
        let e = validate_selfcal(&short).unwrap_err();
        assert_eq!(e.key.as_deref(), Some("experiment.average_s"), "{e}");
    }
}

#[test]
fn selfcal_lists_its_sweeps_problems_with_the_configs_own() {
    // A low-pass above the output Nyquist (the config's own problem) and an averaging time
    // shorter than half a period of 25 deg/s (the rotating sweep's): one message with both;
    // the second used to appear only once the first was fixed.
    let mut c = fast_cfg(&[25.0, 100.0, 150.0], 2.0);
    c.experiment.kind = gyroemu::config::ExperimentKind::Coriolis;
    c.board.lpf_cutoff_hz = Some(1e6);
    let e = validate_selfcal(&c).unwrap_err();
    let keys: Vec<Option<String>> = e.problems().into_iter().map(|p| p.key).collect();
    assert!(keys.contains(&Some("board.lpf_cutoff_hz".into())), "{e}");
    assert!(keys.contains(&Some("experiment.average_s".into())), "{e}");
    assert!(
        e.to_string().contains("in the rotating sweep of selfcal"),
        "{e}"
    );
}

#[test]
fn selfcal_names_the_run_each_added_warning_holds_for() {
    // The selfcal preset's 16-bit DAC rounds its unequal drives differently; the rule states
    // a different size for each run selfcal makes (the rate-table sweep, each drifted
    // device). Each such warning must name its runs, and say each text once.
    let c = preset("m2tfg-selfcal").unwrap();
    // The config's own warnings (as selfcal reads it) first, then the added ones.
    let own = gyroemu::analysis::selfcal::as_read(&c).validate().unwrap();
    let all = validate_selfcal(&c).unwrap();
    assert!(all.starts_with(&own), "{all:#?}");
    let extra = &all[own.len()..];
    let dac: Vec<&String> = extra.iter().filter(|w| w.contains("dac_bits")).collect();
    assert!(dac.len() >= 2, "{extra:#?}");
    let runs = |w: &str| w.rsplit_once(" (in the ").map(|(_, r)| r.to_string());
    for w in extra {
        let r = runs(w).unwrap_or_else(|| panic!("no run named: {w}"));
        assert!(r.ends_with(" of selfcal)"), "{w}");
        // Not a warning of the config itself, said again with a run named.
        let text = w.rsplit_once(" (in the ").unwrap().0;
        assert!(!own.iter().any(|o| o == text), "said twice: {w}");
    }
    assert!(
        extra.iter().any(|w| w.contains("rate-table sweep")),
        "{extra:#?}"
    );
    // One line per distinct text: no two lines differ only in the runs they name.
    let texts: Vec<&str> = extra
        .iter()
        .map(|w| w.rsplit_once(" (in the ").unwrap().0)
        .collect();
    for (i, t) in texts.iter().enumerate() {
        assert!(!texts[i + 1..].contains(t), "{t} said twice");
    }
}

#[test]
fn the_allan_fit_is_widened_by_the_rate_table_slopes_own_error() {
    // The rate-equivalent Allan terms divide the phase by the measured rate-table slope of
    // mode 1; their intervals count that slope's 95 % relative half-width, t95(dof) se/|s|.
    let mut c = fast_cfg(&[50.0, 100.0, 150.0, 175.0], 7.2);
    c.noise = tia_noise(3, 2e-12);
    c.selfcal = Some(SelfcalConfig {
        allan_record_s: Some(20.0),
        ..Default::default()
    });
    validate_selfcal(&c).unwrap();
    let r = gyroemu::analysis::run_selfcal(&c, &gyroemu::experiment::Quiet).unwrap();
    let s = &r.core.modes[0].coriolis;
    let want =
        gyroemu::experiment::fit::t95(s.dof) * s.std_err_deg_per_dps / s.slope_deg_per_dps.abs();
    let a = r.allan.unwrap();
    assert_eq!(a.scale_deg_per_dps, s.slope_deg_per_dps);
    assert!(
        want > 0.0 && (a.scale_rel_ci95 / want - 1.0).abs() < 1e-12,
        "{} vs {want}",
        a.scale_rel_ci95
    );
}

#[test]
fn a_null_two_mode_estimate_says_why() {
    // TIA noise far above the signal: each sweep's two slopes take random signs, and where a
    // sweep's differ the geometric mean is null. It was null with no word; now a warning
    // names the sweep and both slopes, and there is none when the estimate stands.
    let mut nulls = 0;
    for seed in 0..6 {
        let mut c = fast_cfg(&[100.0, 125.0, 150.0, 175.0], 3.6);
        c.noise = tia_noise(seed, 3e-9);
        let core = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
        let comb = core.combined;
        let null =
            comb.rotating.slope_deg_per_dps.is_nan() || comb.coriolis.slope_deg_per_dps.is_nan();
        let w = core.combined_warning();
        assert_eq!(w.is_some(), null, "seed {seed}: {w:?}, {comb:?}");
        if let Some(w) = w {
            nulls += 1;
            let m = core.modes;
            let sweep = if comb.coriolis.slope_deg_per_dps.is_nan() {
                (m[0].coriolis, m[1].coriolis)
            } else {
                (m[0].rotating, m[1].rotating)
            };
            assert!(
                w.contains(&format!("mode 1 {:.6e}", sweep.0.slope_deg_per_dps))
                    && w.contains(&format!("mode 2 {:.6e}", sweep.1.slope_deg_per_dps)),
                "{w}"
            );
        }
    }
    assert!(nulls > 0, "no seed made a null estimate");
}

/// Selfcal's plain line fits (`plain_fit`, in selfcal.json) take the readings on their branch
/// as a sweep's summary does: the Coriolis phases -59, +59, +66 deg (Q = 50 at 1 kHz, +-6000
/// and 8000 deg/s) had been moved a half turn apart (slope -0.0044 for +0.0092, r2 0.947).
#[test]
fn selfcals_plain_fits_keep_a_steep_step_between_rates() {
    let c = gyroemu::config::parse_config(
        r#"
[device]
f0_hz = 1000.0
q = 50.0
angular_gain = 1.0
[drive]
f1 = 1.0
f2 = 1.0
[board]
fs_hz = 16000.0
[experiment]
kind = "rotating"
rates_dps = [-6000.0, 6000.0, 8000.0]
average_s = 0.5
"#,
    )
    .unwrap();
    validate_selfcal(&c).unwrap();
    let r = run_selfcal_core(&c, &quiet, &quiet, None).unwrap();
    for (sweep, fit) in [
        (&r.coriolis, r.modes[0].coriolis.plain_fit),
        (&r.rotating, r.modes[0].rotating.plain_fit),
    ] {
        let xs: Vec<f64> = sweep.points.iter().map(|p| p.rate_dps).collect();
        let ys: Vec<f64> = sweep.points.iter().map(|p| p.phase_deg[0]).collect();
        // The readings are continuous as written; the plain fit is theirs, and the sweep's.
        let plain = gyroemu::experiment::fit::fit_line(&xs, &ys);
        assert_eq!(
            fit.slope.to_bits(),
            plain.slope.to_bits(),
            "{fit:?} {plain:?} {ys:?}"
        );
        assert_eq!(fit.slope.to_bits(), sweep.fit[0].slope.to_bits());
        assert!(fit.slope > 0.0 && fit.r2 > 0.99, "{fit:?}");
    }
}
