//! Exact closed forms of THEORY.md, used for overlays and tests, never in place of the
//! emulation. Angles in radians, rates in rad/s, lag positive.

use core::f64::consts::PI;

/// Coriolis steady-state phase shifts (eqs. 2-3, exact for every rate):
/// `theta1 = atan(2 F2 Q lambda Omega / (F1 w0))`, `theta2 = atan(2 F1 Q lambda Omega / (F2 w0))`.
pub fn coriolis_theta_rad(
    f0_hz: f64,
    q: f64,
    lambda: f64,
    f1: f64,
    f2: f64,
    omega_z: f64,
) -> [f64; 2] {
    let w0 = 2.0 * PI * f0_hz;
    let g = 2.0 * q * lambda * omega_z / w0;
    [(g * f2 / f1).atan(), (g * f1 / f2).atan()]
}

/// Envelope delay of the rotating excitation, eq. 6: `theta0 = atan(2 Q Omega / w0)`.
pub fn rotating_theta0_rad(f0_hz: f64, q: f64, omega: f64) -> f64 {
    (2.0 * q * omega / (2.0 * PI * f0_hz)).atan()
}

/// Exact plant value of the rotating-excitation phase (major-axis estimator, THEORY section 4):
/// `psi = (d+ + d-)/2`, `d± = atan(Q Omega (2 w0 ± Omega) / (w0 (w0 ± Omega)))`.
pub fn rotating_psi_rad(f0_hz: f64, q: f64, omega: f64) -> f64 {
    let w0 = 2.0 * PI * f0_hz;
    let d = |s: f64| (q * omega * (2.0 * w0 + s * omega) / (w0 * (w0 + s * omega))).atan();
    0.5 * (d(1.0) + d(-1.0))
}

/// Mechanical envelope time constant `tau = 2Q/w0 = Q/(pi f0)` in seconds.
pub fn mechanical_tau_s(f0_hz: f64, q: f64) -> f64 {
    q / (PI * f0_hz)
}

/// Small-signal transfer of a sinusoidal rate table to the phase of mode k (THEORY section 3):
/// the phase follows Omega through a first-order low-pass with time constant tau, so the
/// amplitude is `g_k A / sqrt(1 + (w_t tau)^2)` with the DC slope `g_k = 2 Q lambda (F_other/F_k) / w0`.
/// Returns (amplitude gain in rad per rad/s, phase lag of the response in rad).
pub fn rate_table_gain(
    f0_hz: f64,
    q: f64,
    lambda: f64,
    f_self: f64,
    f_other: f64,
    table_hz: f64,
) -> (f64, f64) {
    let w0 = 2.0 * PI * f0_hz;
    let tau = mechanical_tau_s(f0_hz, q);
    let wt = 2.0 * PI * table_hz * tau;
    let dc = 2.0 * q * lambda * (f_other / f_self) / w0;
    (dc / (1.0 + wt * wt).sqrt(), wt.atan())
}

#[cfg(test)]
mod tests {
    use super::*;
    const DPS: f64 = PI / 180.0;

    #[test]
    fn reference_values_of_theory_md() {
        // THEORY.md section 8: Q = 2000, lambda = 1, F1 = F2, f0 = 15 kHz.
        let t =
            |q: f64, r: f64| coriolis_theta_rad(15e3, q, 1.0, 1.0, 1.0, r * DPS)[0].to_degrees();
        assert!((t(2000.0, 100.0) - 4.23639).abs() < 5e-6);
        assert!((t(2000.0, 175.0) - 7.38604).abs() < 5e-6);
        assert!((t(36000.0, 175.0) - 66.80141).abs() < 5e-6);
        assert!((mechanical_tau_s(15e3, 36000.0) - 0.7639).abs() < 1e-3);
    }

    #[test]
    fn psi_is_within_0_015_mdeg_of_theta0() {
        for &q in &[1e3, 2e3, 3.6e4] {
            for k in 1..=8 {
                let w = k as f64 * 21.875 * DPS;
                let d = (rotating_psi_rad(15e3, q, w) - rotating_theta0_rad(15e3, q, w)).abs();
                assert!(d.to_degrees() * 1e3 < 0.015, "q {q} k {k}: {d}");
            }
        }
    }

    #[test]
    fn unequal_drives_swap_the_ratio() {
        let [a, b] = coriolis_theta_rad(15e3, 2e3, 1.0, 1.0, 0.5, 50.0 * DPS);
        let g = 2.0 * 2e3 * 50.0 * DPS / (2.0 * PI * 15e3);
        assert!((a - (0.5 * g).atan()).abs() < 1e-15 && (b - (2.0 * g).atan()).abs() < 1e-15);
    }
}
