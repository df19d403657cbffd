//! Thermomechanical (Brownian) force noise of a damped mode: the fluctuation-dissipation
//! theorem gives a white force density 4 k T c = 4 k T m w0 / Q (one-sided, N^2/Hz), where
//! c = m w0 / Q is the mode's damping coefficient. The plant takes force per unit mass, so
//! the density it sees is that divided by m^2.

use gyroemu_core::noise::BOLTZMANN_J_PER_K;

/// One-sided force density of the Brownian noise, N^2/Hz: 4 k T m w0 / Q.
pub fn thermomechanical_force_psd(temperature_k: f64, mass_kg: f64, f0_hz: f64, q: f64) -> f64 {
    4.0 * BOLTZMANN_J_PER_K * temperature_k * mass_kg * core::f64::consts::TAU * f0_hz / q
}

/// The same density per unit mass, (m/s^2)^2/Hz: what the plant's force input receives.
pub fn thermomechanical_accel_psd(temperature_k: f64, mass_kg: f64, f0_hz: f64, q: f64) -> f64 {
    thermomechanical_force_psd(temperature_k, mass_kg, f0_hz, q) / (mass_kg * mass_kg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brownian_density_of_a_known_mode() {
        // m = 1 ug, f0 = 15 kHz, Q = 2000, T = 300 K: 4 k T m w0 / Q written out by hand.
        let k = 1.380_649e-23;
        let expected = 4.0 * k * 300.0 * 1e-9 * (2.0 * core::f64::consts::PI * 15e3) / 2000.0;
        let got = thermomechanical_force_psd(300.0, 1e-9, 15e3, 2000.0);
        assert!((got / expected - 1.0).abs() < 1e-14);
        // sqrt is about 2.79e-14 N/sqrt(Hz).
        assert!((got.sqrt() - 2.7942e-14).abs() < 1e-17);
        let a = thermomechanical_accel_psd(300.0, 1e-9, 15e3, 2000.0);
        assert!((a * 1e-18 / got - 1.0).abs() < 1e-14);
    }
}
