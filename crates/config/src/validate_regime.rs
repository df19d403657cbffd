//! Rules about the regime a config puts the board in, checked before any sample: the plant must
//! be stable, every node's signal must stay far from overflow and underflow, a converter must
//! not put out a dead (all-zero) signal, and the DAC's hold must not move the measured phase by
//! more than a stated amount. Each names the key to change.

use crate::config::Config;
use crate::error::ConfigError;
use crate::rules::Rules;
use gyroemu_board::Shape;

/// Every node's amplitude must lie in this band (in its own unit): products of two stay finite
/// and normal, and no signal is rounded away in subnormals.
pub const NODE_RANGE: (f64, f64) = (1e-100, 1e100);

/// Above this hold error (mdeg) the board measures the hold's images more than the carrier:
/// refused.
pub const MAX_HOLD_ERROR_MDEG: f64 = 1000.0;

/// Above this hold error (mdeg) it is stated in a warning.
pub const WARN_HOLD_ERROR_MDEG: f64 = 0.01;

/// The steady-state amplitude at resonance of each node of mode `k` at zero rate: drive,
/// displacement, velocity, motional current, TIA output (an upper bound for every experiment:
/// rotation and the rotating envelope only lower it).
fn node_amplitudes(c: &Config, k: usize) -> [f64; 5] {
    let p = c.resonator_params();
    let mode = [p.mode1, p.mode2][k];
    let w = core::f64::consts::TAU * mode.f0_hz;
    let f = [c.drive.f1, c.f2()][k];
    let v = f * mode.q / w;
    let i = c.device.transduction_a_s_per_m * v;
    let pole = c
        .board
        .tia_pole_hz
        .map_or(1.0, |fp| 1.0 / (1.0 + (mode.f0_hz / fp).powi(2)).sqrt());
    [f, v / w, v, i, c.board.tia_gain_ohm * i * pole]
}

impl Config {
    /// The regime rules, for a config whose keys are each valid; appends warnings. An
    /// unstable plant or a node out of range stops them (the rest would weigh a chain that
    /// cannot run).
    pub(crate) fn validate_regime(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        if let Err(e) = self.resonator_params().validate() {
            let key = match e.param {
                "quadrature_coupling_rad2_s2" => "device.quadrature_coupling_rad2_s2",
                "mode2.f0_hz" => "device.mode2_f0_offset_hz",
                "mode2.q" => "device.q_mode2",
                _ => "device",
            };
            p.push(ConfigError::key(key, e.value, e.rule));
            return;
        }
        if let Err(e) = self.validate_node_range() {
            p.push(e);
            return;
        }
        self.validate_converters(p, warnings);
        self.validate_mixer_product(warnings);
        self.validate_table_harmonics(warnings);
        self.validate_table_step(warnings);
        self.validate_hold(p, warnings);
    }

    /// A rate table whose swing has more harmonics than the board demodulates: the read-out
    /// leaves the rest out (each moves the phase by about its relative size, in radians).
    fn validate_table_harmonics(&self, warnings: &mut Vec<String>) {
        if self.table_harmonics_needed().is_some() {
            return;
        }
        let Shape::RateTable { freq_hz } = self.shape() else {
            return;
        };
        let n = gyroemu_mixer::MAX_TABLE_HARMONIC;
        let env = self
            .driven_device()
            .rate_table_envelopes(self.max_rate_rad_s(), freq_hz, n + 1);
        let peak = env.iter().flatten().map(|v| v.norm()).fold(0.0, f64::max);
        let left = env
            .iter()
            .flat_map(|h| [h[0], h[2 * n + 2]])
            .map(|v| v.norm() / peak)
            .fold(0.0, f64::max);
        warnings.push(format!(
            "experiment.rates_dps: the largest rate-table amplitude swings the phase so far that its envelope has harmonics of the table frequency beyond the {n} the board demodulates (harmonic {} is {left:.1e} of the largest): expect read-out errors of order {:.1e} mdeg; lower the amplitude or raise experiment.table_freq_hz",
            n + 1,
            left.to_degrees() * 1e3
        ));
    }

