//! Rules about the regime a config puts the board in, checked before any sample: the plant must
//! be stable, every node's signal must stay far from overflow and underflow, a converter must
//! not put out a dead (all-zero) signal, and the DAC's hold must not move the measured phase by
//! more than a stated amount. Each names the key to change.

use crate::config::Config;
use crate::error::ConfigError;
use crate::plan::DEG;
use crate::rules::Rules;
use gyroemu_board::{ChainResponse, Shape};
use gyroemu_core::{Complex64, Response};
use gyroemu_mixer::NoFundamental;
use gyroemu_resonator::continuous_steady_state;

/// |a - b| in mdeg within a half turn: a phase and the same plus 180 degrees read alike (the
/// sidebands' branch), so only the difference within a half turn is a converter's or the
/// hold's. NaN stays NaN.
pub(crate) fn half_turn_mdeg(a: f64, b: f64) -> f64 {
    mdeg_within(a, b, core::f64::consts::PI)
}

/// |a - b| in mdeg within a whole turn (a Coriolis phase's difference). NaN stays NaN.
pub(crate) fn turn_mdeg(a: f64, b: f64) -> f64 {
    mdeg_within(a, b, core::f64::consts::TAU)
}

/// |a - b| in mdeg, moved by whole `period`s (rad) to within half of one.
fn mdeg_within(a: f64, b: f64, period: f64) -> f64 {
    let d = a - b;
    let d = d - period * (d / period).round();
    (d / DEG * 1e3).abs()
}

/// Every node's amplitude must lie in this band (in its own unit): products of two stay finite
/// and normal, and no signal is rounded away in subnormals.
pub const NODE_RANGE: (f64, f64) = (1e-100, 1e100);

/// A clamp level (a converter's full scale, the TIA's rails): > 0 and inside [`NODE_RANGE`],
/// since a clipped sample takes it as its value.
pub(crate) fn check_level(p: &mut Rules, key: &str, v: f64) -> bool {
    let (lo, hi) = NODE_RANGE;
    p.positive(key, v)
        && p.check(
            (lo..=hi).contains(&v),
            key,
            v,
            format!(
                "must lie in {lo:e} ..= {hi:e}, the band every node's signal is held to: a clipped sample takes this level, and beyond the band the chain's products leave the normal numbers (at 1e-300 a run went 30 to 80 times slower and ended in NaN phases)"
            ),
        )
}

/// Above this hold error (mdeg) the board measures the hold's images more than the carrier:
/// refused.
pub const MAX_HOLD_ERROR_MDEG: f64 = 1000.0;

/// Above this gain of the sideband solve, `1 / (1 - |W(2 Omega)|)`, a rotating window cannot
/// part its two sidebands: refused (a rounding of the window's sums, 1e-16, is then amplified
/// past 1e-10).
pub const MAX_SIDEBAND_GAIN: f64 = 1e6;

/// Above this hold error (mdeg) it is stated in a warning.
pub const WARN_HOLD_ERROR_MDEG: f64 = 0.01;

/// The steady-state amplitude at resonance of each node of mode `k` at zero rate: drive,
/// displacement, velocity, motional current, TIA output. Only an order of magnitude (a
/// detuned carrier or rotation moves it by a factor of order Q at most), which is all the
/// node-range band needs; the converter rules weigh [`Config::tia_output_span`] instead.
fn node_amplitudes(c: &Config, k: usize) -> [f64; 5] {
    let p = c.resonator_params();
    let mode = [p.mode1, p.mode2][k];
    let w = core::f64::consts::TAU * mode.f0_hz;
    let f = [c.drive.f1, c.f2()][k];
    let v = f * mode.q / w;
    let i = c.device.transduction_a_s_per_m * v;
    [
        f,
        v / w,
        v,
        i,
        c.board.tia_gain_ohm * i * tia_pole_factor(c, mode.f0_hz),
    ]
}

/// Both modes' velocity envelopes on the rate table of amplitude `rate_dps` at `freq_hz`,
/// converged in harmonics ([`gyroemu_theory::converged_envelopes`]); `None` beyond the
/// theory's harmonics. What the winding and the harmonics rules weigh.
fn table_envelopes(
    dev: &gyroemu_theory::DrivenDevice,
    rate_dps: f64,
    freq_hz: f64,
) -> Option<[Vec<Complex64>; 2]> {
    gyroemu_theory::converged_envelopes(|m| {
        dev.rate_table_envelopes(rate_dps.abs() * DEG, freq_hz, m)
    })
}

/// A rate table's periodic steady states ([`Config::table_states`]): per rate, both modes'
/// velocity envelopes and their checked phase fundamentals, `None` beyond the theory's
/// harmonics.
struct TableStates {
    freq_hz: f64,
    rates: Vec<(f64, Option<TableState>)>,
}

/// Both modes' envelopes at one rate, each with its checked phase fundamental.
type TableState = [(Vec<Complex64>, Result<Complex64, NoFundamental>); 2];

/// A rate table whose swing takes a mode's velocity envelope around zero within a table
/// period: its phase then turns a whole turn per period and has no lag to read, so the
/// run could only refuse that mode's reading after every sample (it did, blaming an
/// overflow: a 1.5 Hz mode split with drive.f2 = 0.5 at 100 deg/s). The exact periodic
/// steady state (`tables`, `None` off a rate table) says so before the run; the first such
/// rate and mode are named.
fn validate_table_winding(tables: Option<&TableStates>) -> Result<(), ConfigError> {
    let Some(tables) = tables else {
        return Ok(());
    };
    let freq_hz = tables.freq_hz;
    for (rate, state) in &tables.rates {
        // A swing beyond the theory's harmonics is the harmonics rule's to refuse.
        let Some(state) = state else {
            continue;
        };
        for (k, (_, fundamental)) in state.iter().enumerate() {
            let what = match fundamental {
                Ok(_) => continue,
                Err(NoFundamental::Winds) => "passes around zero once per table period",
                Err(NoFundamental::Unresolved) => "passes so near zero once per table period that its phase turns by nearly a half turn within 1e-5 of the period, and its fundamental cannot be resolved",
            };
            let drive = ["drive.f1", "drive.f2"][k];
            return Err(ConfigError::key(
                "experiment.rates_dps",
                *rate,
                format!(
                    "at this rate-table amplitude mode {}'s velocity envelope (its phasor at the carrier, exact periodic steady state) {what} ({freq_hz} Hz): what the rate couples in from the other mode outweighs the mode's own driven response at the swing's peaks, so there is no lag or amplitude to read; lower the amplitude, raise {drive}, or bring the mode nearer the carrier",
                    k + 1
                ),
            ));
        }
    }
    Ok(())
}

