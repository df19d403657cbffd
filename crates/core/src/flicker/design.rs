//! The filter that shapes unit white noise into 1/f: interlaced poles and zeros two per
//! decade, its exact sampled spectrum, and its modal (partial-fraction) form.

use super::params::FlickerParams;
use crate::detmath::sin_cos;
use crate::{ParamResult, Response};
use core::f64::consts::{PI, TAU};
use num_complex::Complex64;

/// Pole-zero pairs per decade. At two the lattice ripple of `f S(f)` is of order
/// `exp(-pi^2 / ln r)` with `ln r = ln 10 / 2` (about 2e-4); the ends of the band set the
/// rest of [`RIPPLE_DB`]. One per decade would give about +-0.35 dB.
pub const POLES_PER_DECADE: f64 = 2.0;

/// Bound on `|10 log10(S(f) f / S1)|` over `[10 f_lo, f_hi / 10]` for every design
/// [`FlickerParams::validate`] accepts (the design tests check it; about 0.02 dB is typical).
pub const RIPPLE_DB: f64 = 0.05;

/// Points over one lattice period at the band centre where the gain is set.
const NORM_POINTS: usize = 64;

/// The designed filter: `H(z) = g prod_k (1 - c_k z^-1) / (1 - a_k z^-1)`, also held as
/// `D + sum_k rho_k / (1 - a_k z^-1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct FlickerDesign {
    fs_hz: f64,
    /// Pole radii `a_k = exp(-2 pi p_k / fs)`, lowest frequency first.
    a: Vec<f64>,
    /// Zero radii `c_k = exp(-2 pi z_k / fs)`.
    c: Vec<f64>,
    gain: f64,
    direct: f64,
    residues: Vec<f64>,
}

impl FlickerDesign {
    /// Designs the filter for `p` (validated first).
    pub fn new(p: &FlickerParams) -> ParamResult<Self> {
        p.validate()?;
        let span = p.f_hi_hz / p.f_lo_hz;
        let n = ((POLES_PER_DECADE * span.log10()).round() as usize).max(1);
        // The lattice is stretched so the lowest pole sits on f_lo and the last zero on f_hi.
        let r = span.powf(1.0 / (n as f64 - 0.5));
        let radius = |f: f64| (-TAU * f / p.fs_hz).exp();
        let poles: Vec<f64> = (0..n).map(|k| p.f_lo_hz * r.powi(k as i32)).collect();
        let a: Vec<f64> = poles.iter().map(|&f| radius(f)).collect();
        let c: Vec<f64> = poles.iter().map(|&f| radius(f * r.sqrt())).collect();
        let mut d = Self {
            fs_hz: p.fs_hz,
            a,
            c,
            gain: 1.0,
            direct: 0.0,
            residues: Vec::new(),
        };
        // Mean of ln(f S(f)) over one lattice period at the centre of the band (in the
        // interior the ripple is periodic in ln f, so one period gives its mean).
        let centre = (p.f_lo_hz * p.f_hi_hz).sqrt();
        let mean_ln = (0..NORM_POINTS)
            .map(|i| {
                let f = centre * r.powf((i as f64 + 0.5) / NORM_POINTS as f64 - 0.5);
                (f * d.psd(f)).ln()
            })
            .sum::<f64>()
            / NORM_POINTS as f64;
        d.gain = (p.psd_at_1hz / mean_ln.exp()).sqrt();
        d.direct = d.gain * d.c.iter().zip(&d.a).map(|(c, a)| c / a).product::<f64>();
        d.residues = d.modal_residues();
        Ok(d)
    }

