//! Amplifier noise of the TIA, referred to its input. The current noise i_n enters with the
//! motional current; the voltage noise e_n is taken at the output within the TIA's own
//! closed-loop bandwidth, which is the same as a current e_n / R at the input (exact when
//! the sensor capacitance is small next to the feedback capacitance, so the noise gain is
//! about 1 near the carrier; a large sensor capacitance raises it, see docs/user-guide.md).

/// Input-referred current noise density, A/sqrt(Hz): sqrt(i_n^2 + (e_n / R)^2).
pub fn input_referred_noise_a_per_rthz(
    current_noise_a_per_rthz: f64,
    voltage_noise_v_per_rthz: f64,
    gain_ohm: f64,
) -> f64 {
    current_noise_a_per_rthz.hypot(voltage_noise_v_per_rthz / gain_ohm)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uncorrelated_sources_add_in_power() {
        // 3 fA and 4 nV over 1 MOhm (4 fA): 5 fA.
        let n = input_referred_noise_a_per_rthz(3e-15, 4e-9, 1e6);
        assert!((n / 5e-15 - 1.0).abs() < 1e-15);
    }
}