    /// A rate table's plant step expands the step matrix to second order in the rate about
    /// rest, so each step is off by about its first term left out, (2 lambda Omega Ts)^3 / 6
    /// of the state, and the resonator sums about tau / Ts such steps before it forgets them
    /// (an error of order Ts^2: 5.8 mdeg at Q = 5, 3e5 deg/s and 240 kHz, with no warning
    /// before; the hold rule weighs the constant-rate plant, which is exact).
    fn validate_table_step(&self, warnings: &mut Vec<String>) {
        let Shape::RateTable { .. } = self.shape() else {
            return;
        };
        let ts = 1.0 / self.fs_hz();
        let x = 2.0 * self.device.angular_gain.abs() * self.max_rate_rad_s() * ts;
        let est_mdeg = (x.powi(3) / 6.0 * self.slowest_tau_s() / ts).to_degrees() * 1e3;
        if est_mdeg > WARN_HOLD_ERROR_MDEG {
            warnings.push(format!(
                "experiment.rates_dps: at the largest rate-table amplitude the plant's time-varying step (second order in the rate, 2 lambda Omega Ts = {x:.2e}) is off by about (2 lambda Omega Ts)^3/6 per step, summed over the resonator's tau/Ts steps: expect read-out errors of order {est_mdeg:.1e} mdeg; raise board.fs_hz (the error falls as fs^-2)"
            ));
        }
    }

    /// The first node out of range (one knob to turn), if any.
    fn validate_node_range(&self) -> Result<(), ConfigError> {
        const NODES: [(&str, &str); 5] = [
            ("drive", "m/s^2"),
            ("displacement", "m"),
            ("velocity", "m/s"),
            ("motional current", "A"),
            ("TIA output", "V"),
        ];
        let (lo, hi) = NODE_RANGE;
        for k in 0..2 {
            let a = node_amplitudes(self, k);
            let drive_key = ["drive.f1", "drive.f2"][k];
            for (n, (&amp, (node, unit))) in a.iter().zip(NODES).enumerate() {
                if (lo..=hi).contains(&amp) {
                    continue;
                }
                // The first node out of range names the knob: the drive sets the mechanical
                // nodes, then the transduction and the TIA gain scale the electrical ones.
                let (key, value) = match n {
                    0..=2 => (drive_key, a[0]),
                    3 => (
                        "device.transduction_a_s_per_m",
                        self.device.transduction_a_s_per_m,
                    ),
                    _ => ("board.tia_gain_ohm", self.board.tia_gain_ohm),
                };
                let what = if amp > hi {
                    "overflow (products of two values would leave the range of double-precision numbers, about 1e308)"
                } else {
                    "underflow (subnormal arithmetic, many times slower, rounds the signal away)"
                };
                return Err(ConfigError::key(
                    key,
                    value,
                    format!(
                        "the {node} of mode {} would be about {amp:e} {unit}, outside {lo:e}..{hi:e}: the chain would {what}",
                        k + 1
                    ),
                ));
            }
        }
        Ok(())
    }

    fn validate_converters(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let b = &self.board;
        let lsb = |bits: u32, full_scale: f64| full_scale / (1u64 << (bits - 1)) as f64;
        for k in 0..2 {
            let a = node_amplitudes(self, k);
            let drive_key = ["drive.f1", "drive.f2"][k];
            if let Some(bits) = b.dac_bits {
                let step = lsb(bits, b.dac_full_scale);
                p.check(
                    a[0] >= 0.5 * step,
                    drive_key,
                    a[0],
                    format!(
                        "is below half an LSB of the DAC ({step:e} = board.dac_full_scale / 2^(board.dac_bits - 1)): every drive sample would be 0; raise it or board.dac_bits, or lower board.dac_full_scale"
                    ),
                );
                if a[0] > b.dac_full_scale - 0.5 * step {
                    warnings.push(format!(
                        "{drive_key} = {} exceeds the DAC's range (board.dac_full_scale = {}): the drive's peaks will clip; raise board.dac_full_scale",
                        a[0], b.dac_full_scale
                    ));
                }
            }
            let tia_out = a[4];
            if let Some(bits) = b.adc_bits {
                let step = lsb(bits, b.adc_full_scale_v);
                // The amplitude is an estimate at resonance: refuse only a clearly dead ADC.
                p.check(
                    !(tia_out < 0.125 * step && self.noise.is_none()),
                    "board.adc_bits",
                    bits,
                    format!(
                        "the TIA output of mode {} (about {tia_out:e} V) is far below half an LSB of the ADC ({:e} V): every sample would read 0; raise board.tia_gain_ohm or board.adc_bits, or lower board.adc_full_scale_v",
                        k + 1,
                        0.5 * step
                    ),
                );
                if tia_out < 0.5 * step {
                    warnings.push(format!(
                        "the TIA output of mode {} (about {tia_out:e} V) is below half an LSB of the ADC ({:e} V): the signal survives only as dither of the noise",
                        k + 1,
                        0.5 * step
                    ));
                }
                if tia_out >= 0.5 * step {
                    let bound_mdeg = self.adc_phase_bound_mdeg(step, tia_out);
                    if bound_mdeg > WARN_HOLD_ERROR_MDEG {
                        warnings.push(format!(
                            "the ADC's LSB ({step:e} V) against the TIA output of mode {} (about {tia_out:e} V){}: its rounding error follows the carrier instead of averaging out and can move the measured phase by up to about {bound_mdeg:.3e} mdeg; raise board.adc_bits or lower board.adc_full_scale_v",
                            k + 1,
                            if self.noise.is_some() { " and the TIA noise there" } else { ", no noise to dither it" }
                        ));
                    }
                }
                if tia_out > b.adc_full_scale_v - 0.5 * step {
                    warnings.push(format!(
                        "the TIA output of mode {} (about {tia_out:e} V) exceeds the ADC's range (board.adc_full_scale_v = {}): it will clip; raise board.adc_full_scale_v or lower board.tia_gain_ohm",
                        k + 1,
                        b.adc_full_scale_v
                    ));
                }
            }
            if let Some(rail) = b.tia_rail_v {
                if tia_out > rail {
                    warnings.push(format!(
                        "the TIA output of mode {} (about {tia_out:e} V) exceeds board.tia_rail_v = {rail}: it will saturate; raise the rails or lower board.tia_gain_ohm",
                        k + 1
                    ));
                }
            }
        }
    }

