//! How an averaging window of span `T` weighs a fluctuation `u / T` away from what it reads,
//! and the quadrature over decades the noise rules integrate such weights with; shared by
//! the slow flicker's rule and a rate table's harmonics' noise.

/// The window's weight `K(u)`: the boxcar's `sinc^2(u)`, or with `hann` the mean-normalised
/// Hann window's `(sinc(u) + sinc(u - 1) / 2 + sinc(u + 1) / 2)^2` (1 at 0; its integral is
/// the window's noise bandwidth, 1 or 1.5); from |u| = 4 on its mean over the oscillation,
/// where a quadrature grid would alias it: `1 / (2 pi^2 u^2)` for the boxcar,
/// `1 / (2 pi^2 u^2 (u^2 - 1)^2)` for Hann.
pub(crate) fn window_weight(u: f64, hann: bool) -> f64 {
    use core::f64::consts::PI;
    let u = u.abs();
    match (u >= 4.0, hann) {
        (true, false) => 1.0 / (2.0 * PI.powi(2) * u * u),
        (true, true) => 1.0 / (2.0 * PI.powi(2) * u * u * (u * u - 1.0).powi(2)),
        (false, false) => sinc(u).powi(2),
        (false, true) => (sinc(u) + 0.5 * sinc(u - 1.0) + 0.5 * sinc(u + 1.0)).powi(2),
    }
}

/// `sin(pi u) / (pi u)`, 1 at 0.
fn sinc(u: f64) -> f64 {
    if u.abs() < 1e-9 {
        1.0
    } else {
        let x = core::f64::consts::PI * u;
        x.sin() / x
    }
}

/// `start + int_a^b f(x) dx` by the trapezoid rule in ln x, 64 points a decade (`f(x) x`
/// against `ln x`), each step added to `start` in turn: for integrands over decades of
/// frequency, such as a window's `1/u^2` sidelobes or a `1/f` density. `start` unless
/// `0 < a < b`.
pub(crate) fn integrate_over_decades(start: f64, a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    if !(a > 0.0 && b > a) {
        return start;
    }
    let g = |x: f64| f(x) * x;
    let steps = ((b / a).log10() * 64.0).ceil().max(1.0) as usize;
    let dl = (b / a).ln() / steps as f64;
    let mut sum = start;
    let mut prev = g(a);
    for i in 1..=steps {
        let cur = g(a * (dl * i as f64).exp());
        sum += 0.5 * (prev + cur) * dl;
        prev = cur;
    }
    sum
}