/// |H(f)| / tia_gain_ohm of the TIA as built (its discretised pole, not the analogue one,
/// whose factor differs where the pole's coefficient rounds); 1 without a pole.
fn tia_pole_factor(c: &Config, f_hz: f64) -> f64 {
    if c.board.tia_pole_hz.is_none() {
        return 1.0;
    }
    gyroemu_tia::Tia::<f64>::new(&c.board_params().tia)
        .map_or(0.0, |t| t.response(f_hz).norm() / c.board.tia_gain_ohm)
}

impl Config {
    /// The regime rules, for a config whose keys are each valid; appends warnings. An
    /// unstable plant or a node out of range stops them (the rest would weigh a chain that
    /// cannot run).
    /// `locked`: this is a `[pll]` config's expected lock ([`Config::expected_lock`]), whose
    /// carrier sits near, not on, its value, at an offset against the samples no rule can know.
    pub(crate) fn validate_regime(&self, p: &mut Rules, warnings: &mut Vec<String>, locked: bool) {
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
        // The table's rules weigh its frequency and window: only once those keys are valid.
        let table_keys = ["experiment.table_freq_hz", "experiment.average_s"];
        // Both table rules weigh the same periodic steady states: computed once.
        let mut tables = None;
        if p.clean(&table_keys) {
            tables = self.table_states();
            if let Err(e) = validate_table_winding(tables.as_ref()) {
                p.push(e);
                return;
            }
        }
        self.validate_sideband_solve(p, warnings);
        let largest = (0..2)
            .flat_map(|k| node_amplitudes(self, k))
            .fold(0.0, f64::max);
        self.validate_noise_range(p, largest);
        self.validate_converters(p, warnings);
        if p.clean(&[
            "noise.temperature_k",
            "noise.effective_mass_kg",
            "noise.tia_current_noise_a_per_rthz",
            "noise.tia_voltage_noise_v_per_rthz",
        ]) {
            self.validate_noise_phase(warnings);
        }
        self.validate_dac_rounding(warnings, locked);
        self.validate_mixer_product(warnings);
        self.validate_lowpass_rounding(warnings);
        if p.clean(&table_keys) {
            // Clean now, so clean before (a rule only adds errors): the states are there.
            let tables = tables.or_else(|| self.table_states());
            self.validate_table_harmonics(p, warnings, tables.as_ref());
            self.validate_table_nyquist(warnings);
        }
        self.validate_hold(p, warnings);
        self.warn_unresolved_phases(warnings);
    }

    /// A rate table whose demodulated harmonics reach past the decimated output's Nyquist:
    /// in the decimated samples harmonic n aliases onto harmonic m wherever (n - m) f_t
    /// nears a multiple of fs_out. The read-out still solves them apart exactly through the
    /// window's leak (a noiseless run reads to 1e-4 mdeg), but ill-conditioned, and it then
    /// divides each by the low-pass's gain at its own frequency: the noise and the filter's
    /// rounding aliased onto a harmonic far down the low-pass's skirt are multiplied back up.
    /// A 9 Hz table read to its 15th harmonic behind a 10 Hz fourth-order low-pass (fs_out =
    /// 210.5 Hz) scattered 0.5 to 3.2 deg at 15000 deg/s, and 8 to 41 mdeg at 200 deg/s where
    /// 3 mdeg of noise was stated; with fs_out above 2 N f_t, 23 to 30 and 3 to 8 mdeg.
    fn validate_table_nyquist(&self, warnings: &mut Vec<String>) {
        let Shape::RateTable { freq_hz } = self.shape() else {
            return;
        };
        let n = self.table_harmonics();
        let top = n as f64 * freq_hz;
        let nyquist = 0.5 * self.fs_out_hz();
        if n == 0 || top <= nyquist {
            return;
        }
        let gain = gyroemu_board::ChainResponse::new(&self.board_params())
            .map_or(f64::NAN, |c| c.lowpass(top).norm() / c.lowpass(0.0).norm());
        warnings.push(format!(
            "experiment.table_freq_hz = {freq_hz}: the read-out demodulates the table's harmonics up to the {n}th ({top} Hz), past the decimated output's Nyquist frequency ({nyquist:.6} Hz, fs_out = fs_hz / board.decimation): there harmonics alias onto one another, the read-out tells them apart only through its averaging window, and it divides each by the low-pass's gain at its own frequency ({gain:.3e} of the DC gain at {top} Hz), which multiplies the noise and the filter's rounding aliased there back up: the readings can be off far beyond the noise and rounding stated (a 9 Hz table read to its 15th harmonic at fs_out = 210.5 Hz was 3.2 deg off where 3 mdeg of noise was stated); raise fs_out above {:.6} Hz (a smaller board.decimation, which a higher board.lpf_cutoff_hz derives), or lower the amplitude or the table frequency",
            2.0 * top
        ));
    }

