//! Overlapping Allan deviation of a sampled rate (or phase-rate) series, and the two readings
//! gyro engineers take from it (IEEE Std 952): the angle random walk from the -1/2 slope and
//! the bias instability from the flat floor; beside them, the fit of the noise model to the
//! same points ([`fit`]).

pub mod fit;

use fit::{fit_noise_model, NoiseModelFit};

use gyroemu_core::flicker::ADEV_PER_BIAS_INSTABILITY;
use serde::Serialize;

/// deg/sqrt(h) per deg/s*sqrt(s): the readings' angle random walk unit.
const ARW_UNIT: f64 = 60.0;
/// deg/h per deg/s: the readings' bias instability unit.
const B_UNIT: f64 = 3600.0;

/// Independent differences (`n_terms / m`) a point must rest on to enter either reading. With
/// flicker noise an overlapping Allan deviation from them has relative standard error about
/// `0.63 / sqrt(n_terms / m)` (NIST SP 1065, edf `5 N / (4 m)`), so 40 keeps it under 10 %:
/// the last points of a curve (a third of the record, a handful of averages) scatter by 30 %,
/// their dips would pass for the floor and their chance -1/2 pairs for the white region.
const MIN_INDEPENDENT_DIFFERENCES: f64 = 40.0;

/// Half-width, in decades of tau, of the window the floor is smoothed over before its minimum
/// is taken (the minimum of a noisy flat curve reads low by about its scatter).
const FLOOR_SMOOTHING_DECADES: f64 = 0.125;

/// How far a slope may lie from -1/2 for its chord to count as white rate noise.
const ARW_SLOPE_TOLERANCE: f64 = 0.1;

/// The baseline, in decades of tau, of the chords whose slopes are tested against -1/2: twice
/// the 1/8 decade between points, since adjacent points on a few hundred independent
/// differences still give slopes scattered by +-0.1.
const ARW_CHORD_DECADES: f64 = 0.25;

/// The least span, in decades of tau, of the -1/2 chords the angle random walk is read on. A
/// curve passing from one slope to another is within 0.1 of -1/2 over less: from white phase
/// (-1) to a flicker floor (0) over 0.18 decade, where at most two quarter-decade chords pass
/// (together 3/8 decade); chance -1/2 chords of a scattered floor do not run on for half a
/// decade either.
const MIN_ARW_SPAN_DECADES: f64 = 0.5;

/// Without a settling time from the caller, a minimum this close (decades of tau) to a curve's
/// first point is flagged: nothing shows the curve there is past a resonator's or filter's
/// roll-off (a curve can dip at its first point and still be rising to its floor).
const FIRST_POINTS_DECADES: f64 = 0.5;

/// The reliable curve's log-log slope over its last half decade below which a minimum at its
/// last point is a curve still falling (white noise: -1/2), not a floor (0).
const STILL_FALLING_SLOPE: f64 = -0.25;

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

/// The readings of an Allan deviation curve of a rate in deg/s. A reading that cannot be
/// trusted is NaN (null in JSON) or carries a warning: never a clean wrong number.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NoiseReadings {
    /// Angle random walk, deg/sqrt(h): the -1/2 line sigma = N / sqrt(tau) read at tau = 1 s
    /// (N in deg/s*sqrt(s), times 60). NaN when the curve has no trustworthy -1/2 region
    /// (`arw_warning` says why).
    pub arw_deg_per_rt_h: f64,
    /// The taus the angle random walk was read over, s (first and last point; NaN without one).
    pub arw_tau_s: [f64; 2],
    /// Why the angle random walk is absent (`None` when it was read).
    pub arw_warning: Option<&'static str>,
    /// Bias instability, deg/h: the flat minimum of the curve divided by 0.664 (the flicker
    /// floor `sqrt(2 ln 2 / pi) B`). Read where the curve is reliable (see
    /// [`noise_readings_settled`]).
    /// NaN when the curve has no minimum past its initial rise.
    pub bias_instability_deg_per_h: f64,
    /// Where the minimum lies, s (NaN without one).
    pub tau_at_min_s: f64,
    /// Why the bias instability is absent, only a bound, or unreliable (`None` when it is the
    /// flat floor of reliable points).
    pub bias_instability_warning: Option<&'static str>,
    /// The noise-model fit (IEEE Std 952 Annex C) over the same reliable points: N, B and K
    /// with 95 % intervals, read even where no -1/2 region shows. `selfcal.json` writes it
    /// beside the readings, as `allan.model_fit`, so `allan.readings` keeps its keys.
    #[serde(skip)]
    pub model_fit: NoiseModelFit,
}

