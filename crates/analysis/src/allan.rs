//! Overlapping Allan deviation of a sampled rate (or phase-rate) series, and the two readings
//! gyro engineers take from it (IEEE Std 952): the angle random walk from the -1/2 slope and
//! the bias instability from the flat floor.

use serde::Serialize;

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
    /// Bias instability, deg/h: the minimum of the curve divided by 0.664 (flicker floor).
    pub bias_instability_deg_per_h: f64,
    /// Where the minimum lies, s.
    pub tau_at_min_s: f64,
}

/// Reads ARW and bias instability from an Allan deviation curve of a rate in deg/s. The
/// random-walk coefficient N is the median of sigma*sqrt(tau) over the points whose local
/// log-log slope is within 0.1 of -1/2 (the white-noise region), or over the first third of
/// the curve if none is.
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
    let min = curve.iter().min_by(|a, b| a.adev.total_cmp(&b.adev))?;
    Some(NoiseReadings {
        arw_deg_per_rt_h: 60.0 * n_coef,
        bias_instability_deg_per_h: min.adev / 0.664 * 3600.0,
        tau_at_min_s: min.tau_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_core::noise::NoiseRng;

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
}