    /// A rate table whose swing has more harmonics than the board demodulates: the read-out
    /// takes the phase's fundamental of harmonics `-N ..= N`, into which the rest leak through
    /// the window; the converged periodic steady state, put through the read-out's own steps,
    /// gives exactly what it reads, so the error is stated as it is (an estimate from a
    /// 16-harmonic balance had stated 4.9e4 mdeg where a 785-degree swing read 119 degrees).
    /// Refused where the amplitude read is more than 1000 mdeg off, or where the swing needs
    /// more harmonics than the theory takes.
    fn validate_table_harmonics(
        &self,
        p: &mut Rules,
        warnings: &mut Vec<String>,
        tables: Option<&TableStates>,
    ) {
        if self.table_harmonics_needed().is_some() {
            return;
        }
        let Some(tables) = tables else {
            return;
        };
        let freq_hz = tables.freq_hz;
        let n = self.table_harmonics();
        let chain = gyroemu_board::ChainResponse::new(&self.board_params()).ok();
        let fc = self.carrier_hz();
        let (mut amp_err, mut lag_err, mut at) = (0.0f64, 0.0f64, f64::NAN);
        let mut read_at = (f64::NAN, f64::NAN);
        for (rate, state) in &tables.rates {
            let rate = *rate;
            let Some(state) = state else {
                p.push(ConfigError::key(
                    "experiment.rates_dps",
                    rate,
                    format!(
                        "this rate-table amplitude swings the phase so far that its envelope needs more than {} harmonics of the table frequency (the board demodulates {n}): it can be neither read nor its theory given; lower the amplitude or raise experiment.table_freq_hz",
                        gyroemu_theory::MAX_THEORY_HARMONICS
                    ),
                ));
                return;
            };
            let point = self.plan_point(rate);
            // The window's leak K(d) for |d| up to 2 big, once for both modes: its middle,
            // |d| <= 2N, is the leak the read-out solves (the same sums, the same bits).
            let big = state
                .iter()
                .map(|(h, _)| (h.len() / 2).div_ceil(2))
                .max()
                .unwrap_or(0)
                + n;
            let k_all = chain
                .as_ref()
                .map(|chain| chain.table_leak(&point, self.n_settle_out(), big));
            for (h, fundamental) in state {
                let c = h.len() / 2;
                let full = fundamental.unwrap_or(Complex64::new(f64::NAN, f64::NAN));
                // What the read-out makes of the whole envelope: every harmonic m through
                // the chain (L(m f_t) H(f_c + m f_t)) and the window's leak K(m - r) into
                // each read harmonic r, the leak solve within -N ..= N, the chain divided out,
                // then the fundamental. Exact for any window (the truncation alone, through a
                // whole-period boxcar; a Hann window's leak of the harmonics beyond read 9.2
                // mdeg where the truncation is 2.0).
                let read = chain.as_ref().zip(k_all.as_ref()).map_or(
                    Complex64::new(f64::NAN, f64::NAN),
                    |(chain, k_all)| {
                        let resp =
                            |m: f64| chain.lowpass(m * freq_hz) * chain.tia(fc + m * freq_hz);
                        let avg: Vec<Complex64> = (-(n as i64)..=n as i64)
                            .map(|r| {
                                (0..h.len())
                                    .map(|i| {
                                        let m = i as i64 - c as i64;
                                        h[i] * resp(m as f64)
                                            * k_all[(m - r + 2 * big as i64) as usize]
                                    })
                                    .sum()
                            })
                            .collect();
                        let solved = gyroemu_board::unleak_table_harmonics(
                            &avg,
                            &k_all[2 * (big - n)..=2 * (big + n)],
                        );
                        let v: Vec<Complex64> = solved
                            .iter()
                            .enumerate()
                            .map(|(i, x)| x / resp(i as f64 - n as f64))
                            .collect();
                        gyroemu_mixer::phase_fundamental_fine(&v)
                    },
                );
                let a = (read.norm() - full.norm()).abs() / DEG * 1e3;
                let l = turn_mdeg(read.arg(), full.arg());
                if a.is_nan() || a > amp_err {
                    (amp_err, at) = (a, rate);
                    read_at = (read.norm() / DEG, full.norm() / DEG);
                }
                if l.is_finite() {
                    lag_err = lag_err.max(l);
                }
            }
        }
        let what = format!(
            "the board demodulates harmonics -{n} ..= {n} of the table frequency and reads the phase's fundamental from them alone; the swing has more (at {at} deg/s it reads an amplitude of {:.6} deg where the periodic steady state's is {:.6})",
            read_at.0, read_at.1
        );
        if amp_err.is_nan() || amp_err > MAX_HOLD_ERROR_MDEG {
            p.push(ConfigError::key(
                "experiment.rates_dps",
                at,
                format!("{what}; lower the amplitude or raise experiment.table_freq_hz"),
            ));
        } else if amp_err.max(lag_err) > WARN_HOLD_ERROR_MDEG {
            warnings.push(format!(
                "experiment.rates_dps: {what}: the amplitudes read are off by up to {amp_err:.3e} mdeg and the lags by up to {lag_err:.3e} mdeg (the read-out of the whole periodic steady state, the window's leak of the harmonics beyond included); lower the amplitude or raise experiment.table_freq_hz"
            ));
        }
    }

    /// Each rate's mode envelopes on the rate table ([`table_envelopes`]) with their checked
    /// phase fundamentals; `None` off a rate table.
    fn table_states(&self) -> Option<TableStates> {
        let Shape::RateTable { freq_hz } = self.shape() else {
            return None;
        };
        let dev = self.driven_device();
        let rates = self
            .experiment
            .rates_dps
            .iter()
            .map(|&rate| {
                let state = table_envelopes(&dev, rate, freq_hz).map(|env| {
                    env.map(|h| {
                        let f = gyroemu_mixer::phase_fundamental_checked(&h);
                        (h, f)
                    })
                });
                (rate, state)
            })
            .collect();
        Some(TableStates { freq_hz, rates })
    }