/// Reads ARW and bias instability from an Allan deviation curve of a rate in deg/s (as
/// [`overlapping_adev`] gives it: the first point at tau0, `n_terms` summed over pooled
/// records), with no settling time known: [`noise_readings_settled`] with 0.
pub fn noise_readings(curve: &[AllanPoint]) -> Option<NoiseReadings> {
    noise_readings_settled(curve, 0.0)
}

/// Reads ARW and bias instability from an Allan deviation curve of a rate in deg/s, taking
/// neither below `settled_tau_s` (e.g. ten mechanical time constants of a resonator whose
/// bandwidth rolls the short taus off; 0 when unknown). `None` for fewer than two points.
///
/// Both readings use the points past the curve's initial rise (from the first point whose
/// next point is not higher, and not below `settled_tau_s`) that rest on at least 40
/// independent differences (`n_terms tau0 / tau`: a relative error under 10 %).
///
/// The random-walk coefficient N is read on the lowest-tau run of those points whose
/// quarter-decade chords (each point to the first a quarter decade on) have log-log slopes
/// within 0.1 of -1/2, and which spans at least half a decade: ln(sigma sqrt(tau)) averaged
/// over the run (a least-squares fit of a -1/2 line), each point weighted by the inverse of its
/// variance (from its independent differences) plus the square of its chords' departure from
/// -1/2 (about the relative bias of sigma sqrt(tau) where a roll-off or a floor bends the line),
/// so the well-averaged points on the straightest part count most. Without such a run the ARW
/// is NaN with a warning: a curve with no white-noise region has no ARW to read (the -1/2
/// pairs of a scattered tail, or of a slope crossing -1/2 on its way between others, are not
/// one).
///
/// The bias instability is the flat minimum of the same points: sigma^2 averaged over +-1/8
/// decade of tau, its minimum's square root divided by 0.664. It is NaN with a warning if no
/// point is past the initial rise, and carries a warning when it is only an upper bound (the
/// minimum lies in the reliable curve's last half decade, which may still be falling: see
/// `still_falling`), when no point rests on 40
/// independent differences (then all points past the rise count), or when, with no settling
/// time given, the minimum lies within half a decade of the curve's first point.
///
/// The noise-model fit ([`fit_noise_model`]) takes the same points, past the rise and on 40
/// independent differences or more; it is not made when none of them is.
pub fn noise_readings_settled(curve: &[AllanPoint], settled_tau_s: f64) -> Option<NoiseReadings> {
    if curve.len() < 2 {
        return None;
    }
    let tau0 = curve[0].tau_s;
    let slope = |i: usize, j: usize| {
        let (a, b) = (curve[i], curve[j]);
        (b.adev.ln() - a.adev.ln()) / (b.tau_s.ln() - a.tau_s.ln())
    };
    let independent = |p: &AllanPoint| p.n_terms as f64 * tau0 / p.tau_s;
    // Independent differences fall with tau: the reliable points are a prefix of the curve.
    let reliable_end = curve
        .iter()
        .take_while(|p| independent(p) >= MIN_INDEPENDENT_DIFFERENCES)
        .count();
    let any_reliable = reliable_end > 0;
    let end = if any_reliable {
        reliable_end
    } else {
        curve.len()
    };
    // Past the initial rise (a resonator's or filter's roll-off) and the settling time.
    // (A NaN slope, of a curve of zeros, is no rise.)
    let start = (0..curve.len() - 1)
        .find(|&i| {
            curve[i].tau_s >= settled_tau_s * (1.0 - 1e-12)
                && slope(i, i + 1).partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater)
        })
        .unwrap_or(curve.len());

    let (arw_deg_per_rt_h, arw_tau_s, arw_warning) = match (any_reliable, start < end) {
        (false, _) => (
            f64::NAN,
            [f64::NAN; 2],
            Some(
                "no point of the Allan curve rests on 40 independent differences: the record is \
                 too short to read an angle random walk",
            ),
        ),
        (true, false) => (
            f64::NAN,
            [f64::NAN; 2],
            Some(
                "the Allan curve rises over all its reliable points (40 independent differences \
                 or more): no white-noise (-1/2) region to read an angle random walk from",
            ),
        ),
        (true, true) => match white_run(curve, start, end, &slope) {
            Some((i, j, chords)) => {
                // Each point weighted by the inverse of its error budget in ln(sigma sqrt(tau)):
                // its variance, 1 / (2 edf) with edf no less than its independent differences,
                // plus the square of the slope departure from -1/2 of the run's chords over it
                // (their mean), which is about the relative bias of sigma sqrt(tau) at the
                // run's edges (a roll-off below, a floor above).
                let (mut sw, mut sl) = (0.0, 0.0);
                for (k, p) in curve.iter().enumerate().take(j + 1).skip(i) {
                    let over: Vec<f64> = chords
                        .iter()
                        .filter(|c| c.0 <= k && k <= c.1)
                        .map(|c| c.2 + 0.5)
                        .collect();
                    let off = over.iter().sum::<f64>() / over.len().max(1) as f64;
                    let w = 1.0 / (0.5 / independent(p) + off * off);
                    sw += w;
                    sl += w * (p.adev * p.tau_s.sqrt()).ln();
                }
                (
                    ARW_UNIT * (sl / sw).exp(),
                    [curve[i].tau_s, curve[j].tau_s],
                    None,
                )
            }
            None => (
                f64::NAN,
                [f64::NAN; 2],
                Some(
                    "no half decade of the reliable Allan curve (40 independent differences \
                     or more, past its initial rise) follows the -1/2 slope within 0.1: no \
                     white-noise region to read an angle random walk from",
                ),
            ),
        },
    };

    let (bias_instability_deg_per_h, tau_at_min_s, bias_instability_warning) =
        match flat_minimum(&curve[start.min(end)..end]) {
            None if any_reliable => (
                f64::NAN,
                f64::NAN,
                Some(
                    "the Allan curve rises over all its reliable points (40 independent \
                     differences or more): no floor to read a bias instability from",
                ),
            ),
            None => (
                f64::NAN,
                f64::NAN,
                Some(
                    "the Allan curve rises over all its points, none of which rests on 40 \
                     independent differences: no floor to read a bias instability from",
                ),
            ),
            Some((floor, tau_min)) => {
                let warning = if !any_reliable {
                    Some(
                        "no point of the Allan curve rests on 40 independent differences: the \
                         bias instability is the minimum of scattered points and may read low",
                    )
                } else if start == 0
                    && settled_tau_s <= tau0
                    && (tau_min / tau0).log10() < FIRST_POINTS_DECADES
                {
                    Some(
                        "the Allan minimum lies within half a decade of the curve's first \
                         point, where a resonator's or filter's settling may still roll the \
                         curve off: the bias instability is unreliable and may read low",
                    )
                } else if still_falling(curve, start, end, tau_min, independent) {
                    Some(
                        "the Allan curve may still be falling over the last half decade \
                         of its reliable points (40 independent differences or more), where \
                         its minimum lies: no flat floor was shown, the bias instability is \
                         only an upper bound",
                    )
                } else {
                    None
                };
                (floor / ADEV_PER_BIAS_INSTABILITY * B_UNIT, tau_min, warning)
            }
        };
    let model_fit = match (any_reliable, start < end) {
        (false, _) => NoiseModelFit::not_fitted(
            "no point of the Allan curve rests on 40 independent differences: the record is \
             too short to fit the noise model",
        ),
        (true, false) => NoiseModelFit::not_fitted(
            "the Allan curve rises over all its reliable points (40 independent differences \
             or more): nothing past its initial rise to fit the noise model to",
        ),
        (true, true) => fit_noise_model(&curve[start..end], tau0, start > 0),
    };
    Some(NoiseReadings {
        arw_deg_per_rt_h,
        arw_tau_s,
        arw_warning,
        bias_instability_deg_per_h,
        tau_at_min_s,
        bias_instability_warning,
        model_fit,
    })
}