    /// The stage-1 mixer's 2 f_c product, what the low-pass leaves of it, aliased by the
    /// decimation: a hand-set decimation whose output rate divides 2 f_c folds it onto DC
    /// (6 % of the scale factor at order 1, M = 8). It moves the phasor by at most
    /// |L(2 f_c)| x the averaging window's exact gain at the alias's distance from each
    /// frequency the read-out demodulates (DC; Omega when rotating; the table's harmonics).
    fn validate_mixer_product(&self, warnings: &mut Vec<String>) {
        let Ok(chain) = gyroemu_board::ChainResponse::new(&self.board_params()) else {
            return;
        };
        let (fc, fs_out) = (self.carrier_hz(), self.fs_out_hz());
        let leak = chain.lowpass(2.0 * fc).norm();
        let alias = 2.0 * fc - fs_out * (2.0 * fc / fs_out).round();
        let (mut worst, mut at): (f64, f64) = (0.0, 0.0);
        for rate in self.emulated_rates_dps() {
            let window = self.plan_point(rate).window;
            let refs: Vec<f64> = match self.shape() {
                Shape::Coriolis => vec![0.0],
                Shape::Rotating => vec![0.0, rate.abs() / 360.0],
                Shape::RateTable { freq_hz } => (0..=15).map(|h| h as f64 * freq_hz).collect(),
            };
            let (e, f) = mixer_product_bound_rad(&chain, fc, fs_out, &window, &refs);
            if e > worst {
                (worst, at) = (e, f);
            }
        }
        let worst_mdeg = worst.to_degrees() * 1e3;
        if worst_mdeg > WARN_HOLD_ERROR_MDEG {
            warnings.push(format!(
                "board.decimation = {}: the stage-1 mixer's 2 f_c product ({} Hz), {:.1e} of it left by the low-pass, aliases to {:.6e} Hz at the output rate {fs_out} Hz, too close to the {at} Hz the read-out demodulates for its averaging to remove it: it can move the measured phase by up to {worst_mdeg:.3e} mdeg; choose a decimation whose output rate does not divide 2 f_c (remove the key for the derived one), or raise board.lpf_order",
                self.decimation(),
                2.0 * fc,
                leak,
                alias.abs()
            ));
        }
    }

    /// The stepped sine's own mixer products: each frequency is the carrier of its reading
    /// (DC demodulated over `sweep.average_s`). Near fs/2 the 2 f product folds into the
    /// low-pass (`|L(2 f)|` of the sampled filter says so), and the decimation can fold what
    /// is left onto DC: both moved Bode points by up to 99.9 % with no warning.
    pub(crate) fn validate_sweep_mixer_products(&self, warnings: &mut Vec<String>) {
        let Ok(chain) = gyroemu_board::ChainResponse::new(&self.board_params()) else {
            return;
        };
        let fs_out = self.fs_out_hz();
        let average = self.sweep_resolved().average_s.unwrap_or(f64::NAN);
        let n = (average * fs_out).floor();
        if n.is_nan() || n < 1.0 {
            return;
        }
        let window = gyroemu_lpf::Window::Boxcar {
            n: n as u64,
            frac: 0.0,
        };
        let (mut worst, mut at) = (0.0f64, f64::NAN);
        for f in self.sweep_frequencies_hz() {
            let (e, _) = mixer_product_bound_rad(&chain, f, fs_out, &window, &[0.0]);
            if e > worst {
                (worst, at) = (e, f);
            }
        }
        let worst_mdeg = worst.to_degrees() * 1e3;
        if worst_mdeg > WARN_HOLD_ERROR_MDEG {
            warnings.push(format!(
                "sweep: at {at} Hz the stage-1 mixer's 2 f product, as the low-pass leaves it and the decimation folds it, is not averaged away: it can move that Bode point by up to {worst_mdeg:.3e} mdeg in phase ({:.1e} of its magnitude); keep sweep.stop_hz below (fs_hz - lpf_cutoff_hz)/2 and choose a decimation whose output rate does not divide 2 f, or raise board.lpf_order",
                worst.sin()
            ));
        }
    }