    /// A rotating point reads its two sidebands f_c +- Omega from the window's averages of the
    /// stage-2 outputs, removing what the window keeps of the 2 Omega term, `W = W(2 Omega)`:
    /// the solve inverts `[[1, conj W], [W, 1]]`, whose eigenvalues are `1 +- |W|`, so it
    /// multiplies an error of the averages by up to `1 / (1 - |W|)`. A window of one output
    /// sample keeps all of it (a Hann window of one sample was accepted and read NaN,
    /// "overflowed"): refused where the gain passes [`MAX_SIDEBAND_GAIN`]. Above 10 every
    /// other error of the reading (noise, converters, the hold) is multiplied by up to it:
    /// warned with the gain.
    fn validate_sideband_solve(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        if !matches!(self.shape(), Shape::Rotating) {
            return;
        }
        let fs_out = self.fs_out_hz();
        let mut worst: Option<(f64, f64, f64)> = None;
        for &rate in self.experiment.rates_dps.iter().filter(|r| **r != 0.0) {
            let window = self.plan_point(rate).window;
            let fm = rate.abs() / 360.0;
            let kept = window.response(2.0 * fm / fs_out).norm();
            if worst.is_none_or(|(k, _, _)| kept > k) {
                worst = Some((kept, rate, window.span()));
            }
        }
        let Some((kept, rate, n)) = worst else {
            return;
        };
        let gain = 1.0 / (1.0 - kept);
        let window = match self.experiment.window {
            crate::WindowKind::Hann => "Hann",
            crate::WindowKind::Boxcar => "boxcar",
        };
        let what = format!(
            "at {rate} deg/s the {window} window of {n} output samples keeps |W(2 Omega)| = {kept:.6} of the stage-2 product at 2 Omega, and the read-out parts the sidebands f_c +- Omega by a solve that multiplies errors by up to 1/(1 - |W|) = {gain:.3e}"
        );
        // Fails closed: |W| rounded to 1 or above (a negative gain) is refused too.
        if kept.is_nan() || kept >= 1.0 - 1.0 / MAX_SIDEBAND_GAIN {
            p.push(ConfigError::key(
                "experiment.average_s",
                self.experiment.average_s,
                format!(
                    "{what}: the two sidebands cannot be told apart; average over more output samples (a longer average_s, or a smaller board.decimation)"
                ),
            ));
        } else if gain > 10.0 {
            warnings.push(format!(
                "experiment.average_s = {}: {what}: every other error of the reading (noise, converters, the DAC hold) is multiplied by up to that, which the figures other warnings state do not include; average over more output samples",
                self.experiment.average_s
            ));
        }
    }

