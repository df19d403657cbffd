//! Overlapping Allan deviation of a sampled rate (or phase-rate) series, and the two readings
//! gyro engineers take from it (IEEE Std 952): the angle random walk from the -1/2 slope and
//! the bias instability from the flat floor.

use gyroemu_core::flicker::ADEV_PER_BIAS_INSTABILITY;
use serde::Serialize;

/// Independent differences (`n_terms / m`) a point must rest on to enter the bias-instability
/// reading. With flicker noise an overlapping Allan deviation from them has relative standard
/// error about `0.63 / sqrt(n_terms / m)` (NIST SP 1065, edf `5 N / (4 m)`), so 40 keeps it
/// under 10 %: the last points of a curve (a third of the record, a handful of averages) scatter
/// by 30 % and their dips would pass for the floor.
const MIN_INDEPENDENT_DIFFERENCES: f64 = 40.0;

/// Half-width, in decades of tau, of the window the floor is smoothed over before its minimum
/// is taken (the minimum of a noisy flat curve reads low by about its scatter).
const FLOOR_SMOOTHING_DECADES: f64 = 0.125;

/// One point of an Allan deviation curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AllanPoint {
    /// Averaging time, s.
    pub tau_s: f64,
    /// Allan deviation, in the unit of the series.
    pub adev: f64,
    /// Number of overlapping differences that formed it (its confidence grows with it).
    pub n_terms: usize,
}

/// Overlapping Allan deviation of `y` (sample interval `tau0_s`) at averaging factors from 1
/// up to a third of the record, about `per_decade` per decade:
/// sigma^2(m tau0) = 1 / (2 (N - 2m + 1)) sum_k (ybar_{k+m} - ybar_k)^2, with ybar_k the mean
/// of y[k .. k + m], from prefix sums (compensated).
pub fn overlapping_adev(y: &[f64], tau0_s: f64, per_decade: usize) -> Vec<AllanPoint> {
    let n = y.len();
    if n < 3 {
        return Vec::new();
    }
    // Prefix sums of the mean-removed series keep the differences well conditioned.
    let mean = y.iter().sum::<f64>() / n as f64;
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    let (mut s, mut c) = (0.0f64, 0.0f64);
    for &v in y {
        // Kahan summation.
        let t = (v - mean) - c;
        let u = s + t;
        c = (u - s) - t;
        s = u;
        prefix.push(s);
    }
    let mut ms: Vec<usize> = Vec::new();
    let max_m = n / 3;
    let step = 10f64.powf(1.0 / per_decade.max(1) as f64);
    let mut x = 1.0f64;
    while (x as usize) <= max_m {
        let m = x.round() as usize;
        if ms.last() != Some(&m) && m >= 1 {
            ms.push(m);
        }
        x *= step;
    }
    ms.into_iter()
        .map(|m| {
            let mf = m as f64;
            let terms = n - 2 * m + 1;
            let mut acc = 0.0;
            for k in 0..terms {
                let a = (prefix[k + m] - prefix[k]) / mf;
                let b = (prefix[k + 2 * m] - prefix[k + m]) / mf;
                acc += (b - a) * (b - a);
            }
            AllanPoint {
                tau_s: mf * tau0_s,
                adev: (acc / (2.0 * terms as f64)).sqrt(),
                n_terms: terms,
            }
        })
        .collect()
}

/// The readings of an Allan deviation curve of a rate in deg/s.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NoiseReadings {
    /// Angle random walk, deg/sqrt(h): the -1/2 line sigma = N / sqrt(tau) read at tau = 1 s
    /// (N in deg/s*sqrt(s), times 60).
    pub arw_deg_per_rt_h: f64,
    /// Bias instability, deg/h: the flat minimum of the curve divided by 0.664 (the flicker
    /// floor `sqrt(2 ln 2 / pi) B`). Read where the curve is reliable (see [`noise_readings`]).
    pub bias_instability_deg_per_h: f64,
    /// Where the minimum lies, s.
    pub tau_at_min_s: f64,
}

