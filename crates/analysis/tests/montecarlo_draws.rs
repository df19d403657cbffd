//! The device draws of a lot: device `i` is a function of `(seed, i)` alone (the same in
//! any order, subset, shard split or lot size, and whatever the spreads), and over many
//! devices the drawn parameters have the configured distributions: zero mean, the configured
//! standard deviation (of a normal truncated at `truncate_sigma`, from its closed-form
//! variance, or of a uniform), no correlation between tolerances, no draw beyond the limit.

use gyroemu_analysis::montecarlo::{device_config, draw_device, DeviceDraw};
use gyroemu_config::presets::preset;
use gyroemu_config::{Config, Distribution, MonteCarloConfig};
use proptest::prelude::*;

fn lot() -> Config {
    preset("m2tfg-montecarlo").unwrap()
}

fn mc(seed: u64, distribution: Distribution, truncate_sigma: f64) -> MonteCarloConfig {
    MonteCarloConfig {
        seed,
        distribution,
        truncate_sigma,
        ..lot().montecarlo.unwrap()
    }
}

fn bits(d: &DeviceDraw) -> [u64; 6] {
    d.z.map(f64::to_bits)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn a_device_depends_on_its_seed_and_index_only(
        seed in any::<u64>(),
        n in 1usize..200,
        shards in 1usize..9,
        uniform in any::<bool>(),
        q_sigma in 0.0f64..0.2,
    ) {
        let dist = if uniform { Distribution::Uniform } else { Distribution::Normal };
        let m = mc(seed, dist, 4.0);
        let in_order: Vec<[u64; 6]> = (0..n as u64).map(|i| bits(&draw_device(&m, i))).collect();
        // Each shard's devices, drawn in reverse within the shard, shards in reverse.
        for s in (0..shards).rev() {
            for i in (s..n).step_by(shards).rev() {
                prop_assert_eq!(bits(&draw_device(&m, i as u64)), in_order[i]);
            }
        }
        // Other spreads (not the shape): the same scores.
        let wider = MonteCarloConfig { q_sigma_rel: q_sigma, lambda_sigma_rel: 0.0, ..m.clone() };
        prop_assert_eq!(bits(&draw_device(&wider, (n - 1) as u64)), in_order[n - 1]);
        // The applied device too, bit for bit, whichever lot it is drawn in.
        let base = Config { montecarlo: Some(m.clone()), ..lot() };
        let i = (n / 2) as u64;
        let a = device_config(&base, &draw_device(&m, i));
        let b = device_config(&base, &draw_device(&m, i));
        prop_assert_eq!(toml::to_string(&a).unwrap(), toml::to_string(&b).unwrap());
        // Another index or another seed: other scores.
        if n > 1 {
            prop_assert_ne!(in_order[0], in_order[1]);
        }
        let other = mc(seed.wrapping_add(1), dist, 4.0);
        prop_assert_ne!(bits(&draw_device(&other, 0)), in_order[0]);
    }
}

/// erf by its Taylor series (converges for every x; at |x| <= 3 the alternating terms lose
/// about 4 of 16 digits): the independent truth for the truncated normal's moments.
fn erf(x: f64) -> f64 {
    let mut term = x;
    let mut sum = x;
    for n in 1..200 {
        term *= -x * x / n as f64;
        sum += term / (2 * n + 1) as f64;
    }
    sum * 2.0 / std::f64::consts::PI.sqrt()
}

/// Variance of a unit normal truncated to [-k, k]: 1 - 2 k phi(k) / (2 Phi(k) - 1).
fn truncated_variance(k: f64) -> f64 {
    let phi = (-k * k / 2.0).exp() / (2.0 * std::f64::consts::PI).sqrt();
    1.0 - 2.0 * k * phi / erf(k / 2f64.sqrt())
}

/// Mean, variance and fourth central moment of `v`.
fn moments(v: &[f64]) -> (f64, f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    let m4 = v.iter().map(|x| (x - m).powi(4)).sum::<f64>() / n;
    (m, var, m4)
}

/// Checks that `v` has mean 0 and variance `want_var`, each within 5 standard errors (of the
/// mean: sqrt(var / n); of the variance: sqrt((m4 - var^2) / n)).
fn assert_moments(what: &str, v: &[f64], want_var: f64) {
    let n = v.len() as f64;
    let (m, var, m4) = moments(v);
    let se_mean = (want_var / n).sqrt();
    assert!(
        m.abs() < 5.0 * se_mean,
        "{what}: mean {m:e}, 5 se {:e}",
        5.0 * se_mean
    );
    let se_var = ((m4 - var * var) / n).sqrt();
    assert!(
        (var - want_var).abs() < 5.0 * se_var,
        "{what}: variance {var:e}, want {want_var:e} +- {:e}",
        5.0 * se_var
    );
}

const DRAWS: u64 = 20_000;

#[test]
fn the_truncated_variance_formula_holds_its_limits() {
    // Untruncated: 1; truncated at 1 sigma: the textbook 0.2911 (Johnson, Kotz and
    // Balakrishnan: 1 - 2 phi(1) / (2 Phi(1) - 1) = 1 - 0.48394 / 0.68269).
    assert!((truncated_variance(8.0) - 1.0).abs() < 1e-12);
    assert!((truncated_variance(1.0) - 0.291_125).abs() < 2e-6);
    assert!((erf(1.0) - 0.842_700_792_949_715).abs() < 1e-14);
}

