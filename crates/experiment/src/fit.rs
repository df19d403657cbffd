//! Least-squares straight line, as the paper's "best linear fit".

use serde::Serialize;

/// y = slope * x + intercept, with the coefficient of determination and the standard error
/// of the slope (from the residual scatter, n - 2 degrees of freedom; NaN with 2 points).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LineFit {
    pub slope: f64,
    pub intercept: f64,
    pub r2: f64,
    pub slope_std_err: f64,
}

/// Ordinary least squares (centred sums, so large offsets do not cancel digits). Needs at
/// least two distinct x; otherwise returns NaN slope.
pub fn fit_line(x: &[f64], y: &[f64]) -> LineFit {
    let n = x.len().min(y.len()) as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (&a, &b) in x.iter().zip(y) {
        sxx += (a - mx) * (a - mx);
        sxy += (a - mx) * (b - my);
        syy += (b - my) * (b - my);
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    // At most 1 by Cauchy-Schwarz (sxy^2 <= sxx syy); its rounding can pass 1 by an ulp on
    // a near-exact line, a value no results file should hold. NaN (a refused phase, or one
    // x) stays NaN: `f64::min` would make it a perfect fit. Without a line (one rate, or a
    // NaN among the readings) there is no fit to score: it had read 1 beside a null slope.
    let r2 = if !slope.is_finite() {
        f64::NAN
    } else if syy == 0.0 {
        1.0
    } else {
        let r2 = sxy * sxy / (sxx * syy);
        if r2 > 1.0 {
            1.0
        } else {
            r2
        }
    };
    let rss: f64 = x
        .iter()
        .zip(y)
        .map(|(&a, &b)| (b - intercept - slope * a).powi(2))
        .sum();
    let slope_std_err = if n > 2.0 {
        (rss / (n - 2.0) / sxx).sqrt()
    } else {
        f64::NAN
    };
    LineFit {
        slope,
        intercept,
        r2,
        slope_std_err,
    }
}

/// Two-sided 95 % quantile of Student's t with `dof` degrees of freedom (the half-width of a
/// 95 % confidence interval in standard errors); the normal 1.96 beyond 30.
pub fn t95(dof: usize) -> f64 {
    const T: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
        2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
        2.052, 2.048, 2.045, 2.042,
    ];
    match dof {
        0 => f64::INFINITY,
        d if d <= 30 => T[d - 1],
        _ => 1.96,
    }
}

/// `ys` (degrees, at `xs`), each moved by whole `period`s to within half a period of where
/// the reading at the next smaller x plus the theory's continuous change between the two
/// puts it, for the line fit. The change is the theory followed along x in steps it moves by
/// under an eighth of a period (at least 32 of them), so a genuine step of more than a
/// quarter turn between two rates stays: [`unwrapped_along`] alone moved psi's -53.1 ->
/// +53.1 deg between -100 and 100 deg/s (Q = 36000) down a half turn, and the summary's
/// slope read -0.19 for +0.42. Where the theory is not finite along the way, as
/// [`unwrapped_along`].
pub fn unwrapped_along_theory(
    xs: &[f64],
    ys: &[f64],
    period: f64,
    theory: &dyn Fn(f64) -> f64,
) -> Vec<f64> {
    let mut order: Vec<usize> = (0..xs.len().min(ys.len())).collect();
    order.sort_by(|&a, &b| xs[a].total_cmp(&xs[b]));
    let mut out = ys.to_vec();
    let mut prev: Option<(f64, f64)> = None;
    for i in order {
        let y = ys[i];
        if !y.is_finite() {
            continue;
        }
        let moved = match prev {
            Some((px, py)) => {
                let step = theory_change(theory, px, xs[i], period).unwrap_or(0.0);
                let k = ((py + step - y) / period).round();
                if k == 0.0 {
                    y
                } else {
                    y + k * period
                }
            }
            None => y,
        };
        out[i] = moved;
        prev = Some((xs[i], moved));
    }
    out
}

/// The continuous change of `theory` from `x0` to `x1` (a function known modulo `period`):
/// the sum of its wrapped steps over a path fine enough that each is under an eighth of a
/// period. `None` where it is not finite on the way.
fn theory_change(theory: &dyn Fn(f64) -> f64, x0: f64, x1: f64, period: f64) -> Option<f64> {
    fn walk(
        theory: &dyn Fn(f64) -> f64,
        (x0, t0): (f64, f64),
        (x1, t1): (f64, f64),
        period: f64,
        depth: u32,
    ) -> Option<f64> {
        let d = (t1 - t0) - period * ((t1 - t0) / period).round();
        if d.abs() <= period / 8.0 || depth == 0 {
            return d.is_finite().then_some(d);
        }
        let xm = 0.5 * (x0 + x1);
        let tm = theory(xm);
        if !tm.is_finite() {
            return None;
        }
        Some(
            walk(theory, (x0, t0), (xm, tm), period, depth - 1)?
                + walk(theory, (xm, tm), (x1, t1), period, depth - 1)?,
        )
    }
    const PIECES: usize = 32;
    let at = |j: usize| x0 + (x1 - x0) * j as f64 / PIECES as f64;
    let mut t_prev = theory(x0);
    let mut sum = 0.0;
    for j in 1..=PIECES {
        let t = theory(at(j));
        if !t_prev.is_finite() || !t.is_finite() {
            return None;
        }
        sum += walk(theory, (at(j - 1), t_prev), (at(j), t), period, 24)?;
        t_prev = t;
    }
    Some(sum)
}