    /// `rho_j = [(1 - a_j z^-1) H(z)] at z = a_j`
    /// `= g (a_j - c_j) / a_j * prod_{i != j} (a_j - c_i) / (a_j - a_i)`, as a product of
    /// ratios (no under- or overflow however many poles). Differences of radii near 1 are
    /// exact (Sterbenz), so the residues are accurate to rounding even for poles far below
    /// fs. Every factor is positive (the zeros interlace the poles), so every residue is.
    fn modal_residues(&self) -> Vec<f64> {
        (0..self.a.len())
            .map(|j| {
                let aj = self.a[j];
                let mut r = self.gain * (aj - self.c[j]) / aj;
                for i in (0..self.a.len()).filter(|&i| i != j) {
                    r *= (aj - self.c[i]) / (aj - self.a[i]);
                }
                r
            })
            .collect()
    }

    /// Sample rate, Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// Number of poles (one state per lane each in [`super::Flicker`]).
    pub fn poles(&self) -> usize {
        self.a.len()
    }

    /// Pole radii `a_k`, lowest frequency first.
    pub fn pole_radii(&self) -> &[f64] {
        &self.a
    }

    /// Zero radii `c_k`, lowest frequency first.
    pub fn zero_radii(&self) -> &[f64] {
        &self.c
    }

    /// The direct term `D = H(z -> infinity)` of the modal form.
    pub fn direct(&self) -> f64 {
        self.direct
    }

    /// The residues `rho_k` of the modal form (all positive).
    pub fn residues(&self) -> &[f64] {
        &self.residues
    }

    /// The exact one-sided density of the output at `f_hz` (`0 <= f <= fs/2`), unit^2/Hz,
    /// for unit-variance white input: `(2/fs) |H(e^{j 2 pi f / fs})|^2`, each factor as
    /// `|1 - a e^{-jw}|^2 = (1 - a)^2 + 4 a sin^2(w/2)` (1 - a exact for a near 1).
    pub fn psd(&self, f_hz: f64) -> f64 {
        let (s, _) = sin_cos(PI * f_hz / self.fs_hz);
        let s2 = 4.0 * s * s;
        let factor = |x: f64| (1.0 - x) * (1.0 - x) + x * s2;
        let ratio: f64 = self
            .c
            .iter()
            .zip(&self.a)
            .map(|(&c, &a)| factor(c) / factor(a))
            .product();
        2.0 / self.fs_hz * self.gain * self.gain * ratio
    }

    /// The covariance of modal states `i` and `j` in the stationary state,
    /// `sum_n a_i^n a_j^n = 1 / (1 - a_i a_j)`, with `1 - a_i a_j = (1 - a_i) + a_i (1 - a_j)`
    /// (no cancellation for radii near 1).
    pub fn mode_covariance(&self, i: usize, j: usize) -> f64 {
        let (ai, aj) = (self.a[i], self.a[j]);
        1.0 / ((1.0 - ai) + ai * (1.0 - aj))
    }

    /// The exact variance of the stationary output for unit-variance white input:
    /// `D^2 + 2 D sum rho + sum_ij rho_i rho_j C_ij` (each state holds the current input with
    /// weight 1, hence the cross term).
    pub fn variance(&self) -> f64 {
        let rho = &self.residues;
        let sum: f64 = rho.iter().sum();
        let quad: f64 = (0..rho.len())
            .flat_map(|i| (0..rho.len()).map(move |j| (i, j)))
            .map(|(i, j)| rho[i] * rho[j] * self.mode_covariance(i, j))
            .sum();
        self.direct * self.direct + 2.0 * self.direct * sum + quad
    }
}

impl Response for FlickerDesign {
    /// `H(e^{jw}) = g prod_k (1 - c_k e^{-jw}) / (1 - a_k e^{-jw})`, `w = 2 pi f / fs`.
    fn response(&self, f_hz: f64) -> Complex64 {
        let (s, c) = sin_cos(-TAU * f_hz / self.fs_hz);
        let z1 = Complex64::new(c, s);
        self.c
            .iter()
            .zip(&self.a)
            .fold(Complex64::new(self.gain, 0.0), |h, (&cz, &ap)| {
                h * (1.0 - cz * z1) / (1.0 - ap * z1)
            })
    }
}
