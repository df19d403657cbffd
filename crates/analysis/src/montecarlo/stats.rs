//! The statistics of a lot: percentiles (linear between order statistics), mean and sample
//! standard deviation, and the Wilson score interval of a yield.

use serde::Serialize;

/// The percentiles a lot reports, %.
pub const PERCENTILES: [f64; 5] = [1.0, 5.0, 50.0, 95.0, 99.0];

/// The two-sided 95 % quantile of the standard normal, Phi^-1(0.975).
pub const Z95: f64 = 1.959_963_984_540_053_6;

/// Percentile `p` (0 to 100) of `sorted` (ascending, finite): linear interpolation between
/// the order statistics at rank `(n - 1) p / 100` (Hyndman and Fan's definition 7, numpy's
/// default). NaN for no values.
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    let n = sorted.len();
    if n == 0 {
        return f64::NAN;
    }
    let h = (n - 1) as f64 * p / 100.0;
    let lo = (h.floor() as usize).min(n - 1);
    let hi = (lo + 1).min(n - 1);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

/// The Wilson score interval of a proportion of `k` successes in `n` trials at the 95 %
/// level: `(p + z^2/2n -+ z sqrt(p (1 - p)/n + z^2/4n^2)) / (1 + z^2/n)`. It stays inside
/// [0, 1] and is not empty at k = 0 or k = n, where the plain normal interval fails.
/// `(NaN, NaN)` for `n = 0`.
pub fn wilson_interval(k: usize, n: usize) -> (f64, f64) {
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let (k, n) = (k as f64, n as f64);
    let p = k / n;
    let z2 = Z95 * Z95;
    let centre = p + z2 / (2.0 * n);
    let half = Z95 * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    let d = 1.0 + z2 / n;
    // At k = 0 (k = n) the lower (upper) end is exactly 0 (1); rounding left 3.3e-18.
    let lo = if k == 0.0 { 0.0 } else { (centre - half) / d };
    let hi = if k == n { 1.0 } else { (centre + half) / d };
    (lo.max(0.0), hi.min(1.0))
}

/// How a set of values (the finite ones) is spread.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spread {
    /// Values counted.
    pub n: usize,
    pub mean: f64,
    /// Sample standard deviation (n - 1 in the denominator; NaN below two values).
    pub std: f64,
    pub min: f64,
    pub max: f64,
    /// [`PERCENTILES`] of the signed values, as (percent, value).
    pub percentiles: Vec<(f64, f64)>,
    /// [`PERCENTILES`] of the absolute values.
    pub abs_percentiles: Vec<(f64, f64)>,
}

impl Spread {
    /// The spread of the finite values of `values`.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Self {
        let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let mean = if n == 0 {
            f64::NAN
        } else {
            v.iter().sum::<f64>() / n as f64
        };
        let std = if n < 2 {
            f64::NAN
        } else {
            (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64).sqrt()
        };
        let mut a: Vec<f64> = v.iter().map(|x| x.abs()).collect();
        a.sort_by(f64::total_cmp);
        let table = |s: &[f64]| PERCENTILES.iter().map(|&p| (p, percentile(s, p))).collect();
        Self {
            n,
            mean,
            std,
            min: v.first().copied().unwrap_or(f64::NAN),
            max: v.last().copied().unwrap_or(f64::NAN),
            percentiles: table(&v),
            abs_percentiles: table(&a),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_interpolate_between_order_statistics() {
        // numpy.percentile([1, 2, 3, 4], [0, 25, 50, 90, 100]) = 1, 1.75, 2.5, 3.7, 4.
        let v = [1.0, 2.0, 3.0, 4.0];
        for (p, want) in [
            (0.0, 1.0),
            (25.0, 1.75),
            (50.0, 2.5),
            (90.0, 3.7),
            (100.0, 4.0),
        ] {
            assert!((percentile(&v, p) - want).abs() < 1e-15, "{p}");
        }
        assert_eq!(percentile(&[7.0], 99.0), 7.0);
        assert!(percentile(&[], 50.0).is_nan());
    }

    #[test]
    fn spread_of_a_hand_computed_set() {
        // -3, -1, 2, 6 (and a NaN, skipped): mean 1, deviations -4 -2 1 5, sum of squares
        // 46, sample variance 46/3; |v| sorted 1 2 3 6.
        let s = Spread::of([2.0, -3.0, f64::NAN, 6.0, -1.0]);
        assert_eq!(s.n, 4);
        assert_eq!(s.mean, 1.0);
        assert!((s.std - (46.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert_eq!((s.min, s.max), (-3.0, 6.0));
        // Rank 3 * 0.5 = 1.5 -> halfway between -1 and 2; |v|: between 2 and 3.
        assert_eq!(s.percentiles[2], (50.0, 0.5));
        assert_eq!(s.abs_percentiles[2], (50.0, 2.5));
        // Rank 3 * 0.95 = 2.85 -> 2 + 0.85 * (6 - 2) = 5.4; |v|: 3 + 0.85 * 3 = 5.55.
        assert!((s.percentiles[3].1 - 5.4).abs() < 1e-14);
        assert!((s.abs_percentiles[3].1 - 5.55).abs() < 1e-14);
    }

    #[test]
    fn wilson_interval_matches_hand_values() {
        // 95 of 100: p = 0.95, z^2 = 3.841459; centre (0.95 + 0.019207) / 1.038415 =
        // 0.933353, half 1.959964 sqrt(0.000475 + 0.0000960365) / 1.038415 = 0.045103
        // (statsmodels' proportion_confint(95, 100, method="wilson"): 0.88825, 0.97846).
        let (lo, hi) = wilson_interval(95, 100);
        assert!((lo - 0.888_250).abs() < 1e-6, "{lo}");
        assert!((hi - 0.978_456).abs() < 1e-6, "{hi}");
        // All pass: the upper end is 1, the lower n / (n + z^2).
        let (lo, hi) = wilson_interval(10, 10);
        assert!((lo - 10.0 / (10.0 + Z95 * Z95)).abs() < 1e-12 && hi == 1.0);
        let (lo, hi) = wilson_interval(0, 10);
        assert!(lo == 0.0 && (hi - Z95 * Z95 / (10.0 + Z95 * Z95)).abs() < 1e-12);
        // Exactly 0 at every size (80 had read 3.3e-18, printed as 3.310e-16 %).
        for n in [1, 7, 80, 1000, 123_457] {
            assert_eq!(wilson_interval(0, n).0, 0.0, "{n}");
            assert_eq!(wilson_interval(n, n).1, 1.0, "{n}");
        }
        assert!(wilson_interval(0, 0).0.is_nan());
        // Z95 is the normal quantile: the upper tail 1 - Phi(Z95) = 0.025 by the
        // Abramowitz-Stegun 26.2.17 approximation (|error| < 7.5e-8).
        let x = Z95;
        let t = 1.0 / (1.0 + 0.231_641_9 * x);
        let poly = t
            * (0.319_381_530
                + t * (-0.356_563_782
                    + t * (1.781_477_937 + t * (-1.821_255_978 + t * 1.330_274_429))));
        let tail = (-x * x / 2.0).exp() / (2.0 * std::f64::consts::PI).sqrt() * poly;
        assert!((tail - 0.025).abs() < 1e-7, "{tail}");
    }
}
