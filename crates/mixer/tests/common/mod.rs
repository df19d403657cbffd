//! Test-side references: exact-phase signal synthesis and a boxcar average, written
//! independently of the crate (std trigonometry, integer phase reduction).
#![allow(dead_code)]

use core::f64::consts::TAU;
use gyroemu_core::Complex64;

/// `2 pi (n k mod m) / m`: the phase of a tone of `k` cycles per `m` samples, reduced exactly.
pub fn exact_phase(n: u64, k: u64, m: u64) -> f64 {
    TAU * ((n * k) % m) as f64 / m as f64
}

/// Carrier phasor `e^{j w0 n Ts}` with `w0 Ts = 2 pi k / m`.
pub fn carrier(n: u64, k: u64, m: u64) -> Complex64 {
    let (s, c) = exact_phase(n, k, m).sin_cos();
    Complex64::new(c, s)
}

/// Plain mean of complex samples.
pub fn mean(xs: &[Complex64]) -> Complex64 {
    xs.iter().sum::<Complex64>() / xs.len() as f64
}

/// Largest |a - b| after wrapping the difference of two angles into (-pi, pi].
pub fn angle_err(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d)
}

/// `(C, S)` sideband phasors of a channel with balanced or imbalanced sidebands:
/// `Z+ = M+ (A/2)(1 - e) e^{j(alpha - psi)}`, `Z- = M- (A/2)(1 + e) e^{j(alpha + psi)}`,
/// i.e. (for e = 0) `z1 = A e^{j alpha} cos(Omega t - psi)`, `z2 = A e^{j alpha} sin(Omega t - psi)`.
pub struct Planted {
    pub amp: f64,
    pub psi: f64,
    pub alpha: f64,
    pub imbalance: f64,
    pub mode2: bool,
}

impl Planted {
    /// z at modulation phase `wt` (= Omega t).
    pub fn z(&self, wt: f64) -> Complex64 {
        let x = wt - self.psi;
        let (up, dn) = (
            0.5 * self.amp * (1.0 - self.imbalance),
            0.5 * self.amp * (1.0 + self.imbalance),
        );
        // e = 0: cos x = (e^{jx} + e^{-jx})/2, sin x = (e^{jx} - e^{-jx})/(2j).
        let ea = Complex64::from_polar(1.0, self.alpha);
        let (mp, mm) = if self.mode2 {
            (Complex64::new(0.0, -1.0), Complex64::new(0.0, 1.0))
        } else {
            (Complex64::new(1.0, 0.0), Complex64::new(1.0, 0.0))
        };
        ea * (mp * up * Complex64::from_polar(1.0, x) + mm * dn * Complex64::from_polar(1.0, -x))
    }
}
