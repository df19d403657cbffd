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
            // The levels as the board reads them (the low corner does not matter here), then
            // the densities it designs from them, which must not overflow.
            let board_noise = crate::plan::noise_params(n, 0.0);
            let levels = board_noise.flicker_levels();
            let levels_ok = levels.map(|(key, v)| p.non_negative(key, v));
            // The TIA's density overflows through its white level, not its corner.
            let mut named = levels;
            named[0] = (
                "noise.tia_voltage_noise_v_per_rthz",
                n.tia_voltage_noise_v_per_rthz,
            );
            let psds = board_noise.flicker_psds_at_1hz(b.tia_gain_ohm);
            for (((key, v), (_, psd)), ok) in named.into_iter().zip(psds).zip(levels_ok) {
                if ok && p.clean(&["board.tia_gain_ohm", key]) {
                    p.check(
                        psd.is_finite(),
                        key,
                        v,
                        format!(
                            "gives a flicker density at 1 Hz of {psd:e}, which must be finite \
                             (the square of the level; for the TIA's, \
                             (e_n / tia_gain_ohm)^2 x tia_voltage_flicker_corner_hz in A^2/Hz)"
                        ),
                    );
                }
            }
            if n.tia_voltage_flicker_corner_hz > 0.0 && n.tia_voltage_noise_v_per_rthz == 0.0 {
                warnings.push(
                    "noise.tia_voltage_flicker_corner_hz is set but noise.tia_voltage_noise_v_per_rthz is 0: the TIA's voltage flicker is silent".into(),
                );
            }
            if self.has_flicker() && p.clean(&["board.fs_hz", "board.decimation"]) {
                // The slow sources run at the output rate: two decades of 1/f below its half.
                let f_lo = self.flicker_f_lo_hz();
                let max = 0.005 * self.fs_out_hz();
                p.check(
                    f_lo.is_finite() && f_lo > 0.0 && f_lo <= max,
                    "noise.flicker_f_lo_hz",
                    f_lo,
                    format!(
                        "must be > 0 and at most fs_out/200 = {max} Hz (the slow flicker sources run at the output rate and need two decades of 1/f below its half)"
                    ),
                );
            }
            let silent = n.effective_mass_kg.is_none()
                && n.tia_current_noise_a_per_rthz == 0.0
                && n.tia_voltage_noise_v_per_rthz == 0.0
                && b.adc_bits.is_none()
                && !self.has_flicker();
            if silent {
                warnings.push(
                    "[noise] is present but sets no source (effective_mass_kg, tia_*_noise, the flicker keys, board.adc_bits): the run is noiseless".into(),
                );
            }
        }
        if let Some(pll) = &self.pll {
            self.validate_pll(pll, p);
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

impl Config {
    /// The `[pll]` rules: a damping > 0, mode 1 or 2, a natural frequency inside the bounds
    /// the loop can be built in, a lock run long enough to settle.
    fn validate_pll(&self, pll: &crate::config::PllConfig, p: &mut Rules) {
        p.check(
            pll.mode == 1 || pll.mode == 2,
            "pll.mode",
            pll.mode,
            "must be 1 or 2 (the mode whose output the PLL locks on)",
        );
        if !p.positive("pll.damping", pll.damping)
            || !p.clean(&["pll.mode"])
            || !p.section_clean("device")
            || !p.section_clean("board")
        {
            return;
        }
        let (lo, hi) = crate::resolve::pll_bounds_hz(self, pll.damping, pll.mode);
        let natural = self.pll_natural_hz().unwrap_or(f64::NAN);
        let fits = p.check(
            lo < hi,
            "pll.natural_hz",
            natural,
            format!(
                "no loop fits: a PI on the frequency needs at least {lo:.4} Hz (2 damping w_n tau >= 1) but the low-pass's group delay and the update rate allow at most {hi:.4} Hz; raise board.lpf_cutoff_hz or pll.damping"
            ),
        );
        if fits {
            p.check(
            natural.is_finite() && natural >= lo && natural <= hi,
            "pll.natural_hz",
            natural,
            format!("must be within {lo:.4} .. {hi:.4} Hz (2 damping w_n tau >= 1, and at most a tenth of the update rate and 0.05 rad of low-pass lag)"),
        );
        }
        if let Some(t) = self.pll_lock_s() {
            let min = 5.0 / (pll.damping * core::f64::consts::TAU * natural);
            p.check(
                t.is_finite() && t >= min,
                "pll.lock_s",
                t,
                format!("must cover at least 5 loop time constants 1/(damping 2 pi natural_hz) = {min:.4} s"),
            );
        }
    }
}
