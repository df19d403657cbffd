//! Validation of the noise, ADC and self-calibration keys (kept apart from the core rules of
//! `validate.rs`; same error form: key, value, rule).

use crate::config::Config;
use crate::rules::Rules;
use crate::schema::{CONVERTER_BITS, PLL_MODE};
use crate::validate::MAX_RUN_SAMPLES;
use crate::validate_regime::{check_level, NODE_RANGE};
use gyroemu_core::noise::{held_white_sigma, white_sigma};
use gyroemu_core::Response;
use gyroemu_tia::Tia;

/// The largest of a run's Gaussian draws in standard deviations: of at most 2^53 draws, one
/// exceeds 9 sigma with probability about 2e-3 (2^53 x P(|g| > 9) = 2^53 x 2.3e-19).
const PEAK_SIGMAS: f64 = 9.0;

/// The phases the board takes sines of are accurate to about 2e-16 up to this size, rad
/// (gyroemu_core::detmath; beyond it the reduction loses bits, and far beyond it the sines
/// are no longer bounded).
const MAX_PHASE_RAD: f64 = 1e6;

/// The Brownian force per unit mass as the board draws it (`held_white_sigma` of
/// `thermomechanical_accel_psd`), with sinc(x) = sin(pi x) / (pi x).
const BROWNIAN_FORCE: &str = "sqrt(4 k temperature_k w0 / (q effective_mass_kg) x fs_hz/2) / sinc(f0/fs_hz), w0 = 2 pi f0, sinc(x) = sin(pi x)/(pi x)";

/// The velocity's stationary deviation: sqrt(S_a q / (4 w0)), i.e. equipartition.
const BROWNIAN_VELOCITY: &str =
    "sqrt(k temperature_k / effective_mass_kg), the stationary deviation";