    /// A low-pass whose cutoff is a tiny fraction of the sample rate: each direct-form section
    /// holds its states near `1 / A(1)` times its input (`A(1)` about `(2 pi fc/fs)^2`), so
    /// the rounding of every sample is that much larger than the signal's own resolution, and
    /// it falls unevenly on I and Q. A Coriolis phase moved by 1.7 mdeg at fc/fs = 1.7e-7 and
    /// by 77.5 mdeg at 2e-8 with no warning (neither settling nor averaging removes it). The
    /// bound stated, `eps * sum_k 1/|A_k(1)|` in rad, is the rounding's reach; runs read 8 to
    /// 41 times less. A rotating run reads psi from the sidebands' ratio in each channel and
    /// measured far less (0.004 mdeg where the bound is 22), so it is not warned.
    fn validate_lowpass_rounding(&self, warnings: &mut Vec<String>) {
        if matches!(self.shape(), Shape::Rotating) {
            return;
        }
        let Ok(lp) = gyroemu_lpf::LowPass::<f64>::new(self.lowpass_design(), self.fs_hz()) else {
            return;
        };
        let reach_mdeg = (f64::EPSILON * lp.rounding_gain()).min(1.0).asin() / DEG * 1e3;
        if reach_mdeg > WARN_HOLD_ERROR_MDEG {
            warnings.push(format!(
                "board.lpf_cutoff_hz = {} is {:.2e} of board.fs_hz: the low-pass's direct-form sections hold their states about {:.1e} times their input, so each sample's rounding is that much coarser than the signal and falls unevenly on I and Q; the measured phase can move by up to about {reach_mdeg:.3e} mdeg (the rounding's reach; runs have read 8 to 41 times less, and neither settling nor averaging removes it); raise lpf_cutoff_hz or lower fs_hz",
                self.lpf_cutoff_hz(),
                self.lpf_cutoff_hz() / self.fs_hz(),
                lp.rounding_gain() / lp.sections() as f64
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
                    // The pole's attenuation alone took an output the gain keeps in range
                    // out of it: the pole is the knob.
                    _ if (lo..=hi).contains(&(self.board.tia_gain_ohm * a[3])) => {
                        let pole = self.board.tia_pole_hz.unwrap_or(f64::NAN);
                        return Err(ConfigError::key(
                            "board.tia_pole_hz",
                            pole,
                            format!(
                                "the TIA output of mode {} would be about {amp:e} V (tia_gain_ohm x motional current = {:e} V, times the pole's attenuation {:e} at {} Hz), outside {lo:e}..{hi:e}: the chain would underflow (subnormal arithmetic, many times slower, rounds the signal away); raise board.tia_pole_hz (or remove it for a wide-band TIA)",
                                k + 1,
                                self.board.tia_gain_ohm * a[3],
                                amp / (self.board.tia_gain_ohm * a[3]),
                                [self.device.f0_hz, self.f0_mode2_hz()][k],
                            ),
                        ));
                    }
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

    /// Per mode, the TIA output's amplitude over the run's points: the steady state of the
    /// configured device (detuning, mismatch, coupling, rotation) at the carrier, through the
    /// DAC hold's fundamental and the TIA as built. Coriolis: the exact amplitude at each rate
    /// (zero included). Rotating: the peak of the envelope, |V+| + |V-| over the sidebands at
    /// f_c +- f_m (its zeros are the modulation's, not a dead signal). Rate table: the extremes
    /// of the envelope over the table period (harmonic balance, 24 harmonics, on a fine grid).
    /// `None` when the chain cannot be built (other rules report it).
    fn tia_output_span(&self) -> Option<[AmpSpan; 2]> {
        let mut span = [AmpSpan::default(); 2];
        for (rate, amps) in self.tia_output_per_rate()? {
            for (s, (lo, hi)) in span.iter_mut().zip(amps) {
                s.include(lo, hi, rate);
            }
        }
        Some(span)
    }

    /// [`Config::tia_output_span`]'s amplitudes at each emulated rate (deg/s): per mode the
    /// smallest and the largest over the point's run.
    pub(crate) fn tia_output_per_rate(&self) -> Option<Vec<(f64, [LoHi; 2])>> {
        let chain = ChainResponse::new(&self.board_params()).ok()?;
        let plant = self.resonator_params();
        let dev = self.driven_device();
        let fc = self.carrier_hz();
        // Velocity to the ADC's input: transduction, the hold's fundamental, the TIA.
        let g = |f: f64| chain.dac_hold(f) * chain.tia(f) * self.device.transduction_a_s_per_m;
        let force = dev.coriolis_force();
        let mut per_rate = Vec::new();
        for rate in self.emulated_rates_dps() {
            let omega = rate * DEG;
            let amps: [(f64, f64); 2] = match self.shape() {
                Shape::Coriolis => {
                    let x = continuous_steady_state(&plant, omega, fc, force);
                    [0, 1].map(|k| {
                        let a = (x[2 + k] * g(fc)).norm();
                        (a, a)
                    })
                }
                Shape::Rotating => {
                    // The sidebands of THEORY.md section 4 (the shifter's error turns mode
                    // 2's), as DrivenDevice::rotating_psi_rad takes them.
                    let fm = omega / core::f64::consts::TAU;
                    let side = |sign: f64| {
                        let v = rotating_sideband(&dev, fc, fm, sign);
                        v.map(|v| v * g(fc + sign * fm))
                    };
                    let (vp, vm) = (side(1.0), side(-1.0));
                    [0, 1].map(|k| {
                        // At f_m = 0 both sidebands are one tone: their sum, not their sizes.
                        let a = if fm == 0.0 {
                            (vp[k] + vm[k]).norm()
                        } else {
                            vp[k].norm() + vm[k].norm()
                        };
                        (a, a)
                    })
                }
                Shape::RateTable { freq_hz } => {
                    const N: usize = 24;
                    let env = dev.rate_table_envelopes(omega, freq_hz, N);
                    [0, 1].map(|k| {
                        let h: Vec<Complex64> = env[k]
                            .iter()
                            .enumerate()
                            .map(|(i, &x)| x * g(fc + (i as f64 - N as f64) * freq_hz))
                            .collect();
                        envelope_extremes(&h)
                    })
                }
            };
            per_rate.push((rate, amps));
        }
        Some(per_rate)
    }

    fn validate_converters(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let b = &self.board;
        let lsb = |bits: u32, full_scale: f64| full_scale / (1u64 << (bits - 1)) as f64;
        let span = self.tia_output_span();
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
                        "is below half an LSB of the DAC ({:e}; one LSB is {step:e} = board.dac_full_scale / 2^(board.dac_bits - 1)): every drive sample would be 0; raise it or board.dac_bits, or lower board.dac_full_scale",
                        0.5 * step
                    ),
                );
                if a[0] > b.dac_full_scale - 0.5 * step {
                    warnings.push(format!(
                        "{drive_key} = {} exceeds the DAC's range (board.dac_full_scale = {}): the drive's peaks will clip; raise board.dac_full_scale",
                        a[0], b.dac_full_scale
                    ));
                }
            }
            let Some(s) = span.map(|s| s[k]) else {
                continue;
            };
            if !(s.min.is_finite() && s.max.is_finite()) {
                continue; // an unbuildable plant: reported by the other rules
            }
            // The dead-signal rules and the phase bound weigh the smallest amplitude, the
            // clipping rules the largest: each errs towards the warning.
            let (small, big) = (
                format!("about {:e} V at {} deg/s", s.min, s.min_at),
                format!("about {:e} V at {} deg/s", s.max, s.max_at),
            );
            if let Some(bits) = b.adc_bits {
                let step = lsb(bits, b.adc_full_scale_v);
                // The amplitude is the steady state's (the hold's images and the settling
                // transient can add a little): refuse only a clearly dead ADC.
                p.check(
                    !(s.min < 0.125 * step && self.noise.is_none()),
                    "board.adc_bits",
                    bits,
                    format!(
                        "the TIA output of mode {} ({small}) is far below half an LSB of the ADC ({:e} V): every sample would read 0; raise board.tia_gain_ohm or board.adc_bits, or lower board.adc_full_scale_v",
                        k + 1,
                        0.5 * step
                    ),
                );
                if s.min < 0.5 * step {
                    warnings.push(format!(
                        "the TIA output of mode {} ({small}) is below half an LSB of the ADC ({:e} V): {}",
                        k + 1,
                        0.5 * step,
                        if self.noise.is_some() {
                            "the signal survives only as dither of the noise"
                        } else {
                            "with no noise to dither it every sample there reads 0, and the run gives that mode no phase; raise board.tia_gain_ohm or board.adc_bits, or lower board.adc_full_scale_v"
                        }
                    ));
                } else {
                    let bound_mdeg = self.adc_phase_bound_mdeg(step, s.min);
                    if bound_mdeg > WARN_HOLD_ERROR_MDEG {
                        warnings.push(format!(
                            "the ADC's LSB ({step:e} V) against the TIA output of mode {} ({small}){}: its rounding error follows the carrier instead of averaging out and can move the measured phase by up to about {bound_mdeg:.3e} mdeg; raise board.adc_bits or lower board.adc_full_scale_v",
                            k + 1,
                            if self.noise.is_some() { " and the TIA noise there" } else { ", no noise to dither it" }
                        ));
                    }
                }
                if s.max > b.adc_full_scale_v - 0.5 * step {
                    warnings.push(format!(
                        "the TIA output of mode {} ({big}) exceeds the ADC's range (board.adc_full_scale_v = {}): it will clip; raise board.adc_full_scale_v or lower board.tia_gain_ohm",
                        k + 1,
                        b.adc_full_scale_v
                    ));
                }
            }
            if let Some(rail) = b.tia_rail_v {
                if s.max > rail {
                    warnings.push(format!(
                        "the TIA output of mode {} ({big}) exceeds board.tia_rail_v = {rail}: it will saturate; raise the rails or lower board.tia_gain_ohm",
                        k + 1
                    ));
                }
            }
        }
    }