/// A chord of the curve: first and last point, slope.
type Chord = (usize, usize, f64);

/// The lowest-tau white region among the points `start..end`: the consecutive chords (from
/// each point to the first a quarter decade on, [`ARW_CHORD_DECADES`]) whose slopes lie within
/// [`ARW_SLOPE_TOLERANCE`] of -1/2, together spanning [`MIN_ARW_SPAN_DECADES`]. Returns its
/// first and last point and its chords.
fn white_run(
    curve: &[AllanPoint],
    start: usize,
    end: usize,
    slope: &dyn Fn(usize, usize) -> f64,
) -> Option<(usize, usize, Vec<Chord>)> {
    let chord = |i: usize| -> Option<Chord> {
        let j = (i + 1..end)
            .find(|&j| (curve[j].tau_s / curve[i].tau_s).log10() >= ARW_CHORD_DECADES - 1e-9)?;
        Some((i, j, slope(i, j)))
    };
    let white = |c: &Chord| (c.2 + 0.5).abs() < ARW_SLOPE_TOLERANCE;
    let mut run: Vec<Chord> = Vec::new();
    for i in start..end {
        match chord(i).filter(white) {
            Some(c) => run.push(c),
            None => run.clear(),
        }
        if let (Some(first), Some(last)) = (run.first(), run.last()) {
            let (a, b) = (first.0, last.1);
            let next_white = chord(i + 1).filter(white).is_some();
            if !next_white
                && (curve[b].tau_s / curve[a].tau_s).log10() >= MIN_ARW_SPAN_DECADES - 1e-9
            {
                return Some((a, b, run));
            }
        }
    }
    None
}