/// Reads ARW and bias instability from an Allan deviation curve of a rate in deg/s (as
/// [`overlapping_adev`] gives it: the first point at tau0, `n_terms` summed over pooled
/// records). The random-walk coefficient N is the median of sigma*sqrt(tau) over the points
/// whose local log-log slope is within 0.1 of -1/2 (the white-noise region), or over the first
/// third of the curve if none is.
///
/// The bias instability is the flat minimum: over the points resting on at least 40
/// independent differences (`n_terms tau0 / tau`; all points if none does), sigma^2 averaged
/// over +-1/8 decade of tau, its minimum's square root divided by 0.664. Without a flicker
/// floor the minimum is the last reliable point, and only bounds the bias instability from
/// above.
pub fn noise_readings(curve: &[AllanPoint]) -> Option<NoiseReadings> {
    if curve.len() < 2 {
        return None;
    }
    let slope = |i: usize| {
        let (a, b) = (curve[i], curve[i + 1]);
        (b.adev.ln() - a.adev.ln()) / (b.tau_s.ln() - a.tau_s.ln())
    };
    let mut ns: Vec<f64> = (0..curve.len() - 1)
        .filter(|&i| (slope(i) + 0.5).abs() < 0.1)
        .map(|i| curve[i].adev * curve[i].tau_s.sqrt())
        .collect();
    if ns.is_empty() {
        ns = curve[..curve.len().div_ceil(3)]
            .iter()
            .map(|p| p.adev * p.tau_s.sqrt())
            .collect();
    }
    ns.sort_by(f64::total_cmp);
    let n_coef = ns[ns.len() / 2];
    let (floor, tau_at_min_s) = flat_minimum(curve)?;
    Some(NoiseReadings {
        arw_deg_per_rt_h: 60.0 * n_coef,
        bias_instability_deg_per_h: floor / ADEV_PER_BIAS_INSTABILITY * 3600.0,
        tau_at_min_s,
    })
}

