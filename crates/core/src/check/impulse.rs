//! The linear checks, on the impulse response of one real path through a stage: its DFT
//! against [`Response`], and its DC group delay against `latency_samples`.

use crate::Response;
use core::f64::consts::TAU;
use num_complex::Complex64;
use rustfft::FftPlanner;

/// A closure `f_hz -> H(f)` as a [`Response`]: for a path whose exact response is not a
/// stage's own (a plant's steady-state solve, a stage's response times a known delay).
#[derive(Clone, Copy, Debug)]
pub struct FnResponse<F>(pub F);

impl<F: Fn(f64) -> Complex64> Response for FnResponse<F> {
    fn response(&self, f_hz: f64) -> Complex64 {
        (self.0)(f_hz)
    }
}

/// Checks that the `n`-point DFT of the impulse response of `adapter` equals
/// `response.response(f)` at every bin `f = k fs/n` (bins past `n/2` as the negative
/// frequencies `(k - n) fs/n`), magnitude and phase: `|DFT[k] - H(f)| <= tol * peak`, with
/// `peak` the largest `|H|` over the bins. Returns the worst `|DFT[k] - H(f)| / peak`.
///
/// `adapter` is one real path through a fresh stage, fed the unit impulse `1, 0, 0, ...`;
/// it is run for `3 n` samples and the tail must show the truncation negligible: the sum of
/// `|h|` over samples `n..2n` at most `tol * peak / 8` (the DFT differs from the response
/// by at most the sum of the tail, twice that when the tail halves every `n` samples) and the
/// sum over `2n..3n` at most half of it (or both at the rounding floor, `1e-9` of the
/// allowance); otherwise it panics asking for a longer `n`. Panics at the worst bin,
/// naming its frequency and both complex values (magnitude and phase).
pub fn response_matches_impulse(
    name: &str,
    fs_hz: f64,
    response: &impl Response,
    mut adapter: impl FnMut(f64) -> f64,
    n: usize,
    tol: f64,
) -> f64 {
    const CHECK: &str = "response_matches_impulse";
    let h = impulse(name, CHECK, &mut adapter, n);
    let freqs: Vec<f64> = (0..n).map(|k| bin_hz(k, n, fs_hz)).collect();
    let want: Vec<Complex64> = freqs.iter().map(|&f| response.response(f)).collect();
    let peak = want.iter().map(|v| v.norm()).fold(0.0, f64::max);
    if !(peak.is_finite() && peak > 0.0) {
        panic!("{name}: {CHECK}: the response's peak gain over the bins is {peak}, nothing to compare against");
    }
    let (t1, t2) = tails(&h, n);
    require_decay(name, CHECK, n, t1, t2, 2.0 * t1, 0.25 * tol * peak);
    let mut dft: Vec<Complex64> = h[..n].iter().map(|&v| Complex64::new(v, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut dft);
    let (k, err) = dft
        .iter()
        .zip(&want)
        .map(|(a, b)| (a - b).norm())
        .enumerate()
        .fold(
            (0, 0.0),
            |w, (k, e)| if e > w.1 || e.is_nan() { (k, e) } else { w },
        );
    if !within(err, tol * peak) {
        let polar =
            |v: Complex64| format!("{v} (|.| {:e}, arg {} deg)", v.norm(), v.arg().to_degrees());
        panic!(
            "{name}: {CHECK}: at f = {} Hz (bin {k} of {n}, fs = {fs_hz} Hz): the DFT of the \
             impulse response is {}, the response is {}; |difference| = {err:e} > tol {tol:e} \
             x peak gain {peak:e}",
            freqs[k],
            polar(dft[k]),
            polar(want[k])
        );
    }
    err / peak
}

/// Checks that `latency_samples` (a stage's [`crate::Stage::latency_samples`]) equals the DC
/// group delay of the impulse response of `adapter`, `sum n h[n] / sum h[n]` over `n`
/// samples, within `tol_samples`; returns the measured delay.
///
/// For a real impulse response that sum is exactly `-d arg H / d omega` at DC. `adapter` is
/// fed `1, 0, 0, ...` for `3 n` samples; the tail must halve from samples `n..2n` to `2n..3n`
/// and be small enough that truncating at `n` moves the delay by at most `tol_samples / 2`
/// (bounded by `(6 n + 2 |delay|) sum_{n..2n} |h| / |sum h|`), else it panics asking for a
/// longer `n`. Panics if the path has no DC gain (no DC group delay).
pub fn latency_matches(
    name: &str,
    latency_samples: f64,
    mut adapter: impl FnMut(f64) -> f64,
    n: usize,
    tol_samples: f64,
) -> f64 {
    const CHECK: &str = "latency_matches";
    let h = impulse(name, CHECK, &mut adapter, n);
    let s0: f64 = h[..n].iter().sum();
    let s1: f64 = h[..n].iter().enumerate().map(|(i, v)| i as f64 * v).sum();
    if !(s0.is_finite() && s0 != 0.0) {
        panic!("{name}: {CHECK}: the impulse response sums to {s0} (DC gain): no DC group delay; choose a path with a DC gain");
    }
    let tau = s1 / s0;
    let (t1, t2) = tails(&h, n);
    // Beyond n the m-th block of n samples sums to at most t1 / 2^(m-1), its indices are
    // below (m + 1) n: sum_{i >= n} i |h_i| <= 6 n t1 and sum_{i >= n} |h_i| <= 2 t1.
    let bound = (6.0 * n as f64 + 2.0 * tau.abs()) * t1 / s0.abs();
    require_decay(name, CHECK, n, t1, t2, bound, 0.5 * tol_samples);
    if !within((tau - latency_samples).abs(), tol_samples) {
        panic!(
            "{name}: {CHECK}: latency_samples() = {latency_samples}, but the DC group delay of \
             the impulse response (sum n h[n] / sum h[n] over {n} samples) is {tau}; \
             difference {:e} > {tol_samples:e} samples",
            (tau - latency_samples).abs()
        );
    }
    tau
}

/// Checks that `latency_samples` equals the phase slope of `response` at DC,
/// `-d arg H / d omega` in samples, within `tol_samples`; returns the measured slope.
///
/// The slope is the centred difference `D(w) = -arg(H(w) / H(-w)) / (2 w)` (exact for a
/// linear phase, error `O(w^2)` otherwise), Richardson-extrapolated as
/// `(4 D(w/2) - D(w)) / 3` (error `O(w^4)`), at `w = 1e-4 / max(1, |delay|)` rad/sample: a
/// phase of about `1e-4` rad, far inside the linear range and far above its rounding.
/// Panics if the DC gain is zero or not finite.
pub fn latency_matches_response(
    name: &str,
    latency_samples: f64,
    fs_hz: f64,
    response: &impl Response,
    tol_samples: f64,
) -> f64 {
    const CHECK: &str = "latency_matches_response";
    let dc = response.response(0.0);
    if !(dc.norm().is_finite() && dc.norm() > 0.0) {
        panic!("{name}: {CHECK}: the DC gain is {dc}: no DC group delay");
    }
    let slope = |w: f64| {
        let f = w * fs_hz / TAU;
        -(response.response(f) / response.response(-f)).arg() / (2.0 * w)
    };
    let extrapolated = |w: f64| (4.0 * slope(0.5 * w) - slope(w)) / 3.0;
    let first = extrapolated(1e-4 / latency_samples.abs().max(1.0));
    let w = 1e-4 / latency_samples.abs().max(first.abs()).max(1.0);
    let tau = extrapolated(w);
    if !within((tau - latency_samples).abs(), tol_samples) {
        panic!(
            "{name}: {CHECK}: latency_samples() = {latency_samples}, but the phase slope of the \
             response at DC (probed at +-{} Hz, fs = {fs_hz} Hz) is {tau} samples; difference \
             {:e} > {tol_samples:e} samples",
            w * fs_hz / TAU,
            (tau - latency_samples).abs()
        );
    }
    tau
}

/// `err <= tol`, false for a NaN error (which must fail a check, not pass it).
fn within(err: f64, tol: f64) -> bool {
    err <= tol
}

/// The signed frequency of DFT bin `k` of `n`: `k fs/n` up to `n/2`, `(k - n) fs/n` above.
fn bin_hz(k: usize, n: usize, fs_hz: f64) -> f64 {
    let k = if 2 * k <= n {
        k as f64
    } else {
        k as f64 - n as f64
    };
    k * fs_hz / n as f64
}

/// The first `3 n` samples of the response of `adapter` to the unit impulse, all finite.
fn impulse(name: &str, check: &str, adapter: &mut impl FnMut(f64) -> f64, n: usize) -> Vec<f64> {
    assert!(n >= 2, "{name}: {check}: n = {n}, need at least 2 samples");
    let h: Vec<f64> = (0..3 * n)
        .map(|i| adapter(if i == 0 { 1.0 } else { 0.0 }))
        .collect();
    if let Some(i) = h.iter().position(|v| !v.is_finite()) {
        panic!("{name}: {check}: impulse response sample {i} is {}", h[i]);
    }
    h
}

/// `sum |h|` over samples `n..2n` and `2n..3n`.
fn tails(h: &[f64], n: usize) -> (f64, f64) {
    let sum = |s: &[f64]| s.iter().map(|v| v.abs()).sum::<f64>();
    (sum(&h[n..2 * n]), sum(&h[2 * n..3 * n]))
}

/// Panics unless the tail decays (halves from `n..2n` to `2n..3n`, or both blocks sit at the
/// rounding floor, `1e-9` of the budget) and the truncation `bound` is within `budget`.
fn require_decay(name: &str, check: &str, n: usize, t1: f64, t2: f64, bound: f64, budget: f64) {
    let decays = t2 <= 0.5 * t1 || t1 + t2 <= 1e-9 * budget;
    if !(decays && bound <= budget) {
        panic!(
            "{name}: {check}: the impulse response has not decayed within n = {n} samples \
             (sum |h| over samples n..2n = {t1:e}, over 2n..3n = {t2:e}; the truncation bound \
             {bound:e} must stay within {budget:e} and the tail must halve every n samples): \
             pass a longer n"
        );
    }
}
