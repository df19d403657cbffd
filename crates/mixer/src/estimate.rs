//! Read-outs from averaged mixer outputs (THEORY section 6). Post-processing, not the
//! per-sample path, so std `atan2` is used.
//!
//! Rotating excitation. Write the stage-1 output as `z = Z+ e^{j Omega t} + Z- e^{-j Omega t}`.
//! Averages over whole half modulation periods give `C = <2 z cos Omega t> = Z+ + Z-` and
//! `S = <2 z sin Omega t> = j (Z+ - Z-)`, hence `Z+ = (C - jS)/2`, `Z- = (C + jS)/2`. For
//! `z1 = A e^{j alpha} cos(Omega t - psi)`: `Z+ = (A/2) e^{j(alpha - psi)}`,
//! `Z- = (A/2) e^{j(alpha + psi)}`; for `z2 = A e^{j alpha} sin(Omega t - psi)` the same times
//! `M+ = -j`, `M- = +j`. Sideband amplitudes that differ (`|Z-| != |Z+|`) do not bias psi.

use core::f64::consts::PI;
use gyroemu_core::Complex64;

use crate::wrap_pi;

/// Which mode a channel reads: its stage-2 signal goes as cos (mode 1) or sin (mode 2) of
/// `Omega t - psi`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Drive `cos(Omega t) cos(w0 t)`, sideband references `(M+, M-) = (1, 1)`.
    One,
    /// Drive `sin(Omega t) cos(w0 t)`, sideband references `(M+, M-) = (-j, +j)`.
    Two,
}

/// The sideband read-out of one channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SidebandEstimate {
    /// Envelope delay psi in `(-pi/2, pi/2]`, radians.
    pub psi_rad: f64,
    /// Carrier phase alpha in `(-pi, pi]`, radians (on the branch that puts psi in `(-pi/2, pi/2]`).
    pub alpha_rad: f64,
    /// `Z+ = (C - jS)/2`, the `e^{+j Omega t}` sideband phasor of `z`.
    pub z_plus: Complex64,
    /// `Z- = (C + jS)/2`, the `e^{-j Omega t}` sideband phasor of `z`.
    pub z_minus: Complex64,
}

/// `arg` in `(-pi, pi]` (std `arg` can return `-pi` for a negative zero imaginary part).
#[inline]
fn arg(z: Complex64) -> f64 {
    let a = z.im.atan2(z.re);
    if a <= -PI {
        PI
    } else {
        a
    }
}

/// psi and alpha from the averaged stage-2 outputs `C`, `S` (THEORY section 6):
/// `psi = (arg(Z-/M-) - arg(Z+/M+))/2`, `alpha = (arg(Z-/M-) + arg(Z+/M+))/2`.
///
/// Branch: `(psi, alpha)` and `(psi + pi, alpha + pi)` give the same `(Z+, Z-)` (the sign of `A`
/// is not observable), so psi is taken in `(-pi/2, pi/2]`: the difference of the two arguments is
/// wrapped to `(-pi, pi]` before halving, then `alpha = arg(Z+/M+) + psi` wrapped to `(-pi, pi]`.
/// A zero sideband has argument 0.
pub fn sideband_estimate(c: Complex64, s: Complex64, mode: Mode) -> SidebandEstimate {
    let j = Complex64::new(0.0, 1.0);
    let z_plus = (c - j * s) * 0.5;
    let z_minus = (c + j * s) * 0.5;
    // Dividing by M = -j or +j is an exact rotation: z / (-j) = j z, z / j = -j z.
    let (a_plus, a_minus) = match mode {
        Mode::One => (arg(z_plus), arg(z_minus)),
        Mode::Two => (arg(j * z_plus), arg(-j * z_minus)),
    };
    let psi = 0.5 * wrap_pi(a_minus - a_plus);
    let alpha = wrap_pi(a_plus + psi);
    SidebandEstimate {
        psi_rad: psi,
        alpha_rad: alpha,
        z_plus,
        z_minus,
    }
}

/// The paper-style psi from the real I channel only: `atan2(Re S1, Re C1)` for mode 1,
/// `atan2(-Re C2, Re S2)` for mode 2, in `(-pi, pi]`.
///
/// For the general channel `Z+ = M+ (A/2)(1 - e) e^{j(alpha - psi)}`,
/// `Z- = M- (A/2)(1 + e) e^{j(alpha + psi)}` (`e` the sideband amplitude imbalance) this equals
/// `psi + atan2(e sin alpha, cos alpha)` (mod 2 pi): exact when `alpha = 0` or the sidebands are
/// balanced (and `cos alpha > 0`), off by `atan(e tan alpha)` otherwise.
pub fn paper_i_channel_psi_rad(c: Complex64, s: Complex64, mode: Mode) -> f64 {
    let (num, den) = match mode {
        Mode::One => (s.re, c.re),
        Mode::Two => (-c.re, s.re),
    };
    arg(Complex64::new(den, num))
}

/// Coriolis reading: the lag of the constant stage-1 phasor `z` behind the zero-rate phasor
/// `z0`, `arg(z0 / z)` in `(-pi, pi]`; positive for `z = z0 e^{-j theta}`, theta > 0 (stage 1
/// maps a lag to a negative argument). Computed as `arg(z0 conj(z))`, which has the same
/// argument and needs no division; 0 when either phasor is 0.
pub fn phase_lag_rad(z: Complex64, z0: Complex64) -> f64 {
    arg(z0 * z.conj())
}