/// The flat minimum of a curve and where it lies: see [`noise_readings`].
fn flat_minimum(curve: &[AllanPoint]) -> Option<(f64, f64)> {
    let tau0 = curve.first()?.tau_s;
    let reliable: Vec<&AllanPoint> = curve
        .iter()
        .filter(|p| p.n_terms as f64 * tau0 / p.tau_s >= MIN_INDEPENDENT_DIFFERENCES)
        .collect();
    let pts: Vec<&AllanPoint> = if reliable.is_empty() {
        curve.iter().collect()
    } else {
        reliable
    };
    pts.iter()
        .map(|p| {
            let near: Vec<f64> = pts
                .iter()
                .filter(|q| (q.tau_s / p.tau_s).log10().abs() <= FLOOR_SMOOTHING_DECADES + 1e-9)
                .map(|q| q.adev * q.adev)
                .collect();
            (
                (near.iter().sum::<f64>() / near.len() as f64).sqrt(),
                p.tau_s,
            )
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_core::flicker::{psd_at_1hz_from_bias_instability, Flicker, FlickerParams};
    use gyroemu_core::noise::NoiseRng;
    use gyroemu_core::{f64x4, Stage};

    fn white(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
        let mut rng = NoiseRng::new([seed, seed + 1, seed + 2, seed + 3]);
        let mut v = Vec::with_capacity(n);
        while v.len() < n {
            let (a, b) = rng.normal_pair();
            v.extend(
                a.to_array()
                    .iter()
                    .chain(b.to_array().iter())
                    .map(|x| x * sigma),
            );
        }
        v.truncate(n);
        v
    }

    /// The textbook definition, written directly (non-overlapping means recomputed per pair).
    fn naive_overlapping(y: &[f64], m: usize) -> f64 {
        let mean = |s: &[f64]| s.iter().sum::<f64>() / s.len() as f64;
        let terms = y.len() - 2 * m + 1;
        let acc: f64 = (0..terms)
            .map(|k| (mean(&y[k + m..k + 2 * m]) - mean(&y[k..k + m])).powi(2))
            .sum();
        (acc / (2.0 * terms as f64)).sqrt()
    }

    #[test]
    fn matches_the_naive_definition() {
        let y = white(2000, 1.0, 5);
        for p in overlapping_adev(&y, 0.5, 5) {
            let m = (p.tau_s / 0.5).round() as usize;
            let r = naive_overlapping(&y, m);
            assert!((p.adev / r - 1.0).abs() < 1e-10, "m = {m}");
        }
    }

    #[test]
    fn white_noise_has_slope_minus_half_and_the_textbook_level() {
        // White noise of variance s^2 at tau0: sigma(m tau0) = s / sqrt(m) (the variance of a
        // difference of two independent means of m samples, halved).
        let s = 0.3;
        let y = white(400_000, s, 9);
        let curve = overlapping_adev(&y, 0.01, 4);
        for p in curve.iter().filter(|p| p.tau_s <= 10.0) {
            let m = p.tau_s / 0.01;
            let expected = s / m.sqrt();
            // Relative uncertainty of an overlapping Allan deviation with white noise is about
            // 1/sqrt(N/m) (conservative, no overlap credit): 5 of those.
            let tol = 5.0 / (400_000.0 / m).sqrt();
            assert!(
                (p.adev / expected - 1.0).abs() < tol,
                "tau {} adev {} expected {expected}",
                p.tau_s,
                p.adev
            );
        }
        let r = noise_readings(&curve).unwrap();
        // N = s sqrt(tau0) deg/s*sqrt(s): ARW = 60 N.
        let n_expected = s * 0.01f64.sqrt();
        assert!((r.arw_deg_per_rt_h / (60.0 * n_expected) - 1.0).abs() < 0.03);
    }

    #[test]
    fn bias_instability_reads_the_reliable_smoothed_minimum() {
        // A synthetic curve, tau0 = 1 s, one record of 10 000 samples (m up to a third of it):
        // a floor of 2 from tau = 10 s on with a dip to 0.5 in the last points (n_terms / m
        // < 40 from m = 240 on).
        let curve: Vec<AllanPoint> = (0..29)
            .map(|i| {
                let m = 10f64.powf(i as f64 / 8.0).round();
                let adev = if m < 10.0 {
                    2.0 * (10.0 / m).sqrt()
                } else if m >= 300.0 {
                    0.5
                } else {
                    2.0
                };
                AllanPoint {
                    tau_s: m,
                    adev,
                    n_terms: 10_000 - 2 * m as usize + 1,
                }
            })
            .collect();
        let r = noise_readings(&curve).unwrap();
        assert!(
            (r.bias_instability_deg_per_h / 3600.0 * ADEV_PER_BIAS_INSTABILITY - 2.0).abs() < 1e-12
        );
        assert!(
            r.tau_at_min_s >= 10.0 && r.tau_at_min_s <= 200.0,
            "{}",
            r.tau_at_min_s
        );
        // With no point reliable the whole curve counts: the dip is the minimum.
        let short: Vec<AllanPoint> = curve
            .iter()
            .map(|p| AllanPoint { n_terms: 10, ..*p })
            .collect();
        let r = noise_readings(&short).unwrap();
        assert!(
            (r.bias_instability_deg_per_h / 3600.0 * ADEV_PER_BIAS_INSTABILITY - 0.5).abs() < 1e-12
        );
    }

    #[test]
    fn bias_instability_of_a_flicker_floor_is_its_b() {
        // Rate = white (ARW 0.05 deg/sqrt(h)) + flicker of bias instability B = 10 deg/h
        // (one-sided B^2 / (pi f) from 1e-4 Hz to Nyquist), tau0 = 0.01 s, four 1000 s
        // records pooled as selfcal pools them; 16 independent runs. The white part meets the
        // floor at tau = (N / 0.664 B)^2 = 0.2 s, so the curve is flat from a few s to the end.
        // Each reading scatters by about 6 % (its points have relative standard errors up to
        // 10 %), and the minimum of a scattered flat curve reads low by about that scatter:
        // the mean of 16 within -10 % .. +5 % of B, each within 25 %.
        let (tau0, n) = (0.01f64, 100_000usize);
        let b_dps = 10.0 / 3600.0;
        let sigma_white = 0.05 / 60.0 / tau0.sqrt();
        let p = FlickerParams {
            fs_hz: 1.0 / tau0,
            psd_at_1hz: psd_at_1hz_from_bias_instability(b_dps),
            f_lo_hz: 1e-4,
            f_hi_hz: 50.0,
        };
        // (`raw`, the minimum of the whole curve the reading used to take, is printed for the
        // record: it falls for the dips of the last, barely averaged points.)
        let (mut new, mut raw) = (Vec::new(), Vec::new());
        for run in 0..16u64 {
            let mut rng = NoiseRng::new(core::array::from_fn(|l| 500 + 4 * run + l as u64));
            let mut f = Flicker::<f64x4>::stationary(&p, || rng.normal_pair().0).unwrap();
            let mut lanes: [Vec<f64>; 4] = core::array::from_fn(|_| Vec::with_capacity(n));
            for _ in 0..n {
                let (a, b) = rng.normal_pair();
                let y = (f.tick(a) + b * f64x4::splat(sigma_white)).to_array();
                lanes.iter_mut().zip(y).for_each(|(l, v)| l.push(v));
            }
            let curves: Vec<Vec<AllanPoint>> =
                lanes.iter().map(|y| overlapping_adev(y, tau0, 8)).collect();
            let pooled: Vec<AllanPoint> = (0..curves[0].len())
                .map(|j| AllanPoint {
                    tau_s: curves[0][j].tau_s,
                    adev: (curves.iter().map(|c| c[j].adev.powi(2)).sum::<f64>() / 4.0).sqrt(),
                    n_terms: curves.iter().map(|c| c[j].n_terms).sum(),
                })
                .collect();
            let r = noise_readings(&pooled).unwrap();
            let ratio = r.bias_instability_deg_per_h / 10.0;
            assert!(
                (ratio - 1.0).abs() < 0.25,
                "run {run}: B read {ratio} x true"
            );
            new.push(ratio);
            let min = pooled.iter().map(|p| p.adev).fold(f64::INFINITY, f64::min);
            raw.push(min / ADEV_PER_BIAS_INSTABILITY / b_dps);
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        eprintln!(
            "B read / true: mean {:.3} (raw minimum of the whole curve: {:.3})",
            mean(&new),
            mean(&raw)
        );
        assert!(mean(&new) > 0.90 && mean(&new) < 1.05, "{new:?}");
    }
}
