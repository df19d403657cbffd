//! The periodic Hann window and its exact frequency response.

use num_complex::Complex64;
use std::f64::consts::PI;

/// Equivalent noise bandwidth of the periodic Hann window, in bins: L sum(w^2) / sum(w)^2 = 3/2.
pub const HANN_ENBW_BINS: f64 = 1.5;

/// Periodic Hann window of length `len`: `w[n] = (1 - cos(2 pi n / len)) / 2` (the DFT-even
/// form, whose Welch segments tile with 50 % overlap to a constant).
pub fn hann(len: usize) -> Vec<f64> {
    (0..len)
        .map(|n| 0.5 - 0.5 * (2.0 * PI * n as f64 / len as f64).cos())
        .collect()
}

/// `sum_n exp(-j 2 pi x n / len)` over `n = 0 .. len`: the Dirichlet kernel, for `x` in bins.
fn dirichlet(x: f64, len: usize) -> Complex64 {
    let l = len as f64;
    let s = (PI * x / l).sin();
    let mag = if s.abs() < 1e-12 {
        // x is a multiple of len: every term is exp(-j 2 pi k n) = 1 (|x| < len here).
        l
    } else {
        (PI * x).sin() / s
    };
    Complex64::from_polar(mag, -PI * x * (l - 1.0) / l)
}

/// |W(x)| / W(0) of the periodic Hann window of length `len` at `x` bins from a tone: the
/// exact finite-length response (not the large-L sinc approximation). 1 at 0, 1/2 at +-1,
/// 0 at every other integer.
pub fn hann_response(x: f64, len: usize) -> f64 {
    // w[n] = 1/2 - e^{j 2 pi n/L}/4 - e^{-j 2 pi n/L}/4, so W(x) = D(x)/2 - D(x-1)/4 - D(x+1)/4.
    let w =
        dirichlet(x, len) * 0.5 - dirichlet(x - 1.0, len) * 0.25 - dirichlet(x + 1.0, len) * 0.25;
    w.norm() / (0.5 * len as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The response by direct summation of the window times the complex exponential.
    fn direct(x: f64, len: usize) -> f64 {
        let w = hann(len);
        let s: Complex64 = w
            .iter()
            .enumerate()
            .map(|(n, &wn)| Complex64::from_polar(wn, -2.0 * PI * x * n as f64 / len as f64))
            .sum();
        s.norm() / w.iter().sum::<f64>()
    }

    #[test]
    fn closed_form_response_equals_direct_summation() {
        for len in [8usize, 31, 64, 1000] {
            for x in [0.0, 0.25, 0.5, 0.9, 1.0, 1.5, 2.0, 3.3, -0.7] {
                let (a, b) = (hann_response(x, len), direct(x, len));
                assert!((a - b).abs() < 1e-12, "len {len} x {x}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn enbw_and_coherent_gain_are_the_hann_constants() {
        for len in [16usize, 1024] {
            let w = hann(len);
            let s1: f64 = w.iter().sum();
            let s2: f64 = w.iter().map(|v| v * v).sum();
            assert!((s1 / len as f64 - 0.5).abs() < 1e-12);
            assert!((len as f64 * s2 / (s1 * s1) - HANN_ENBW_BINS).abs() < 1e-12);
        }
        // Worst-case scalloping of Hann: -1.42 dB at half a bin (Harris 1978, table 1).
        let db = 20.0 * hann_response(0.5, 4096).log10();
        assert!((db + 1.42).abs() < 0.01, "{db}");
    }
}