    /// The stage-1 mixer's 2 f_c product, what the low-pass leaves of it, aliased by the
    /// decimation: a hand-set decimation whose output rate divides 2 f_c folds it onto DC
    /// (6 % of the scale factor at order 1, M = 8). Coriolis: the read-out averages the
    /// phasor (DC), which the product moves by at most |L(2 f_c)| x the window's exact gain at
    /// the alias. Rate table: the read-out takes harmonics -N ..= N of the table, and the
    /// product carries the envelope's own harmonics, so distances up to 2N table frequencies
    /// from the alias count. Rotating: see [`Config::rotating_mixer_product_bound_rad`] (it
    /// demodulates at +-f_m only, and what lands on DC there mostly cancels in psi).
    fn validate_mixer_product(&self, warnings: &mut Vec<String>) {
        let Ok(chain) = gyroemu_board::ChainResponse::new(&self.board_params()) else {
            return;
        };
        let (fc, fs_out) = (self.carrier_hz(), self.fs_out_hz());
        let leak = chain.lowpass(2.0 * fc).norm();
        let alias = 2.0 * fc - fs_out * (2.0 * fc / fs_out).round();
        let (mut worst, mut at): (f64, f64) = (0.0, 0.0);
        let mut worst_lag: (f64, f64) = (0.0, 0.0);
        for rate in self.emulated_rates_dps() {
            let window = self.plan_point(rate).window;
            let refs: Vec<f64> = match self.shape() {
                Shape::Coriolis => vec![0.0],
                Shape::Rotating => vec![],
                Shape::RateTable { freq_hz } => (0..=2 * self.table_harmonics())
                    .map(|h| h as f64 * freq_hz)
                    .collect(),
            };
            let (e, f) = match self.shape() {
                Shape::Rotating => self.rotating_mixer_product_bound_rad(&chain, &window, rate),
                // A Coriolis phase is read against the zero-rate reference, whose own product
                // error adds to it: a 2714 mdeg bound was passed by 3071 mdeg.
                Shape::Coriolis => {
                    let (e, f) = mixer_product_bound_rad(&chain, fc, fs_out, &window, &refs);
                    (2.0 * e, f)
                }
                Shape::RateTable { freq_hz } => {
                    // The phase's fundamental is j (Z_1 - conj Z_-1) / Z_0 to first order in the
                    // swing: the errors of the two harmonics add (12.7 mdeg read, 6.6 stated).
                    let (e, f) = mixer_product_bound_rad(&chain, fc, fs_out, &window, &refs);
                    let e = 2.0 * e;
                    // The lag is the fundamental's angle: an error e against an amplitude A
                    // turns it by up to asin(e / A) (453 mdeg at 300 deg/s where the phase
                    // bound stated 6.6).
                    let (amp, _) = self
                        .driven_device()
                        .rate_table_response(rate.abs() * DEG, freq_hz);
                    for a in amp.into_iter().filter(|a| a.is_finite()) {
                        let l = if e < a.abs() {
                            (e / a.abs()).asin()
                        } else {
                            core::f64::consts::PI
                        };
                        if l > worst_lag.0 {
                            worst_lag = (l, rate);
                        }
                    }
                    (e, f)
                }
            };
            if e > worst {
                (worst, at) = (e, f);
            }
        }
        let worst_mdeg = worst.to_degrees() * 1e3;
        if worst_mdeg > WARN_HOLD_ERROR_MDEG {
            // Where 2 f_c already aliases into the low-pass's band at the sample rate, no
            // decimation nor order removes it.
            let fs = self.fs_hz();
            let at_fs = (2.0 * fc - fs * (2.0 * fc / fs).round()).abs();
            let advice = if at_fs < 2.0 * self.lpf_cutoff_hz() {
                format!(
                    "raise board.fs_hz: at {fs} Hz the product itself aliases to {at_fs:.6e} Hz, within twice the low-pass cutoff, whatever the decimation"
                )
            } else {
                // Removing the key helps only where the derived decimation is another one.
                let derived = {
                    let mut c = self.clone();
                    c.board.decimation = None;
                    c.decimation()
                };
                format!(
                    "choose a decimation whose output rate does not divide 2 f_c{}, or raise board.lpf_order",
                    if derived == self.decimation() {
                        String::new()
                    } else {
                        format!(" (or remove the key for the derived one, {derived})")
                    }
                )
            };
            let lag = if worst_lag.0 > 0.0 {
                format!(
                    ", and the table lag by up to {:.3e} mdeg (that bound over the phase's amplitude at {} deg/s)",
                    worst_lag.0.to_degrees() * 1e3,
                    worst_lag.1
                )
            } else {
                String::new()
            };
            warnings.push(format!(
                "board.decimation = {}: the stage-1 mixer's 2 f_c product ({} Hz), {:.1e} of it left by the low-pass, aliases to {:.6e} Hz at the output rate {fs_out} Hz, too close to the {at} Hz the read-out demodulates for its averaging to remove it: it can move the measured phase by up to {worst_mdeg:.3e} mdeg{}{lag}; {advice}",
                self.decimation(),
                2.0 * fc,
                leak,
                alias.abs(),
                if self.shape() == Shape::Coriolis {
                    " (its own error and the zero-rate reference's)"
                } else {
                    ""
                }
            ));
        }
    }