/// Whether a minimum at `tau_min`, within the last half decade of `start..end`, lies on a curve
/// that may still be falling there: the chord over that half decade (at least from the point
/// before) steeper than [`STILL_FALLING_SLOPE`] less one standard error of the chord. Each
/// end's ln sigma has a variance of at most 1 / (2 x its independent differences), so at 40 of
/// them the chord scatters by about 0.1: judged on the bare chord, a curve expected to fall at
/// -0.30 passed as a floor in about half the records (readings of 1.2 to 1.7 B, unflagged),
/// while a true floor is flagged by chance in about 8 % (a warning, not a refusal).
fn still_falling(
    curve: &[AllanPoint],
    start: usize,
    end: usize,
    tau_min: f64,
    independent: impl Fn(&AllanPoint) -> f64,
) -> bool {
    let last = end - 1;
    if last == start || (curve[last].tau_s / tau_min).log10() > 0.5 + 1e-9 {
        return false;
    }
    let from = (start..last)
        .find(|&k| (curve[last].tau_s / curve[k].tau_s).log10() <= 0.5 + 1e-9)
        .unwrap_or(last - 1);
    let (a, b) = (curve[from], curve[last]);
    let span = b.tau_s.ln() - a.tau_s.ln();
    let slope = (b.adev.ln() - a.adev.ln()) / span;
    let se = (0.5 / independent(&a) + 0.5 / independent(&b)).sqrt() / span;
    slope < STILL_FALLING_SLOPE + se
}

/// The flat minimum of `pts` and where it lies: sigma^2 smoothed over +-1/8 decade of tau
/// (see [`noise_readings_settled`]). `None` for no point.
fn flat_minimum(pts: &[AllanPoint]) -> Option<(f64, f64)> {
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
        assert_eq!((r.arw_tau_s[0], r.arw_warning), (0.01, None));
        // The curve never flattens: its minimum only bounds a bias instability, and says so.
        assert!(r.bias_instability_warning.is_some());
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
        assert_eq!(r.bias_instability_warning, None);
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
        // ... flagged, and no ARW read from such points.
        assert!(r.bias_instability_warning.is_some());
        assert!(r.arw_deg_per_rt_h.is_nan() && r.arw_warning.is_some());
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

    #[test]
    fn a_curve_still_falling_gently_at_its_end_is_flagged_as_an_upper_bound() {
        // White + flicker of B = 10 deg/h whose white part still holds about half of sigma^2
        // at the last reliable tau (it meets the floor at N^2 / (0.664 B)^2 = 7 s; one 300 s
        // record at tau0 = 0.01 s is reliable up to 7.5 s): the expected curve still falls at
        // about -0.3 there, and the minimum reads B times sqrt(1 + 7 / 7.5) = 1.4 B or more.
        let (tau0, n) = (0.01f64, 30_000usize);
        let b_dps = 10.0 / 3600.0;
        let arw = ADEV_PER_BIAS_INSTABILITY * b_dps * 7f64.sqrt();
        let p = FlickerParams {
            fs_hz: 1.0 / tau0,
            psd_at_1hz: psd_at_1hz_from_bias_instability(b_dps),
            f_lo_hz: 1e-4,
            f_hi_hz: 50.0,
        };
        let readings = |arw: f64| -> Vec<(f64, bool)> {
            (0..16u64)
                .map(|run| {
                    let mut rng = NoiseRng::new(core::array::from_fn(|l| 900 + 4 * run + l as u64));
                    let mut f = Flicker::<f64x4>::stationary(&p, || rng.normal_pair().0).unwrap();
                    let y: Vec<f64> = (0..n)
                        .map(|_| {
                            let (a, b) = rng.normal_pair();
                            (f.tick(a) + b * f64x4::splat(arw / tau0.sqrt())).to_array()[0]
                        })
                        .collect();
                    let r = noise_readings(&overlapping_adev(&y, tau0, 8)).unwrap();
                    (
                        r.bias_instability_deg_per_h / 10.0,
                        r.bias_instability_warning.is_some(),
                    )
                })
                .collect()
        };
        // The bare chord at the end let every one of these through unflagged (1.36 to 1.67 B).
        let falling = readings(arw);
        assert!(falling.iter().all(|&(b, w)| b > 1.2 && w), "{falling:?}");
        // White noise meeting the floor at 0.07 s: flat over two decades before the end. The
        // flag costs a true floor a chance warning in about 8 % of records.
        let flat = readings(arw / 10.0);
        let flagged = flat.iter().filter(|r| r.1).count();
        eprintln!("a true floor: {flagged} of 16 records flagged");
        assert!(flagged <= 3, "{flat:?}");
        assert!(flat.iter().all(|r| (r.0 - 1.0).abs() < 0.3), "{flat:?}");
    }
}