#[test]
fn scores_have_the_configured_shape() {
    for (dist, k) in [
        (Distribution::Normal, 4.0),
        (Distribution::Normal, 1.5),
        (Distribution::Uniform, 4.0),
    ] {
        let m = mc(7, dist, k);
        let draws: Vec<[f64; 6]> = (0..DRAWS).map(|i| draw_device(&m, i).z).collect();
        let (want_var, limit) = match dist {
            Distribution::Normal => (truncated_variance(k), k),
            Distribution::Uniform => (1.0, 3f64.sqrt()),
        };
        for p in 0..6 {
            let v: Vec<f64> = draws.iter().map(|z| z[p]).collect();
            let what = format!("{dist:?} at {k}: score {p}");
            assert!(v.iter().all(|x| x.abs() <= limit), "{what}: beyond {limit}");
            assert_moments(&what, &v, want_var);
            // The tail: P(|z| > 1) of the truncated law, within 5 standard errors.
            let p_tail = match dist {
                Distribution::Normal => {
                    (erf(k / 2f64.sqrt()) - erf(1.0 / 2f64.sqrt())) / erf(k / 2f64.sqrt())
                }
                Distribution::Uniform => 1.0 - 1.0 / 3f64.sqrt(),
            };
            let f = v.iter().filter(|x| x.abs() > 1.0).count() as f64 / DRAWS as f64;
            let se = (p_tail * (1.0 - p_tail) / DRAWS as f64).sqrt();
            assert!(
                (f - p_tail).abs() < 5.0 * se,
                "{what}: tail {f} vs {p_tail}"
            );
        }
        // Independent tolerances: every pair's correlation within 5 / sqrt(n) of 0.
        for a in 0..6 {
            for b in a + 1..6 {
                let r = draws.iter().map(|z| z[a] * z[b]).sum::<f64>() / DRAWS as f64 / want_var;
                assert!(
                    r.abs() < 5.0 / (DRAWS as f64).sqrt(),
                    "{dist:?} {a}-{b}: r = {r}"
                );
            }
        }
    }
}

#[test]
fn drawn_devices_have_the_configured_spreads() {
    let base = lot();
    let m = base.montecarlo.clone().unwrap();
    let devs: Vec<Config> = (0..DRAWS)
        .map(|i| device_config(&base, &draw_device(&m, i)))
        .collect();
    let v_z = truncated_variance(m.truncate_sigma);
    let d0 = &base.device;
    // (what, relative or absolute deviation of each device, configured spread)
    let q2_over_q = |c: &Config| c.device.q_mode2.unwrap_or(c.device.q) / c.device.q;
    type Deviation<'a> = Box<dyn Fn(&Config) -> f64 + 'a>;
    let cases: [(&str, Deviation, f64); 6] = [
        (
            "mode split",
            Box::new(|c| c.device.mode2_f0_offset_hz - d0.mode2_f0_offset_hz),
            m.mode_split_sigma_hz,
        ),
        ("Q", Box::new(|c| c.device.q / d0.q - 1.0), m.q_sigma_rel),
        (
            "Q mismatch",
            Box::new(move |c| q2_over_q(c) - 1.0),
            m.q_mismatch_sigma_rel,
        ),
        (
            "F2/F1",
            Box::new(|c| c.f2() / c.drive.f1 - base.f2() / base.drive.f1),
            m.drive_gain_sigma_rel,
        ),
        (
            "phase shifter",
            Box::new(|c| c.board.phase_shifter_error_deg - base.board.phase_shifter_error_deg),
            m.phase_shifter_sigma_deg,
        ),
        (
            "lambda",
            Box::new(|c| c.device.angular_gain / d0.angular_gain - 1.0),
            m.lambda_sigma_rel,
        ),
    ];
    for (what, dev, sigma) in &cases {
        assert!(*sigma > 0.0, "{what}: the preset spreads every tolerance");
        let v: Vec<f64> = devs.iter().map(dev).collect();
        assert_moments(what, &v, sigma * sigma * v_z);
    }
    // Each device its own noise streams; nothing else of the nominal config changes.
    let seeds: std::collections::BTreeSet<u64> = devs
        .iter()
        .map(|c| c.noise.as_ref().unwrap().seed)
        .collect();
    assert_eq!(seeds.len(), devs.len());
    let mut same = devs[3].clone();
    same.device = base.device.clone();
    same.drive = base.drive.clone();
    same.board.phase_shifter_error_deg = base.board.phase_shifter_error_deg;
    same.noise = base.noise.clone();
    assert_eq!(
        same,
        Config {
            montecarlo: None,
            ..base.clone()
        }
    );
}

#[test]
fn zero_spreads_leave_the_nominal_device_bit_for_bit() {
    let mut base = lot();
    base.noise = None;
    base.device.q_mode2 = None;
    let m = base.montecarlo.as_mut().unwrap();
    m.mode_split_sigma_hz = 0.0;
    m.q_sigma_rel = 0.0;
    m.q_mismatch_sigma_rel = 0.0;
    m.drive_gain_sigma_rel = 0.0;
    m.phase_shifter_sigma_deg = 0.0;
    m.lambda_sigma_rel = 0.0;
    let m = base.montecarlo.clone().unwrap();
    for i in 0..50 {
        let c = device_config(&base, &draw_device(&m, i));
        assert_eq!(
            toml::to_string(&c).unwrap(),
            toml::to_string(&Config {
                montecarlo: None,
                ..base.clone()
            })
            .unwrap()
        );
    }
}
