//! The noise-model fit of the Allan variance (IEEE Std 952 Annex C) on seeded records of known
//! white rate noise (N), flicker (B) and rate random walk (K): the 95 % intervals it reports
//! cover the true values at about their stated rate, and terms absent from the record are not
//! reported.

mod common;

use common::{pooled, rolled_off_record, TAU0};
use gyroemu_analysis::allan::fit::{fit_noise_model, NoiseModelFit};
use gyroemu_analysis::allan::{noise_readings, noise_readings_settled, AllanPoint};
use gyroemu_core::flicker::{psd_at_1hz_from_bias_instability, Flicker, FlickerParams};
use gyroemu_core::noise::NoiseRng;
use gyroemu_core::{f64x4, Stage};

/// Sample interval (selfcal's block means), s, and samples of one of four pooled records
/// (1000 s, as the worked example's Allan record).
const N: usize = 100_000;

/// Four lanes of white rate noise (`n` deg/s*sqrt(s)), flicker of bias instability `b` deg/s
/// (one-sided B^2 / (pi f), from 1e-4 Hz) and rate random walk (`k` deg/s/sqrt(s)), pooled
/// as selfcal pools them.
fn record(n: f64, b: f64, k: f64, seed: u64) -> Vec<AllanPoint> {
    let mut rng = NoiseRng::new(core::array::from_fn(|l| 7000 + 4 * seed + l as u64));
    let p = FlickerParams {
        fs_hz: 1.0 / TAU0,
        psd_at_1hz: psd_at_1hz_from_bias_instability(b.max(1e-30)),
        f_lo_hz: 1e-4,
        f_hi_hz: 0.5 / TAU0,
    };
    let mut fl = Flicker::<f64x4>::stationary(&p, || rng.normal_pair().0).unwrap();
    let flicker_on = f64x4::splat(if b > 0.0 { 1.0 } else { 0.0 });
    let mut walk = f64x4::splat(0.0);
    let mut lanes: [Vec<f64>; 4] = core::array::from_fn(|_| Vec::with_capacity(N));
    for _ in 0..N {
        let (w, x) = rng.normal_pair();
        let (r, _) = rng.normal_pair();
        // A sampled random walk: its Allan variance is K^2 tau / 3 + K^2 tau0^2 / (6 tau),
        // the second part 1e-5 of the white term here.
        walk += r * f64x4::splat(k * TAU0.sqrt());
        let y = fl.tick(w) * flicker_on + x * f64x4::splat(n / TAU0.sqrt()) + walk;
        lanes
            .iter_mut()
            .zip(y.to_array())
            .for_each(|(l, v)| l.push(v));
    }
    pooled(&lanes)
}

fn fit(curve: &[AllanPoint]) -> NoiseModelFit {
    noise_readings(curve).unwrap().model_fit
}

/// Whether `ci` holds `v` (an undetermined term's interval is [0, upper bound]).
fn covers(ci: [f64; 2], v: f64) -> bool {
    ci[0] <= v && v <= ci[1]
}