impl Config {
    /// The rules of the `[noise]` and `[selfcal]` sections and of the ADC keys.
    pub(crate) fn validate_noise_adc_selfcal(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let b = &self.board;
        if let Some(bits) = b.adc_bits {
            p.check(
                CONVERTER_BITS.contains(bits),
                "board.adc_bits",
                bits,
                CONVERTER_BITS.rule(),
            );
        }
        check_level(p, "board.adc_full_scale_v", b.adc_full_scale_v);
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
            // The corner is to blame when the white level's own per-sample deviation is in
            // the node range (else that level is, as its white rule would say).
            let i_v = n.tia_voltage_noise_v_per_rthz / b.tia_gain_ohm;
            if (i_v * i_v * 0.5 * self.fs_hz()).sqrt() <= NODE_RANGE.1 {
                named[0] = levels[0];
            }
            let psds = board_noise.flicker_psds_at_1hz(b.tia_gain_ohm);
            // No corner, no TIA flicker: its rule would weigh inf x 0 (the white level's
            // own rule is `validate_noise_range`).
            let on = [n.tia_voltage_flicker_corner_hz > 0.0, true, true, true];
            for ((((key, v), (_, psd)), ok), on) in
                named.into_iter().zip(psds).zip(levels_ok).zip(on)
            {
                if on && ok && p.clean(&["board.tia_gain_ohm", key]) {
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
                // The TIA's flicker runs at fs_hz: the bound of the fastest source serves all.
                let min = gyroemu_core::flicker::min_f_lo_hz(self.fs_hz());
                p.check(
                    f_lo.is_finite() && f_lo >= min && f_lo <= max,
                    "noise.flicker_f_lo_hz",
                    f_lo,
                    format!(
                        "must be from {min:e} Hz (below it the lowest flicker pole at fs_hz, exp(-2 pi f_lo / fs_hz), lies within 1000 ulps of 1 and is realised off by more than 0.1 %) to fs_out/200 = {max} Hz (the slow flicker sources run at the output rate and need two decades of 1/f below its half)"
                    ),
                );
            }
            self.warn_tia_flicker_at_carrier(p, warnings);
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
                "must be finite and of magnitude below 1e4 ppm/K",
            );
            p.check(
                s.q_tc_ppm_per_k.is_finite() && s.q_tc_ppm_per_k.abs() < 1e5,
                "selfcal.q_tc_ppm_per_k",
                s.q_tc_ppm_per_k,
                "must be finite and of magnitude below 1e5 ppm/K",
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
            PLL_MODE.contains(pll.mode),
            "pll.mode",
            pll.mode,
            format!(
                "{} (the mode whose output the PLL locks on)",
                PLL_MODE.rule()
            ),
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
                "{}no loop fits: a PI on the frequency needs at least {lo:.4} Hz (2 damping w_n tau >= 1) but the low-pass's group delay and the update rate allow at most {hi:.4} Hz; raise board.lpf_cutoff_hz or pll.damping",
                // The key is not in the file: say whose value it is.
                // (parse_config fills derived keys in: equal to the derivation is derived.)
                if pll.natural_hz.is_none_or(|n| n.to_bits() == (lo * hi).sqrt().to_bits()) {
                    "(not set: its default, the geometric mean of these bounds) "
                } else {
                    ""
                }
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
        if let (Some(t), Some(tau)) = (self.pll_lock_s(), self.pll_time_constant_s()) {
            let min = 5.0 * tau;
            p.check(
                t.is_finite() && t >= min,
                "pll.lock_s",
                t,
                format!("must cover at least 5 of the loop's slowest time constants (1/(damping 2 pi natural_hz) up to damping 1, 1/(2 pi natural_hz (damping - sqrt(damping^2 - 1))) above) = {min:.4} s"),
            );
        }
    }
}

impl Config {
    /// Each noise source's level against the chain's representable range, once the chain's
    /// keys and the source's are each valid: the standard deviation the board gives it, per
    /// sample, carried to each node it reaches, must stay within the node range the regime
    /// rules hold the signal to (the signal rules cannot see noise, which filled the chain
    /// with inf and NaN after validation passed). `largest_node` is the largest signal
    /// amplitude of a node (in its unit).
    pub(crate) fn validate_noise_range(&self, p: &mut Rules, largest_node: f64) {
        let Some(n) = &self.noise else {
            return;
        };
        let Ok(tia) = Tia::<f64>::new(&self.board_params().tia) else {
            return;
        };
        let hi = NODE_RANGE.1;
        let fs = self.fs_hz();
        let plant = self.resonator_params();
        let modes = [plant.mode1, plant.mode2];
        let r = self.board.tia_gain_ohm;
        let white_gain = tia.white_noise_gain();
        // A white input current of density `d` A/sqrt(Hz): its per-sample deviation, as the
        // board draws it, and that through the TIA.
        let white = |d: f64| {
            let s = white_sigma(d * d, fs);
            (s, s * white_gain)
        };
        let within = |x: f64| x <= hi; // NaN is not
        let rule = |what: &str, s_i: f64, s_v: f64| {
            format!(
                "gives {what} a per-sample current of standard deviation {s_i:.3e} A (sqrt(density^2 fs_hz/2), as the board draws it) and {s_v:.3e} V at the TIA output (x {white_gain:.3e} ohm, the discretised TIA's white-noise gain tia_gain_ohm sqrt((1 - a)/(1 + a))), which must stay within {hi:e} (the node range, so products of two stay finite): lower it"
            )
        };
        let i_c = n.tia_current_noise_a_per_rthz;
        let e_n = n.tia_voltage_noise_v_per_rthz;
        let key_i = "noise.tia_current_noise_a_per_rthz";
        let key_e = "noise.tia_voltage_noise_v_per_rthz";
        let (si, vi) = white(i_c);
        let ok_i = p.clean(&[key_i])
            && p.check(
                within(si) && within(vi),
                key_i,
                i_c,
                rule("the TIA's input", si, vi),
            );
        let (se, ve) = white(e_n / r);
        let ok_e = p.clean(&[key_e])
            && p.check(
                within(se) && within(ve),
                key_e,
                e_n,
                rule("(as e_n / tia_gain_ohm at the TIA's input)", se, ve),
            );
        if ok_i && ok_e {
            // Both within alone, their sum in power can still leave it.
            let i_n = gyroemu_tia::input_referred_noise_a_per_rthz(i_c, e_n, r);
            let (s, v) = white(i_n);
            let (key, value) = if i_c >= e_n / r {
                (key_i, i_c)
            } else {
                (key_e, e_n)
            };
            p.check(
                within(s) && within(v),
                key,
                value,
                rule("with the other TIA noise density (in power)", s, v),
            );
        }

        // Brownian force: per-sample deviation as drawn, then the velocity's stationary
        // deviation sqrt(S_a Q / (4 w0)) (equipartition, k T / m) through transduction and TIA.
        // Each as sqrt(S_a) times the rest, so a deviation far out of range still prints as
        // the number its formula gives (S_a fs/2 overflowed to inf from m ~ 1e-300).
        if let Some(m) = n.effective_mass_kg {
            let key = "noise.effective_mass_kg";
            if p.clean(&[key, "noise.temperature_k"]) {
                let mut worst: Option<String> = None;
                for (k, mode) in modes.iter().enumerate() {
                    let psd = gyroemu_resonator::thermomechanical_accel_psd(
                        n.temperature_k,
                        m,
                        mode.f0_hz,
                        mode.q,
                    );
                    let w0 = core::f64::consts::TAU * mode.f0_hz;
                    let force = held_white_sigma(1.0, fs, mode.f0_hz) * psd.sqrt();
                    let v = psd.sqrt() * (mode.q / (4.0 * w0)).sqrt();
                    let i = v * self.device.transduction_a_s_per_m;
                    let out = i * tia.response(mode.f0_hz).norm();
                    let nodes = [
                        (
                            "force per unit mass",
                            force,
                            "m/s^2 per sample",
                            BROWNIAN_FORCE,
                        ),
                        ("velocity", v, "m/s", BROWNIAN_VELOCITY),
                        (
                            "motional current",
                            i,
                            "A",
                            "that velocity x device.transduction_a_s_per_m",
                        ),
                        (
                            "TIA output",
                            out,
                            "V",
                            "that current x |H(f0)| of the TIA as built",
                        ),
                    ];
                    if let Some((node, x, unit, formula)) =
                        nodes.into_iter().find(|&(_, x, _, _)| !within(x))
                    {
                        worst.get_or_insert(format!(
                            "with temperature_k = {} gives mode {} a Brownian {node} of standard deviation {x:.3e} {unit} ({formula}), which must stay within {hi:e} (the node range, so products of two stay finite): raise effective_mass_kg or lower temperature_k",
                            n.temperature_k,
                            k + 1
                        ));
                    }
                }
                if let Some(rule) = worst {
                    p.check(false, key, m, rule);
                }
            }
        }

        // Flicker: the exact stationary deviation of each designed source.
        if !self.has_flicker() || !p.clean(&["noise.flicker_f_lo_hz"]) {
            return;
        }
        let [tia_s1, amp_s1, drive_phi_s1, carrier_phi_s1] = self.flicker_psds_at_1hz();
        let fs_out = self.fs_out_hz();
        let deviation = |s1: f64, rate: f64| {
            if s1 == 0.0 {
                return 0.0;
            }
            self.flicker_design(s1, rate)
                .map_or(f64::NAN, |d| d.variance().sqrt())
        };
        let key_c = "noise.tia_voltage_flicker_corner_hz";
        if n.tia_voltage_flicker_corner_hz > 0.0 && p.clean(&[key_c, key_e]) {
            // Low-frequency current: the TIA passes it with its DC gain, |G| at most.
            let s = deviation(tia_s1, fs);
            let v = s * r;
            p.check(
                within(s) && within(v),
                key_c,
                n.tia_voltage_flicker_corner_hz,
                format!(
                    "gives the TIA's voltage flicker ((e_n / tia_gain_ohm)^2 x tia_voltage_flicker_corner_hz / f A^2/Hz, referred to the input) a per-sample current of standard deviation {s:.3e} A and about {v:.3e} V at the TIA output (x tia_gain_ohm), which must stay within {hi:e} (the node range): lower it or noise.tia_voltage_noise_v_per_rthz"
                ),
            );
        }
        let key_a = "noise.drive_amplitude_flicker_per_rthz";
        if p.clean(&[key_a]) {
            let s = deviation(amp_s1, fs_out);
            let scale = 1.0 + PEAK_SIGMAS * s;
            p.check(
                within(scale * largest_node),
                key_a,
                n.drive_amplitude_flicker_per_rthz,
                format!(
                    "gives each drive a relative amplitude of standard deviation {s:.3e}: at {PEAK_SIGMAS} of them (the largest of a run's draws) it scales the largest node's signal, about {largest_node:.3e}, to {:.3e}, outside the node range (at most {hi:e}, so products of two stay finite): lower it",
                    scale * largest_node
                ),
            );
        }
        let keys_phi = [
            "noise.drive_phase_flicker_rad_per_rthz",
            "noise.carrier_phase_flicker_rad_per_rthz",
        ];
        let levels_phi = [
            n.drive_phase_flicker_rad_per_rthz,
            n.carrier_phase_flicker_rad_per_rthz,
        ];
        let s_phi = [drive_phi_s1, carrier_phi_s1].map(|s1| deviation(s1, fs_out));
        if p.clean(&keys_phi) {
            // The board takes the sine of the carrier's phase plus a drive's.
            let peak = PEAK_SIGMAS * (s_phi[0] + s_phi[1]);
            let k = usize::from(s_phi[1] > s_phi[0]);
            p.check(
                peak <= MAX_PHASE_RAD,
                keys_phi[k],
                levels_phi[k],
                format!(
                    "gives a phase of standard deviation {:.3e} rad (drive and carrier phase flicker together: {:.3e} rad at {PEAK_SIGMAS} of them, the largest of a run's draws), beyond the {MAX_PHASE_RAD:e} rad within which the board's sines are accurate: lower it",
                    s_phi[0] + s_phi[1],
                    peak
                ),
            );
        }
    }
}

/// How far the TIA's noise density at the carrier may stray from its stated law before it is
/// said (in power: 5 %, about 2.5 % of a phase reading's scatter).
const TIA_FLICKER_EXCESS: f64 = 0.05;

impl Config {
    /// The TIA's voltage flicker is designed two poles a decade up to fs_hz/2 and holds its
    /// 1/f law within its ripple only below about fs_hz/20; a carrier above that sees the
    /// design's density, not `e_n^2 corner / f`. Warns when that moves the noise at the carrier
    /// (white and flicker, input-referred) by more than [`TIA_FLICKER_EXCESS`] from the stated
    /// `i_n^2 + (e_n/R)^2 (1 + corner / f)`: at fs_hz = 36 kHz the readings scattered 1.18
    /// times what the stated density gives, unwarned.
    fn warn_tia_flicker_at_carrier(&self, p: &Rules, warnings: &mut Vec<String>) {
        let Some(n) = &self.noise else {
            return;
        };
        let corner = n.tia_voltage_flicker_corner_hz;
        let keys = [
            "noise.tia_voltage_flicker_corner_hz",
            "noise.tia_voltage_noise_v_per_rthz",
            "noise.tia_current_noise_a_per_rthz",
            "noise.flicker_f_lo_hz",
            "board.tia_gain_ohm",
            "board.fs_hz",
        ];
        if corner <= 0.0 || n.tia_voltage_noise_v_per_rthz <= 0.0 || !p.clean(&keys) {
            return;
        }
        let fs = self.fs_hz();
        let fc = self.carrier_hz();
        let i_v2 = (n.tia_voltage_noise_v_per_rthz / self.board.tia_gain_ohm).powi(2);
        let s1 = self.flicker_psds_at_1hz()[0];
        let Some(design) = self.tia_flicker_design() else {
            return;
        };
        let (realised, stated) = (design.psd(fc), s1 / fc);
        let total = n.tia_current_noise_a_per_rthz.powi(2) + i_v2 + stated;
        let excess = (realised - stated) / total;
        if excess.abs() > TIA_FLICKER_EXCESS {
            warnings.push(format!(
                "noise.tia_voltage_flicker_corner_hz = {corner}: the TIA's voltage flicker is designed two poles a decade up to fs_hz/2 and follows its 1/f law within its ripple only below about fs_hz/20 = {} Hz; at the carrier ({fc} Hz) its density is {:.3} times the stated (e_n/tia_gain_ohm)^2 corner/f, which moves the TIA noise there by {:+.1} % in power from the stated i_n^2 + (e_n/tia_gain_ohm)^2 (1 + corner/f) (the noise rule counts the design's density); raise board.fs_hz",
                fs / 20.0,
                realised / stated,
                100.0 * excess
            ));
        }
    }
}
