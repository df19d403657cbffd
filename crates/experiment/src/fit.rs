//! Least-squares straight line, as the paper's "best linear fit".

use serde::Serialize;

/// y = slope * x + intercept, with the coefficient of determination.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LineFit {
    pub slope: f64,
    pub intercept: f64,
    pub r2: f64,
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
    let r2 = if syy == 0.0 {
        1.0
    } else {
        sxy * sxy / (sxx * syy)
    };
    LineFit {
        slope,
        intercept,
        r2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
