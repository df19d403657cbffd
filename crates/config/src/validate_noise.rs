//! Validation of the noise, ADC and self-calibration keys (kept apart from the core rules of
//! `validate.rs`; same error form: key, value, rule).

use crate::config::Config;
use crate::rules::Rules;
use crate::validate::MAX_RUN_SAMPLES;

impl Config {
    /// The rules of the `[noise]` and `[selfcal]` sections and of the ADC keys.
    pub(crate) fn validate_noise_adc_selfcal(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let b = &self.board;
        if let Some(bits) = b.adc_bits {
            p.check(
                (2..=32).contains(&bits),
                "board.adc_bits",
                bits,
                "must be an integer from 2 to 32",
            );
        }
        p.positive("board.adc_full_scale_v", b.adc_full_scale_v);
        if let Some(n) = &self.noise {
            p.positive("noise.temperature_k", n.temperature_k);
            if let Some(m) = n.effective_mass_kg {
                p.positive("noise.effective_mass_kg", m);
            }
            p.non_negative(
                "noise.tia_current_noise_a_per_rthz",
                n.tia_current_noise_a_per_rthz,
            );
            p.non_negative(
                "noise.tia_voltage_noise_v_per_rthz",
                n.tia_voltage_noise_v_per_rthz,
            );
            let silent = n.effective_mass_kg.is_none()
                && n.tia_current_noise_a_per_rthz == 0.0
                && n.tia_voltage_noise_v_per_rthz == 0.0
                && b.adc_bits.is_none();
            if silent {
                warnings.push(
                    "[noise] is present but sets no source (effective_mass_kg, tia_*_noise, board.adc_bits): the run is noiseless".into(),
                );
            }
        }
        if let Some(s) = &self.selfcal {
            // The record lengths are bounded by the sample rates.
            let rates_ok = p.clean(&["board.fs_hz", "board.decimation"]);
            let max_s = MAX_RUN_SAMPLES / self.fs_hz();
            if let Some(t) = s.allan_record_s.filter(|_| rates_ok) {
                let min = (10.0 / self.fs_out_hz()).max(10.0);
                p.check(
                    t.is_finite() && t >= min && t <= max_s,
                    "selfcal.allan_record_s",
                    t,
                    format!(
                        "must be a finite number from {min} s (at least 10 s and 10 output samples: the Allan deviation needs a record of many averaging times) to {max_s:e} s (2^53 input samples)"
                    ),
                );
            }
            if let Some(t) = s.tau_max_s.filter(|_| rates_ok) {
                p.check(
                    t.is_finite() && t >= 2.0 && t <= max_s,
                    "selfcal.tau_max_s",
                    t,
                    format!(
                        "must be a finite number from 2 s (the analysis starts at 1 s) to {max_s:e} s (2^53 input samples)"
                    ),
                );
            }
            for (i, &dt) in s.drift_delta_t_k.iter().enumerate() {
                p.check(
                    dt.is_finite() && dt.abs() <= 200.0,
                    &format!("selfcal.drift_delta_t_k[{i}]"),
                    dt,
                    "must be finite and within -200..200 K",
                );
            }
            p.check(
                s.f0_tc_ppm_per_k.is_finite() && s.f0_tc_ppm_per_k.abs() < 1e4,
                "selfcal.f0_tc_ppm_per_k",
                s.f0_tc_ppm_per_k,
                "must be finite and within -1e4..1e4 ppm/K",
            );
            p.check(
                s.q_tc_ppm_per_k.is_finite() && s.q_tc_ppm_per_k.abs() < 1e5,
                "selfcal.q_tc_ppm_per_k",
                s.q_tc_ppm_per_k,
                "must be finite and within -1e5..1e5 ppm/K",
            );
            let tc_ok = p.clean(&["selfcal.f0_tc_ppm_per_k", "selfcal.q_tc_ppm_per_k"]);
            for (i, &dt) in s.drift_delta_t_k.iter().enumerate().filter(|_| tc_ok) {
                let q_scale = 1.0 + s.q_tc_ppm_per_k * 1e-6 * dt;
                let f_scale = 1.0 + s.f0_tc_ppm_per_k * 1e-6 * dt;
                p.check(
                    q_scale > 0.0 && f_scale > 0.0,
                    &format!("selfcal.drift_delta_t_k[{i}]"),
                    dt,
                    "the temperature coefficients must keep Q and f0 > 0 at this offset",
                );
            }
        }
    }
}