#[test]
fn white_flicker_and_random_walk_come_back_within_their_intervals() {
    // B = 10 deg/h; white noise meeting its floor at 3 s (N = 0.664 B sqrt(3 s): ARW 0.19
    // deg/sqrt(h), its -1/2 slope bent by the floor from about 0.75 s, as on the worked
    // example); a rate random walk reaching the floor at 30 s (K^2 = 3 (2 ln 2 / pi) B^2 /
    // 30 s: 126 deg/h/sqrt(h)). With the intervals' correlation between taus left out (each
    // point's own variance only) they covered 13 to 14 of 20.
    let b = 10.0 / 3600.0;
    let floor2 = 2.0 * core::f64::consts::LN_2 / core::f64::consts::PI * b * b;
    let n = (floor2 * 3.0).sqrt();
    let k = (3.0 * floor2 / 30.0).sqrt();
    let truth = [60.0 * n, 3600.0 * b, 216_000.0 * k];
    let seeds = 20u64;
    let mut covered = [0usize; 3];
    let mut determined = [0usize; 3];
    for seed in 0..seeds {
        let f = fit(&record(n, b, k, seed));
        assert_eq!(f.warning, None, "{f:?}");
        let terms = [
            (f.arw_deg_per_rt_h, f.arw_deg_per_rt_h_ci95),
            (
                f.bias_instability_deg_per_h,
                f.bias_instability_deg_per_h_ci95,
            ),
            (
                f.rate_random_walk_deg_per_h_per_rt_h,
                f.rate_random_walk_deg_per_h_per_rt_h_ci95,
            ),
        ];
        eprintln!("seed {seed}: {terms:.4?} (true {truth:.4?})");
        for (i, (v, ci)) in terms.iter().enumerate() {
            covered[i] += covers(*ci, truth[i]) as usize;
            determined[i] += v.is_finite() as usize;
        }
    }
    eprintln!("covered {covered:?} of {seeds}, determined {determined:?}");
    // 95 % intervals: at least 17 of 20 cover (a binomial(20, 0.95) falls below in 1.6 %).
    assert!(covered.iter().all(|&c| c >= 17), "{covered:?}");
    // Each term is in every record and well above its noise: each is read in most of them.
    assert!(determined.iter().all(|&d| d >= 18), "{determined:?}");
}

#[test]
fn white_noise_alone_gives_n_and_no_floor_or_random_walk() {
    // ARW 0.3 deg/sqrt(h), nothing else: the slope reading and the fit agree, and B and K
    // are null (or, at the rate a 95 % interval allows, a chance positive lower bound).
    let n = 0.3 / 60.0;
    let seeds = 20u64;
    let (mut covered, mut b_read, mut k_read) = (0, 0, 0);
    for seed in 0..seeds {
        let curve = record(n, 0.0, 0.0, 100 + seed);
        let r = noise_readings(&curve).unwrap();
        let f = r.model_fit;
        eprintln!(
            "seed {seed}: N {:.4} {:.4?}, slope reading {:.4}; B {:.3} {:.3?}; K {:.3} {:.3?}",
            f.arw_deg_per_rt_h,
            f.arw_deg_per_rt_h_ci95,
            r.arw_deg_per_rt_h,
            f.bias_instability_deg_per_h,
            f.bias_instability_deg_per_h_ci95,
            f.rate_random_walk_deg_per_h_per_rt_h,
            f.rate_random_walk_deg_per_h_per_rt_h_ci95
        );
        assert!(f.arw_deg_per_rt_h.is_finite(), "{f:?}");
        covered += covers(f.arw_deg_per_rt_h_ci95, 0.3) as usize;
        // Both readings of the same white curve within 2 % of each other.
        assert!(
            (f.arw_deg_per_rt_h / r.arw_deg_per_rt_h - 1.0).abs() < 0.02,
            "{r:?}"
        );
        for (v, ci, w, read) in [
            (
                f.bias_instability_deg_per_h,
                f.bias_instability_deg_per_h_ci95,
                f.bias_instability_warning,
                &mut b_read,
            ),
            (
                f.rate_random_walk_deg_per_h_per_rt_h,
                f.rate_random_walk_deg_per_h_per_rt_h_ci95,
                f.rate_random_walk_warning,
                &mut k_read,
            ),
        ] {
            if v.is_finite() {
                *read += 1;
            } else {
                assert!(w.is_some() && ci[0] == 0.0 && ci[1] > 0.0, "{f:?}");
            }
        }
    }
    // (Without the correlation between taus, N's interval covered 11 of 20.)
    eprintln!("N covered in {covered} of {seeds}; B read in {b_read}, K in {k_read}");
    assert!(covered >= 17, "{covered}");
    assert!(b_read <= 3 && k_read <= 3, "{b_read} {k_read}");
}

