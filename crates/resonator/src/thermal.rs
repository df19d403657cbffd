//! Thermomechanical (Brownian) force noise of a damped mode: the fluctuation-dissipation
//! theorem gives a white force density 4 k T c = 4 k T m w0 / Q (one-sided, N^2/Hz), where
//! c = m w0 / Q is the mode's damping coefficient. The plant takes force per unit mass, so
//! the density it sees is 4 k T w0 / (Q m).

use gyroemu_core::noise::BOLTZMANN_J_PER_K;

/// One-sided force density of the Brownian noise, N^2/Hz: 4 k T m w0 / Q.
pub fn thermomechanical_force_psd(temperature_k: f64, mass_kg: f64, f0_hz: f64, q: f64) -> f64 {
    4.0 * BOLTZMANN_J_PER_K * temperature_k * mass_kg * core::f64::consts::TAU * f0_hz / q
}

/// The same density per unit mass, (m/s^2)^2/Hz: 4 k T w0 / (Q m), what the plant's force
/// input receives.
pub fn thermomechanical_accel_psd(temperature_k: f64, mass_kg: f64, f0_hz: f64, q: f64) -> f64 {
    let Some((s, e)) = split_pow2(mass_kg) else {
        return 4.0 * BOLTZMANN_J_PER_K * temperature_k * core::f64::consts::TAU * f0_hz
            / (q * mass_kg);
    };
    // m = s 2^e with s in [1, 2): the density is that of mass s times 2^-e. Scaling by powers
    // of two is exact, so this is bit for bit the force density over m^2 wherever m^2 is
    // normal (the presets' results stay put), while m^2 itself, which is subnormal below
    // m ~ 1.5e-154 and 0 below ~2e-162, is never formed.
    let per_s = thermomechanical_force_psd(temperature_k, s, f0_hz, q) / (s * s);
    // 2^-e in two factors: for a subnormal m, -e exceeds the largest exponent (1023).
    let half = -e / 2;
    per_s * pow2(half) * pow2(-e - half)
}

/// `(s, e)` with `m = s 2^e` and `1 <= |s| < 2`, exactly; `None` for 0, inf and NaN.
fn split_pow2(m: f64) -> Option<(f64, i32)> {
    if !m.is_finite() || m == 0.0 {
        return None;
    }
    // A subnormal is first made normal (exactly).
    let (m, shift) = if m.abs() < f64::MIN_POSITIVE {
        (m * pow2(64), 64)
    } else {
        (m, 0)
    };
    const EXP: u64 = 0x7ff << 52;
    let bits = m.to_bits();
    let e = ((bits & EXP) >> 52) as i32 - 1023;
    let s = f64::from_bits((bits & !EXP) | (1023 << 52));
    Some((s, e - shift))
}

/// 2^n for n in -1022..=1023, exactly.
fn pow2(n: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&n));
    f64::from_bits(((n + 1023) as u64) << 52)
}

#[cfg(test)]
mod tests {
    use super::*;

    const K: f64 = 1.380_649e-23;

    #[test]
    fn brownian_density_of_a_known_mode() {
        // m = 1 ug, f0 = 15 kHz, Q = 2000, T = 300 K: 4 k T m w0 / Q written out by hand.
        let expected = 4.0 * K * 300.0 * 1e-9 * (2.0 * core::f64::consts::PI * 15e3) / 2000.0;
        let got = thermomechanical_force_psd(300.0, 1e-9, 15e3, 2000.0);
        assert!((got / expected - 1.0).abs() < 1e-14);
        // sqrt is about 2.79e-14 N/sqrt(Hz).
        assert!((got.sqrt() - 2.7942e-14).abs() < 1e-17);
        let a = thermomechanical_accel_psd(300.0, 1e-9, 15e3, 2000.0);
        assert!((a * 1e-18 / got - 1.0).abs() < 1e-14);
    }

    #[test]
    fn the_accel_density_is_right_at_masses_whose_square_underflows() {
        // m^2 is subnormal below 1.5e-154 and 0 below 2e-162: the density was 10 % low at
        // 2e-162 and inf below.
        let w0 = core::f64::consts::TAU * 15e3;
        for m in [
            1e-9, 1e-150, 1e-155, 2e-162, 1e-200, 9.7e-211, 1e-300, 2.2e-308, 1e-310, 5e-324,
            1e150, 1e200,
        ] {
            let want = 4.0 * K * 300.0 * w0 / (2000.0 * m);
            let got = thermomechanical_accel_psd(300.0, m, 15e3, 2000.0);
            assert!(
                (got / want - 1.0).abs() < 1e-14,
                "{m:e}: {got:e} vs {want:e}"
            );
        }
    }

    #[test]
    fn the_accel_density_keeps_its_bits_where_m_squared_is_normal() {
        // The former force density / m^2, at the presets' modes and a spread of masses.
        let old =
            |t: f64, m: f64, f0: f64, q: f64| thermomechanical_force_psd(t, m, f0, q) / (m * m);
        let mut m = 1.6e-154;
        while m < 1e154 {
            for (f0, q) in [(15e3, 2000.0), (15e3 + 0.02, 1950.0), (3.1e6, 1.7e4)] {
                for t in [300.0, 4.2, 273.15] {
                    let got = thermomechanical_accel_psd(t, m, f0, q);
                    assert_eq!(got.to_bits(), old(t, m, f0, q).to_bits(), "{m:e} {f0} {q}");
                }
            }
            m *= 1.37;
        }
    }
}