/// `ys` (degrees, at `xs`), each moved by whole `period`s to within half a period of the
/// reading at the next smaller x, for the line fit: each reading sits on its theory's branch,
/// and a strongly coupled device's psi crosses -90 deg between rates (a fit through that wrap
/// read a slope of -0.081 against a theory of +0.0244 while every point matched its theory).
/// A NaN stays NaN and is stepped over; readings already continuous keep their bits.
pub fn unwrapped_along(xs: &[f64], ys: &[f64], period: f64) -> Vec<f64> {
    // No theory: each reading against its neighbour alone (a step of 0 where the theory's
    // change would be).
    unwrapped_along_theory(xs, ys, period, &|_| f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unwrapping_along_x_restores_a_line_folded_onto_a_branch() {
        // A line of slope 0.1 deg per unit over rates given out of order, folded into
        // (-90, 90]: unwrapped by half turns (neighbours under a quarter turn apart) it is the
        // line again, up to one whole offset.
        let xs = [500.0, -500.0, 25.0, 175.0, 1000.0, -100.0];
        let line: Vec<f64> = xs.iter().map(|x| 0.1 * x - 80.0).collect();
        let folded: Vec<f64> = line
            .iter()
            .map(|y| y - 180.0 * ((y - 0.0) / 180.0).round())
            .collect();
        assert!(
            folded.iter().zip(&line).any(|(a, b)| a != b),
            "the fold moved some"
        );
        let u = unwrapped_along(&xs, &folded, 180.0);
        let offset = u[0] - line[0];
        assert!((offset / 180.0 - (offset / 180.0).round()).abs() < 1e-12);
        for (a, b) in u.iter().zip(&line) {
            assert!((a - b - offset).abs() < 1e-9, "{a} vs {b}");
        }
        // Readings already continuous keep their bits; a NaN stays and is stepped over.
        let ys = [1.0, f64::NAN, 3.5, -2.25];
        let v = unwrapped_along(&[1.0, 2.0, 3.0, 0.0], &ys, 360.0);
        assert_eq!(v[0].to_bits(), 1.0f64.to_bits());
        assert!(v[1].is_nan());
        assert_eq!((v[2], v[3]), (3.5, -2.25));
    }

    /// Unwrapping by the theory keeps a genuine step of more than a quarter turn between two
    /// rates (plain unwrapping moves it a half turn), restores a reading folded across the
    /// branch cut, and follows a theory that turns by more than a period between two rates.
    #[test]
    fn unwrapping_by_the_theory_keeps_steep_steps_and_restores_folds() {
        let fold = |y: f64| y - 180.0 * ((y - 1e-9) / 180.0).round();
        // psi = atan(x / 20): -83.5, -78.7, 78.7, 83.5 deg at +-100, +-250; the middle step
        // is 157 deg.
        let psi = |x: f64| (x / 20.0).atan().to_degrees();
        let xs = [-250.0, -100.0, 100.0, 250.0];
        let ys: Vec<f64> = xs.iter().map(|&x| psi(x)).collect();
        assert_eq!(unwrapped_along_theory(&xs, &ys, 180.0, &psi), ys);
        assert_ne!(unwrapped_along(&xs, &ys, 180.0), ys);
        // A line of slope 0.5 from 60 deg crosses 90 deg: folded readings come back.
        let line = |x: f64| 60.0 + 0.5 * x;
        let xs: Vec<f64> = (0..6).map(|i| 20.0 * i as f64).collect();
        let folded: Vec<f64> = xs.iter().map(|&x| fold(line(x))).collect();
        let u = unwrapped_along_theory(&xs, &folded, 180.0, &line);
        for (x, y) in xs.iter().zip(&u) {
            assert!((y - line(*x)).abs() < 1e-12, "{x}: {y}");
        }
        // 200 tanh(x): 385 deg from -2 to 2, more than two periods, in one step.
        let steep = |x: f64| 200.0 * x.tanh();
        let xs = [-2.0, 2.0];
        let folded: Vec<f64> = xs.iter().map(|&x| fold(steep(x))).collect();
        let u = unwrapped_along_theory(&xs, &folded, 180.0, &steep);
        assert!(
            (u[1] - u[0] - (steep(2.0) - steep(-2.0))).abs() < 1e-9,
            "{u:?}"
        );
        // No theory on the way: as the plain unwrapping.
        let nan = |_: f64| f64::NAN;
        assert_eq!(
            unwrapped_along_theory(&xs, &folded, 180.0, &nan),
            unwrapped_along(&xs, &folded, 180.0)
        );
    }

    #[test]
    fn recovers_an_exact_line_and_scores_noise() {
        let x: Vec<f64> = (0..8).map(|k| 25.0 * k as f64).collect();
        let y: Vec<f64> = x.iter().map(|v| 0.042 * v - 0.3).collect();
        let f = fit_line(&x, &y);
        assert!((f.slope - 0.042).abs() < 1e-15 && (f.intercept + 0.3).abs() < 1e-13);
        assert!((f.r2 - 1.0).abs() < 1e-12);
        let y2: Vec<f64> = y
            .iter()
            .enumerate()
            .map(|(i, v)| v + if i % 2 == 0 { 0.5 } else { -0.5 })
            .collect();
        assert!(fit_line(&x, &y2).r2 < 0.999);
    }

    #[test]
    fn one_rate_has_no_line_and_no_r2() {
        let f = fit_line(&[100.0], &[3.0]);
        assert!(
            f.slope.is_nan() && f.intercept.is_nan() && f.r2.is_nan(),
            "{f:?}"
        );
        let f = fit_line(&[100.0, 100.0], &[3.0, 3.0]);
        assert!(f.slope.is_nan() && f.r2.is_nan(), "{f:?}");
        // A flat line through two rates is a perfect fit.
        assert_eq!(fit_line(&[1.0, 2.0], &[3.0, 3.0]).r2, 1.0);
    }

    #[test]
    fn r2_never_passes_one_on_near_exact_lines() {
        // Seeded lines with offsets and tiny scatter, the data a noiseless sweep fits: the
        // rounded ratio passes 1 on some of them (this loop failed without the clamp).
        let mut seed = 11u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let n = 2 + (next() * 9.0) as usize;
            let (a, b) = (next() * 2.0 - 1.0, next() * 100.0 - 50.0);
            let x: Vec<f64> = (0..n).map(|k| 25.0 * (k + 1) as f64).collect();
            let y: Vec<f64> = x.iter().map(|v| a * v + b + 1e-13 * next()).collect();
            let r2 = fit_line(&x, &y).r2;
            assert!((0.0..=1.0).contains(&r2), "r2 {r2} for {x:?} {y:?}");
        }
        // A refused phase (NaN) or a single x gives no fit, not a perfect one.
        assert!(fit_line(&[1.0, 2.0, 3.0], &[0.5, f64::NAN, 1.5])
            .r2
            .is_nan());
        assert!(fit_line(&[2.0, 2.0], &[0.5, 1.5]).r2.is_nan());
    }

    #[test]
    fn slope_std_err_equals_the_normal_equations_covariance() {
        // Var(slope) = s^2 [(X'X)^-1]_11 with X = [x 1], s^2 = RSS/(n-2): solved here by
        // the explicit 2x2 inverse, independently of the centred sums of fit_line.
        let x: Vec<f64> = (0..9).map(|k| 10.0 + 7.0 * k as f64).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, v)| 0.3 * v + 2.0 + [0.4, -0.1, 0.7, -0.9, 0.2, 0.0, -0.3, 0.5, -0.6][i])
            .collect();
        let f = fit_line(&x, &y);
        let n = x.len() as f64;
        let (sx, sxx) = (x.iter().sum::<f64>(), x.iter().map(|v| v * v).sum::<f64>());
        let det = n * sxx - sx * sx;
        let rss: f64 = x
            .iter()
            .zip(&y)
            .map(|(a, b)| (b - f.slope * a - f.intercept).powi(2))
            .sum();
        let var = rss / (n - 2.0) * n / det;
        assert!((f.slope_std_err / var.sqrt() - 1.0).abs() < 1e-12);
        assert!(fit_line(&x[..2], &y[..2]).slope_std_err.is_nan());
    }

    #[test]
    fn t95_matches_the_closed_forms_and_tends_to_the_normal_quantile() {
        // dof 1 is Cauchy: t = tan(pi (p - 1/2)); dof 2: t = (2p - 1) / sqrt(2 p (1 - p)).
        let p = 0.975f64;
        let t1 = (std::f64::consts::PI * (p - 0.5)).tan();
        let t2 = (2.0 * p - 1.0) / (2.0 * p * (1.0 - p)).sqrt();
        assert!((t95(1) - t1).abs() < 5e-4, "{} vs {t1}", t95(1));
        assert!((t95(2) - t2).abs() < 5e-4, "{} vs {t2}", t95(2));
        // Decreasing in dof, above the normal 1.959964 and close to it by dof 30.
        for d in 1..30 {
            assert!(t95(d) > t95(d + 1));
        }
        assert!(t95(30) > 1.959_964 && t95(30) - 1.959_964 < 0.1);
        assert!((t95(1000) - 1.959_964).abs() < 1e-3);
        assert!(t95(0).is_infinite());
    }
}