#[test]
fn past_a_roll_off_the_white_term_comes_back_within_its_interval() {
    // The worked example's curve: ARW 2.32 deg/sqrt(h) under a 90 deg/h floor, through a
    // 42 ms envelope, read from ten time constants on (selfcal's settling). There the roll-off
    // still takes 1.5 t N^2 / tau off sigma^2 tau (15 % at 0.42 s): the 1/tau^2 term fitted
    // with either sign takes it up. The model without it covered N in 0 of these 20 records
    // (it read 4 to 6 % low).
    let (t_res, arw, b_dph) = (0.042, 2.32, 90.0);
    let (n, b) = (arw / 60.0, b_dph / 3600.0);
    let seeds = 20u64;
    let (mut covered, mut b_covered, mut three_covered) = (0, 0, 0);
    for seed in 0..seeds {
        let curve = rolled_off_record(n, b, t_res, N, 9000, seed);
        let f = noise_readings_settled(&curve, 10.0 * t_res)
            .unwrap()
            .model_fit;
        assert!(f.tau_minus2_coefficient_dps2_s2.is_finite(), "{f:?}");
        covered += covers(f.arw_deg_per_rt_h_ci95, arw) as usize;
        b_covered += covers(f.bias_instability_deg_per_h_ci95, b_dph) as usize;
        let pts: Vec<AllanPoint> = curve
            .iter()
            .filter(|p| p.tau_s >= f.tau_min_s && p.tau_s <= f.tau_max_s)
            .copied()
            .collect();
        let three = fit_noise_model(&pts, TAU0, false);
        three_covered += covers(three.arw_deg_per_rt_h_ci95, arw) as usize;
        eprintln!(
            "seed {seed}: N {:.3} {:.3?} (without the 1/tau^2 term {:.3} {:.3?}), B {:.1} {:.1?}, \
             C {:.2e} (-1.5 t N^2 = {:.2e})",
            f.arw_deg_per_rt_h,
            f.arw_deg_per_rt_h_ci95,
            three.arw_deg_per_rt_h,
            three.arw_deg_per_rt_h_ci95,
            f.bias_instability_deg_per_h,
            f.bias_instability_deg_per_h_ci95,
            f.tau_minus2_coefficient_dps2_s2,
            -1.5 * t_res * n * n
        );
    }
    eprintln!(
        "N covered in {covered} of {seeds} (without the term: {three_covered}), B in {b_covered}"
    );
    assert!(covered >= 17 && b_covered >= 17, "{covered} {b_covered}");
}

#[test]
fn the_slope_readings_and_the_fit_agree_with_the_known_coefficients() {
    // Two independent readings of one curve, each against the coefficients the record was
    // made with: white noise over a flicker floor, whose ARW the -1/2 slope reads (N = 0.3
    // deg/sqrt(h), B = 10 deg/h); and the worked example's kind of curve behind a roll-off
    // (N = 2.32, B = 90), where the slope reads no ARW and the fit must.
    let r = noise_readings(&record(0.3 / 60.0, 10.0 / 3600.0, 0.0, 3)).unwrap();
    assert!((r.arw_deg_per_rt_h / 0.3 - 1.0).abs() < 0.03, "{r:?}");
    assert_eq!(r.arw_warning, None, "{r:?}");
    // The floor reading rests on a few long averages and the white noise above it.
    assert!(
        (r.bias_instability_deg_per_h / 10.0 - 1.0).abs() < 0.2,
        "{r:?}"
    );
    assert!(
        covers(r.model_fit.arw_deg_per_rt_h_ci95, 0.3),
        "{:?}",
        r.model_fit
    );
    // Where both read N, they agree: the slope's value lies in the fit's interval.
    assert!(
        covers(r.model_fit.arw_deg_per_rt_h_ci95, r.arw_deg_per_rt_h),
        "{:?}",
        r.model_fit
    );
    let curve = rolled_off_record(2.32 / 60.0, 90.0 / 3600.0, 0.042, N, 9000, 3);
    let r = noise_readings_settled(&curve, 0.42).unwrap();
    assert!(
        r.arw_deg_per_rt_h.is_nan() && r.arw_warning.is_some(),
        "{r:?}"
    );
    assert!(
        (r.bias_instability_deg_per_h / 90.0 - 1.0).abs() < 0.2,
        "{r:?}"
    );
    assert!(
        covers(r.model_fit.arw_deg_per_rt_h_ci95, 2.32),
        "{:?}",
        r.model_fit
    );
}
