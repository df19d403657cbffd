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
    // x) stays NaN: `f64::min` would make it a perfect fit.
    let r2 = if syy == 0.0 {
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

/// `ys` (degrees, at `xs`), each moved by whole `period`s to within half a period of the
/// reading at the next smaller x, for the line fit: each reading sits on its theory's branch,
/// and a strongly coupled device's psi crosses -90 deg between rates (a fit through that wrap
/// read a slope of -0.081 against a theory of +0.0244 while every point matched its theory).
/// A NaN stays NaN and is stepped over; readings already continuous keep their bits.
pub fn unwrapped_along(xs: &[f64], ys: &[f64], period: f64) -> Vec<f64> {
    let mut order: Vec<usize> = (0..xs.len().min(ys.len())).collect();
    order.sort_by(|&a, &b| xs[a].total_cmp(&xs[b]));
    let mut out = ys.to_vec();
    let mut prev: Option<f64> = None;
    for i in order {
        let y = ys[i];
        if !y.is_finite() {
            continue;
        }
        let moved = match prev {
            Some(p) => {
                let k = ((p - y) / period).round();
                if k == 0.0 {
                    y
                } else {
                    y + k * period
                }
            }
            None => y,
        };
        out[i] = moved;
        prev = Some(moved);
    }
    out
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