    /// The rotating read-out's error from the stage-1 mixer's 2 f_c product at the point of
    /// `rate_dps`, rad, and the f_m it demodulates. With the envelope `Z+ e^{j Omega t} + Z-
    /// e^{-j Omega t}` the product is `conj(Z+) L'(2 f_c + f_m) e^{-j (2 w_c + Omega) t} +
    /// conj(Z-) L'(2 f_c - f_m) e^{-j (2 w_c - Omega) t}` (`L' = conj L`). Stage 2 reads `Z+`
    /// as the average of `z e^{-j Omega t}`, `Z-` of `z e^{j Omega t}`: each takes one term at
    /// the alias of 2 f_c (window gain `W_a`, the same for both) and one at 2 f_c -+ 2 f_m.
    /// The first terms move psi = (arg Z- - arg Z+)/2 by `Im(W_a e^{-j(arg Z+ + arg Z-)} (rho
    /// L'+ / L(-f_m) - L'- / (rho L(f_m))))/2`, `rho = |Z+|/|Z-|` at the low-pass input: they
    /// cancel for symmetric sidebands, which is why the DC bound was 5000 times too loose.
    /// Bounded over the unknown common phase, plus the second terms' sizes.
    fn rotating_mixer_product_bound_rad(
        &self,
        chain: &ChainResponse,
        window: &gyroemu_lpf::Window,
        rate_dps: f64,
    ) -> (f64, f64) {
        let (fc, fs_out) = (self.carrier_hz(), self.fs_out_hz());
        let fm = rate_dps * DEG / core::f64::consts::TAU;
        let w = |f: f64| window.response(f / fs_out).norm();
        if fm == 0.0 {
            // No modulation: the envelope is a constant phasor, as in a Coriolis run.
            return mixer_product_bound_rad(chain, fc, fs_out, window, &[0.0]);
        }
        let dev = self.driven_device();
        // The sidebands at the low-pass input (the chain before it scales them by its response).
        let side = |sign: f64| {
            let g = chain.dac_hold(fc + sign * fm) * chain.tia(fc + sign * fm);
            rotating_sideband(&dev, fc, fm, sign).map(|v| v * g)
        };
        let (zp, zm) = (side(1.0), side(-1.0));
        let lp = chain.lowpass(2.0 * fc + fm).conj();
        let lm = chain.lowpass(2.0 * fc - fm).conj();
        let l_pos = chain.lowpass(fm);
        let l_neg = l_pos.conj();
        let (w_a, w_p, w_m) = (w(2.0 * fc), w(2.0 * fc + 2.0 * fm), w(2.0 * fc - 2.0 * fm));
        let worst = (0..2)
            .map(|k| {
                let rho = zp[k].norm() / zm[k].norm();
                let dc = w_a * (rho * lp / l_neg - lm / (rho * l_pos)).norm();
                let rest = (lp.norm() * w_p + lm.norm() * w_m) / l_pos.norm();
                (0.5 * (dc + rest)).min(1.0).asin()
            })
            // A vanished sideband has no psi: the read-out reports it.
            .filter(|e| e.is_finite())
            .fold(0.0, f64::max);
        (worst, fm.abs())
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
        let sigma = self.tia_white_noise().map_or(0.0, |(density, band)| {
            self.board.tia_gain_ohm * density * band.sqrt()
        });
        let bias = gyroemu_theory::quantiser_bias_bound(step, sigma);
        gyroemu_theory::quantiser_phase_bound_rad(bias, amplitude).to_degrees() * 1e3
    }