    /// How far the ADC's systematic rounding error can move the measured phase, mdeg: its
    /// bias under the TIA's white noise (a lower bound on the noise there, so an upper bound
    /// on the bias) against the carrier's amplitude.
    fn adc_phase_bound_mdeg(&self, step: f64, amplitude: f64) -> f64 {
        let b = &self.board;
        let sigma = self.noise.as_ref().map_or(0.0, |n| {
            let density = gyroemu_tia::input_referred_noise_a_per_rthz(
                n.tia_current_noise_a_per_rthz,
                n.tia_voltage_noise_v_per_rthz,
                b.tia_gain_ohm,
            );
            // A one-pole TIA passes pi/2 of its pole frequency of white noise.
            let band = b
                .tia_pole_hz
                .map_or(f64::INFINITY, |fp| core::f64::consts::FRAC_PI_2 * fp)
                .min(0.5 * self.fs_hz());
            b.tia_gain_ohm * density * band.sqrt()
        });
        let bias = gyroemu_theory::quantiser_bias_bound(step, sigma);
        gyroemu_theory::quantiser_phase_bound_rad(bias, amplitude).to_degrees() * 1e3
    }

    /// The DAC holds each drive sample for a period: the measured phase departs from the
    /// continuous-drive theory by what the exact held-drive steady state says. Stated when it
    /// matters, refused when the hold's images dominate.
    fn validate_hold(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let dev = self.driven_device();
        let deg = core::f64::consts::PI / 180.0;
        let mut worst: f64 = 0.0;
        for &r in &self.experiment.rates_dps {
            let omega = r * deg;
            let (held, exact) = match self.shape() {
                Shape::Rotating => (
                    dev.held_rotating_psi_rad(omega),
                    dev.rotating_psi_rad(omega),
                ),
                // A rate table swings through its amplitude: the Coriolis phase there bounds it.
                _ => (
                    dev.held_coriolis_phase_rad(omega),
                    dev.coriolis_phase_rad(omega),
                ),
            };
            for k in 0..2 {
                // A phase and the same plus 180 degrees read alike (the sidebands' branch):
                // only the difference within a half turn is the hold's.
                let d = held[k] - exact[k];
                let d = d - core::f64::consts::PI * (d / core::f64::consts::PI).round();
                let e = (d / deg * 1e3).abs();
                // A NaN (an unbuildable plant) is reported by the other rules.
                if e.is_finite() {
                    worst = worst.max(e);
                }
            }
        }
        let per_period = self.fs_hz() / self.device.f0_hz;
        p.check(
            worst <= MAX_HOLD_ERROR_MDEG,
            "board.fs_hz",
            self.fs_hz(),
            format!(
                "at {per_period:.2} samples per carrier period the DAC's zero-order hold moves the measured phase by up to {worst:.3e} mdeg from the continuous-drive theory (its images beside the carrier dominate); raise fs_hz (16 samples per period keeps it near 0.01 mdeg)"
            ),
        );
        if worst > WARN_HOLD_ERROR_MDEG {
            warnings.push(format!(
                "board.fs_hz = {} ({per_period:.2} samples per carrier period): the DAC's zero-order hold moves the measured phase by up to {worst:.3e} mdeg from the continuous-drive theory at these rates (the exact held-drive steady state); raise fs_hz to shrink it",
                self.fs_hz()
            ));
        }
    }
}

/// The largest phase error, rad, the stage-1 mixer's 2 `fc` product leaves on a reading
/// demodulated at each of `refs` over `window`: |L(2 fc)| of the sampled low-pass times the
/// window's response at the distance of the product's alias at `fs_out` from each reference;
/// with the reference it is largest at.
fn mixer_product_bound_rad(
    chain: &gyroemu_board::ChainResponse,
    fc: f64,
    fs_out: f64,
    window: &gyroemu_lpf::Window,
    refs: &[f64],
) -> (f64, f64) {
    let leak = chain.lowpass(2.0 * fc).norm();
    let alias = 2.0 * fc - fs_out * (2.0 * fc / fs_out).round();
    let (mut worst, mut at) = (0.0f64, 0.0);
    for &f in refs {
        for df in [alias - f, alias + f] {
            let e = (leak * window.response(df / fs_out).norm()).min(1.0).asin();
            if e > worst {
                (worst, at) = (e, f);
            }
        }
    }
    (worst, at)
}