    /// The DAC holds each drive sample for a period: the measured phase departs from the
    /// continuous-drive theory by what the exact held-drive steady state says. Stated when it
    /// matters, refused when the hold's images dominate.
    fn validate_hold(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let dev = self.driven_device();
        let mut worst: f64 = 0.0;
        // A rate table's lag, by the same exact figure.
        let mut worst_lag: f64 = 0.0;
        for &r in &self.experiment.rates_dps {
            let omega = r * DEG;
            let (held, exact) = match self.shape() {
                Shape::Rotating => (
                    dev.held_rotating_psi_rad(omega),
                    dev.rotating_psi_rad(omega),
                ),
                // The periodic steady state of the board's own recursion against the
                // continuous plant's (the constant-rate figure had missed 9.7 mdeg of a
                // detuned table's amplitude, and 5.3 on a split one).
                Shape::RateTable { freq_hz } => {
                    let (ha, hl) = dev.held_rate_table_response(omega.abs(), freq_hz);
                    let (ca, cl) = dev.rate_table_response(omega.abs(), freq_hz);
                    for k in 0..2 {
                        let e = turn_mdeg(hl[k], cl[k]);
                        if e.is_finite() {
                            worst_lag = worst_lag.max(e);
                        }
                    }
                    (ha, ca)
                }
                Shape::Coriolis => (
                    dev.held_coriolis_phase_rad(omega),
                    dev.coriolis_phase_rad(omega),
                ),
            };
            for k in 0..2 {
                // Psi is known within a half turn; a Coriolis phase within a whole one (its
                // half-turn fold read a 180 deg error as 32 mdeg at 1e9 deg/s).
                let e = match self.shape() {
                    Shape::Rotating => half_turn_mdeg(held[k], exact[k]),
                    _ => turn_mdeg(held[k], exact[k]),
                };
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
                "at {per_period:.2} samples per carrier period the DAC's zero-order hold moves the measured phase by up to {worst:.3e} mdeg from the continuous-drive theory at these rates (the exact held-drive steady state: the board measures the hold more than the device); raise fs_hz{}",
                if per_period < 16.0 {
                    " (16 samples per period keeps it near 0.01 mdeg at ordinary rates)"
                } else {
                    ""
                }
            ),
        );
        if worst.max(worst_lag) > WARN_HOLD_ERROR_MDEG {
            let size = match self.shape() {
                Shape::RateTable { .. } => format!(
                    "(with the plant's time-varying step, as the board runs it) by up to {worst:.3e} mdeg in the table's amplitude and {worst_lag:.3e} mdeg in its lag"
                ),
                _ => format!("by up to {worst:.3e} mdeg"),
            };
            warnings.push(format!(
                "board.fs_hz = {} ({per_period:.2} samples per carrier period): the DAC's zero-order hold moves the measured phase {size} from the continuous-drive theory at these rates (the exact held-drive steady state); raise fs_hz to shrink it",
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

/// Both modes' velocity phasors at the sideband `fc + sign fm` of the rotating drive (THEORY.md
/// section 4; mode 2's drive turned by the phase shifter's error, as
/// `DrivenDevice::rotating_psi_rad` takes it), before the chain.
fn rotating_sideband(
    dev: &gyroemu_theory::DrivenDevice,
    fc: f64,
    fm: f64,
    sign: f64,
) -> [Complex64; 2] {
    let x = continuous_steady_state(&dev.plant, 0.0, fc + sign * fm, dev.sideband_force(sign));
    [x[2], x[3]]
}

/// A signal's smallest and largest amplitude over a point's run.
pub(crate) type LoHi = (f64, f64);

/// The smallest and the largest amplitude of a signal over the run's points, with the rate
/// (deg/s) of each.
#[derive(Clone, Copy, Debug)]
struct AmpSpan {
    min: f64,
    min_at: f64,
    max: f64,
    max_at: f64,
}

impl Default for AmpSpan {
    fn default() -> Self {
        Self {
            min: f64::INFINITY,
            min_at: f64::NAN,
            max: f64::NEG_INFINITY,
            max_at: f64::NAN,
        }
    }
}

impl AmpSpan {
    /// Widens the span by a point's amplitudes; a NaN (an unbuildable plant) poisons it.
    fn include(&mut self, lo: f64, hi: f64, rate_dps: f64) {
        if lo.is_nan() || hi.is_nan() {
            self.min = f64::NAN;
            self.max = f64::NAN;
        }
        if lo < self.min {
            (self.min, self.min_at) = (lo, rate_dps);
        }
        if hi > self.max {
            (self.max, self.max_at) = (hi, rate_dps);
        }
    }
}

/// The smallest and the largest `|sum_n h[n] e^{j (n - N) phi}|` over a period (`h` holds
/// harmonics `-N ..= N`), on 16 (2N + 1) points per period: over a grid step near an
/// extreme the envelope (its square a trigonometric polynomial of degree 2N) moves by about
/// N^2 sum|h| (step/2)^2 / 2 (Bernstein), under 0.5 % of sum|h|.
/// The modulus drops the common factor `e^{-j N phi}`, so each point is a polynomial in
/// `e^{j phi}` by Horner: one `sin_cos` per point instead of one per harmonic (the validation
/// of a rate-table sweep took 0.6 % of a `reproduce` with one per harmonic).
fn envelope_extremes(h: &[Complex64]) -> (f64, f64) {
    let points = 16 * h.len().max(1);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for i in 0..points {
        let phi = core::f64::consts::TAU * i as f64 / points as f64;
        let base = Complex64::from_polar(1.0, phi);
        let v = h
            .iter()
            .rev()
            .fold(Complex64::new(0.0, 0.0), |v, &x| v * base + x);
        let a = v.norm();
        if a.is_nan() {
            return (f64::NAN, f64::NAN);
        }
        lo = lo.min(a);
        hi = hi.max(a);
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn envelope_extremes_of_two_harmonics_in_closed_form() {
        // |a e^{-j phi} + b e^{j phi}| for real a, b: a + b at phi = 0 and |a - b| at
        // phi = pi / 2, both on the 48-point grid of three harmonics.
        for (a, b) in [(1.0, 0.25), (0.3, 2.0), (1.0, 1.0)] {
            let h = [
                Complex64::new(a, 0.0),
                Complex64::new(0.0, 0.0),
                Complex64::new(b, 0.0),
            ];
            let (lo, hi) = envelope_extremes(&h);
            assert!((hi - (a + b)).abs() < 1e-14, "{a}, {b}: max {hi}");
            assert!((lo - (a - b).abs()).abs() < 1e-14, "{a}, {b}: min {lo}");
        }
    }

    #[test]
    fn envelope_extremes_match_the_sum_term_by_term() {
        // The definition on the same grid, each harmonic's phasor on its own.
        let mut x: u64 = 12345;
        let mut next = move || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for len in [1usize, 3, 5, 9, 15] {
            let h: Vec<Complex64> = (0..len).map(|_| Complex64::new(next(), next())).collect();
            let n = (len / 2) as f64;
            let points = 16 * len;
            let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
            for i in 0..points {
                let phi = core::f64::consts::TAU * i as f64 / points as f64;
                let v: Complex64 = h
                    .iter()
                    .enumerate()
                    .map(|(m, &x)| x * Complex64::from_polar(1.0, (m as f64 - n) * phi))
                    .sum();
                lo = lo.min(v.norm());
                hi = hi.max(v.norm());
            }
            let (l, u) = envelope_extremes(&h);
            assert!(
                (l - lo).abs() < 1e-13 && (u - hi).abs() < 1e-13,
                "{len}: {l} {u} vs {lo} {hi}"
            );
        }
    }
}
