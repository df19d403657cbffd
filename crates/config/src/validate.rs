//! Validation before any sample is computed: every rule names the key, the value and the rule,
//! and every broken rule of a config is reported (a rule whose inputs already broke one is
//! skipped: see [`Rules`]).

use crate::config::{Config, ExperimentKind, RateTable};
use crate::error::ConfigError;
use crate::plan::DEG;
use crate::rules::Rules;
use crate::schema::{CONVERTER_BITS, LPF_ORDER};
use crate::validate_regime::check_level;
use gyroemu_board::DUMP_NODES;

/// Most input samples one operating point may run: 2^53, so every sample index and count
/// is exact as an f64.
pub const MAX_RUN_SAMPLES: f64 = 9_007_199_254_740_992.0;

/// A Coriolis or rate-table run's largest Coriolis coupling `2 lambda |Omega_z|`, in units of
/// the lower resonance `2 pi f0`. The emulation agrees with the exact theory (within its
/// warned hold error) up to about 1e13 on the m2tfg preset (3e19 deg/s) and leaves it at 5e19;
/// the tests reach 1e9 deg/s (a ratio of about 400), a real gyroscope's range a ratio of
/// 1e-2. Beyond the bound a rate is refused before any sample.
pub const MAX_CORIOLIS_COUPLING: f64 = 1e6;

/// How [`Config::validate_sweep`] begins a warning of the `[experiment]`'s rules.
pub const EXPERIMENT_WARNING: &str = "judged for `run` of [experiment], at its rates and windows (the sweep drives one mode at a time at its own frequencies, where the figure differs; a range or clipping it names can hold here too): ";

/// The same f64, bit for bit (a derived value equals its derivation exactly).
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

impl Config {
    /// Checks every rule that does not need the stages built (the `[sweep]` rules when the
    /// section is present); returns the warnings, or every broken rule in one error.
    pub fn validate(&self) -> Result<Vec<String>, ConfigError> {
        self.validate_with(self.sweep.is_some(), false)
    }

    /// [`Config::validate`] plus the rules of the `[sweep]` that `gyroemu sweep` runs, its
    /// defaults included when the section is absent.
    ///
    /// The warnings of the rules that weigh the `[experiment]`'s operating points (its rates,
    /// settling, modulation or table) start with [`EXPERIMENT_WARNING`]: `sweep` does not
    /// run those points, and "at 5 deg/s" read as if it did (the ranges and clipping those
    /// rules name can still hold for the sweep's own drive, so it is not said they do not).
    /// `[dump]`, which `sweep` ignores, is not judged: an unused section never refuses it.
    /// `[selfcal]` is (its record lengths set the flicker sources' derived low corner, which
    /// the sweep's noise uses, and a corner derived from it must keep saying so).
    pub fn validate_sweep(&self) -> Result<Vec<String>, ConfigError> {
        let read = Config {
            dump: None,
            ..self.clone()
        };
        read.validate_with(true, true)
    }

    fn validate_with(&self, sweep: bool, for_sweep: bool) -> Result<Vec<String>, ConfigError> {
        let mut p = Rules::default();
        let mut warnings = Vec::new();
        self.link_derived(&mut p);
        self.validate_device_board(&mut p);
        self.warn_tia_pole(&p, &mut warnings);
        self.validate_experiment(&mut p);
        self.validate_noise_adc_selfcal(&mut p, &mut warnings);
        self.validate_montecarlo(&mut p);
        // The regime rules weigh the whole chain: only once its keys are each valid.
        let experiment_from = warnings.len();
        if ["device", "drive", "board"]
            .iter()
            .all(|s| p.section_clean(s))
            && p.clean(&["experiment.rates_dps"])
        {
            // Under a `[pll]` the run holds the carrier where the lock ends, on the locked
            // mode's resonance, not at `drive.carrier_hz`, where it starts (the rules judged
            // a 6-bit DAC's pattern at 15010 Hz for a run at 15000.0006 Hz).
            let held = self.expected_lock();
            let judged = held.as_ref().unwrap_or(self);
            judged.validate_regime(&mut p, &mut warnings, held.is_some());
            judged.validate_table_alias(&mut p, &mut warnings);
            judged.validate_settling(&mut p, &mut warnings);
        }
        if for_sweep {
            for w in &mut warnings[experiment_from..] {
                w.insert_str(0, EXPERIMENT_WARNING);
            }
        }
        self.validate_dump(&mut p, &mut warnings);
        if sweep {
            self.validate_sweep_rules(&mut p, &mut warnings);
        }
        p.finish().map(|()| warnings)
    }

    /// Declares the keys `parse_config` derived (their value is exactly the derivation's), so
    /// that a bad source is reported once, not again through what was derived from it.
    fn link_derived(&self, p: &mut Rules) {
        let raw = |f: &dyn Fn(&mut Config)| {
            let mut c = self.clone();
            f(&mut c);
            c
        };
        if same(raw(&|c| c.drive.f2 = None).f2(), self.f2()) {
            p.derived_from("drive.f2", "drive.f1");
        }
        if same(
            raw(&|c| c.drive.carrier_hz = None).carrier_hz(),
            self.carrier_hz(),
        ) {
            p.derived_from("drive.carrier_hz", "device.f0_hz");
        }
        if same(raw(&|c| c.board.fs_hz = None).fs_hz(), self.fs_hz()) {
            p.derived_from("board.fs_hz", "device.f0_hz");
            p.derived_from("board.fs_hz", "device.mode2_f0_offset_hz");
        }
        // Clamped to f0/100 .. f0/10: only f0 can make it bad.
        if same(
            raw(&|c| c.board.lpf_cutoff_hz = None).lpf_cutoff_hz(),
            self.lpf_cutoff_hz(),
        ) {
            p.derived_from("board.lpf_cutoff_hz", "device.f0_hz");
        }
        // 0.02 / the longest record: a record refused as too long gave a subnormal corner,
        // and the flicker design then asked for usize::MAX poles (a panic, not a message).
        let clear_f_lo = |c: &mut Config| {
            if let Some(n) = &mut c.noise {
                n.flicker_f_lo_hz = None;
            }
        };
        if same(raw(&clear_f_lo).flicker_f_lo_hz(), self.flicker_f_lo_hz()) {
            for source in [
                "experiment.average_s",
                "experiment.settle_s",
                "selfcal.allan_record_s",
                "selfcal.tau_max_s",
            ] {
                p.derived_from("noise.flicker_f_lo_hz", source);
            }
        }
        if raw(&|c| c.board.decimation = None).decimation() == self.decimation() {
            p.derived_from("board.decimation", "board.fs_hz");
            p.derived_from("board.decimation", "board.lpf_cutoff_hz");
            p.derived_from("board.decimation", "drive.carrier_hz");
        }
    }

    fn validate_device_board(&self, p: &mut Rules) {
        let d = &self.device;
        let b = &self.board;
        let (fs_hz, cutoff_hz) = (self.fs_hz(), self.lpf_cutoff_hz());
        p.positive("device.f0_hz", d.f0_hz);
        p.positive("device.q", d.q);
        p.positive("device.angular_gain", d.angular_gain);
        if p.finite("device.mode2_f0_offset_hz", d.mode2_f0_offset_hz) && p.clean(&["device.f0_hz"])
        {
            p.check(
                self.f0_mode2_hz() > 0.0,
                "device.mode2_f0_offset_hz",
                d.mode2_f0_offset_hz,
                "mode-2 resonance f0_hz + offset must stay > 0",
            );
        }
        if let Some(q2) = d.q_mode2 {
            p.positive("device.q_mode2", q2);
        }
        p.finite(
            "device.quadrature_coupling_rad2_s2",
            d.quadrature_coupling_rad2_s2,
        );
        p.positive("device.transduction_a_s_per_m", d.transduction_a_s_per_m);
        p.positive("drive.f1", self.drive.f1);
        p.positive("drive.f2", self.f2());

        p.positive("board.fs_hz", fs_hz);
        let f_max = d.f0_hz.max(self.f0_mode2_hz());
        if p.clean(&["device.f0_hz", "device.mode2_f0_offset_hz"]) {
            p.check(
                fs_hz > 2.0 * f_max,
                "board.fs_hz",
                fs_hz,
                format!("must be above 2*f0 = {} Hz", 2.0 * f_max),
            );
        }
        if p.positive("drive.carrier_hz", self.carrier_hz()) && p.clean(&["board.fs_hz"]) {
            p.check(
                self.carrier_hz() < 0.5 * fs_hz,
                "drive.carrier_hz",
                self.carrier_hz(),
                format!("must be below Nyquist (fs_hz/2 = {} Hz)", 0.5 * fs_hz),
            );
        }
        p.positive("board.tia_gain_ohm", b.tia_gain_ohm);
        if let Some(pole) = b.tia_pole_hz {
            if p.clean(&["board.fs_hz"]) {
                let ok = p.check(
                    pole.is_finite() && pole > 0.0 && pole < 0.5 * fs_hz,
                    "board.tia_pole_hz",
                    pole,
                    format!(
                        "must be > 0 and below Nyquist (fs_hz/2 = {} Hz)",
                        0.5 * fs_hz
                    ),
                );
                // The TIA as built: a pole whose coefficient rounds to 1 has a gain of 0.
                p.check(
                    !ok || gyroemu_tia::pole_coefficient(pole, fs_hz) < 1.0,
                    "board.tia_pole_hz",
                    pole,
                    format!(
                        "{}; raise it, or remove the key for a wide-band TIA",
                        gyroemu_tia::min_pole_rule(fs_hz)
                    ),
                );
            } else {
                p.positive("board.tia_pole_hz", pole);
            }
        }
        if let Some(r) = b.tia_rail_v {
            check_level(p, "board.tia_rail_v", r);
        }
        p.check(
            LPF_ORDER.contains(b.lpf_order),
            "board.lpf_order",
            b.lpf_order,
            LPF_ORDER.rule(),
        );
        let decimation = self.decimation();
        p.check(
            decimation >= 1,
            "board.decimation",
            decimation,
            "must be an integer >= 1",
        );
        if p.clean(&["board.fs_hz", "board.decimation"]) {
            let nyq_out = 0.5 * self.fs_out_hz();
            p.check(
                cutoff_hz.is_finite() && cutoff_hz > 0.0 && cutoff_hz < nyq_out,
                "board.lpf_cutoff_hz",
                cutoff_hz,
                format!(
                    "must be > 0 and below the Nyquist rate after decimation (fs_hz/decimation/2 = {nyq_out} Hz)"
                ),
            );
        } else {
            p.positive("board.lpf_cutoff_hz", cutoff_hz);
        }
        if p.clean(&["device.f0_hz"]) {
            p.check(
                cutoff_hz < d.f0_hz,
                "board.lpf_cutoff_hz",
                cutoff_hz,
                "must be below f0_hz so the low-pass removes the 2*f0 mixing product",
            );
        }
        // The design itself: f64 must realise it with its poles inside the unit circle.
        if p.clean(&["board.lpf_cutoff_hz", "board.fs_hz", "board.lpf_order"]) {
            if let Err(e) = gyroemu_lpf::LowPass::<f64>::new(self.lowpass_design(), fs_hz) {
                p.push(ConfigError::key(
                    "board.lpf_cutoff_hz",
                    cutoff_hz,
                    format!("the stage-1 low-pass cannot be built: {}", e.rule),
                ));
            }
        }
        if let Some(bits) = b.dac_bits {
            p.check(
                CONVERTER_BITS.contains(bits),
                "board.dac_bits",
                bits,
                CONVERTER_BITS.rule(),
            );
        }
        check_level(p, "board.dac_full_scale", b.dac_full_scale);
        p.check(
            b.phase_shifter_error_deg.is_finite() && b.phase_shifter_error_deg.abs() < 90.0,
            "board.phase_shifter_error_deg",
            b.phase_shifter_error_deg,
            "must be finite and within (-90, 90) degrees",
        );
    }

    /// A valid pole whose coefficient's rounding moves it: near the minimum,
    /// a = exp(-2 pi pole / fs) steps in units of 2^-53, so the pole realised can be twice the
    /// one configured.
    fn warn_tia_pole(&self, p: &Rules, warnings: &mut Vec<String>) {
        let Some(pole) = self.board.tia_pole_hz else {
            return;
        };
        if !p.clean(&["board.tia_pole_hz", "board.fs_hz"]) {
            return;
        }
        let fs = self.fs_hz();
        let realised = gyroemu_tia::realised_pole_hz(pole, fs);
        let rel = realised / pole - 1.0;
        if rel.abs() > 1e-6 {
            let always = 2f64.powi(-54) * 1e6 * fs / core::f64::consts::TAU;
            warnings.push(format!(
                "board.tia_pole_hz = {pole:e}: the TIA's discretised pole a = exp(-2 pi tia_pole_hz / fs_hz) steps in units of 2^-53 below 1, so the TIA realises a pole of {realised:.6e} Hz (-ln(a) fs_hz / (2 pi)), not {pole:e} Hz: {rel:+.3e} relative. Its gain follows the realised pole, and with it the ADC range, the rails and the noise levels (the read-out's phases do not: it divides by the response as built); above {always:.3e} Hz (2^-54 x 1e6 x fs_hz / (2 pi)) every pole is realised within 1e-6"
            ));
        }
    }

    fn validate_experiment(&self, p: &mut Rules) {
        let e = &self.experiment;
        let (fs_hz, cutoff_hz) = (self.fs_hz(), self.lpf_cutoff_hz());
        let device_ok = p.clean(&["device.f0_hz", "device.q", "device.q_mode2"]);
        p.check(
            !e.rates_dps.is_empty(),
            "experiment.rates_dps",
            "[]",
            "must list at least one rate",
        );
        for (i, &r) in e.rates_dps.iter().enumerate() {
            let key = format!("experiment.rates_dps[{i}]");
            let rotating = e.kind == ExperimentKind::Rotating;
            // Refused here, not after the run: its read-out came out NaN, blamed on an overflow.
            if rotating
                && !p.check(
                    r != 0.0,
                    &key,
                    r,
                    "a rotating run reads psi from the sidebands at +-Omega, and rate 0 has none: leave it out",
                )
            {
                continue;
            }
            if !rotating
                && r.is_finite()
                && p.clean(&[
                    "device.f0_hz",
                    "device.angular_gain",
                    "device.mode2_f0_offset_hz",
                ])
            {
                // Before the regime rules: their plant exponentials never returned at 1e50 deg/s.
                let w0 = core::f64::consts::TAU * self.device.f0_hz.min(self.f0_mode2_hz());
                let coupling = 2.0 * self.device.angular_gain * (r * DEG).abs();
                p.check(
                    coupling <= MAX_CORIOLIS_COUPLING * w0,
                    &key,
                    r,
                    format!(
                        "the Coriolis coupling 2 lambda |Omega_z| = {coupling:.3e} rad/s (device.angular_gain = {:e}) must stay within {MAX_CORIOLIS_COUPLING:e} times the lower resonance 2 pi f0 = {w0:.6e} rad/s, that is |rate| <= {:.3e} deg/s: beyond it the emulation is not verified (its phases left the theory past 1e13 times, at 5e19 deg/s on the m2tfg preset)",
                        self.device.angular_gain,
                        MAX_CORIOLIS_COUPLING * w0 / (2.0 * self.device.angular_gain) / DEG
                    ),
                );
            }
            if p.finite(&key, r) && rotating && p.clean(&["board.lpf_cutoff_hz"]) {
                let f_mod = r.abs() / 360.0;
                p.check(
                    f_mod < cutoff_hz,
                    &key,
                    r,
                    format!(
                        "the modulation frequency |rate|/360 must be below board.lpf_cutoff_hz = {} Hz",
                        cutoff_hz
                    ),
                );
            }
        }
        // What a hand-set settle_s leaves in the window is stated by `validate_settling`.
        if let Some(s) = e.settle_s {
            p.non_negative("experiment.settle_s", s);
        }
        p.positive("experiment.average_s", e.average_s);
        if p.clean(&["board.fs_hz", "board.decimation"]) {
            p.check(
                e.average_s >= 1.0 / self.fs_out_hz(),
                "experiment.average_s",
                e.average_s,
                format!(
                    "must cover at least one output sample period ({} s)",
                    1.0 / self.fs_out_hz()
                ),
            );
        }
        // Sample indices and counts must stay exact in f64 (and far from u64 overflow). The
        // default settling comes from the device and the low-pass.
        let settle_ok = match e.settle_s {
            Some(_) => p.clean(&["experiment.settle_s"]),
            None => device_ok && p.clean(&["board.lpf_cutoff_hz"]),
        };
        if settle_ok && p.clean(&["experiment.average_s", "board.fs_hz"]) {
            let run_samples = (self.settle_s() + e.average_s) * fs_hz;
            p.check(
                run_samples <= MAX_RUN_SAMPLES,
                if e.settle_s.is_some_and(|s| s > e.average_s) {
                    "experiment.settle_s"
                } else {
                    "experiment.average_s"
                },
                e.settle_s.filter(|&s| s > e.average_s).unwrap_or(e.average_s),
                format!(
                    "settling plus averaging must span at most 2^53 = {MAX_RUN_SAMPLES:e} input samples per point (here {run_samples:e} at fs_hz = {:?})",
                    fs_hz
                ),
            );
        }
        if e.kind == ExperimentKind::Rotating && p.clean(&["experiment.rates_dps"]) {
            if let Some(min) = e
                .rates_dps
                .iter()
                .map(|r| r.abs())
                .filter(|&r| r > 0.0)
                .reduce(f64::min)
            {
                let half_period = 180.0 / min;
                p.check(
                    e.average_s >= half_period,
                    "experiment.average_s",
                    e.average_s,
                    format!(
                        "must cover at least half a modulation period of the slowest rate ({min} deg/s: {half_period} s)"
                    ),
                );
            }
        }
        match (e.rate_table, e.kind) {
            (RateTable::Constant, _) => {
                if let Some(ft) = e.table_freq_hz {
                    p.push(ConfigError::key(
                        "experiment.table_freq_hz",
                        ft,
                        "only applies with rate_table = \"sinusoid\"",
                    ));
                }
            }
            (RateTable::Sinusoid, ExperimentKind::Rotating) => p.push(ConfigError::key(
                "experiment.rate_table",
                "\"sinusoid\"",
                "a rate table applies to kind = \"coriolis\" only",
            )),
            (RateTable::Sinusoid, ExperimentKind::Coriolis) => match e.table_freq_hz {
                None => p.push(ConfigError::key(
                    "experiment.table_freq_hz",
                    "(missing)",
                    "is required with rate_table = \"sinusoid\"",
                )),
                Some(ft) => {
                    // A table's rates are amplitudes: -A sin is A sin half a table period on
                    // (the same amplitude read, its lag 180 deg on), and 0 has no swing and no
                    // lag. Signed amplitudes had made the sweep's line a V: a slope of 0 for
                    // the symmetric -175 ..= 175, and a lag of noise at 0.
                    if let Some(&bad) = e.rates_dps.iter().find(|r| r.is_nan() || **r <= 0.0) {
                        p.push(ConfigError::key(
                            "experiment.rates_dps",
                            bad,
                            "with rate_table = \"sinusoid\" each rate is the table's amplitude and must be > 0: a negative one is the positive table half a period on (the same amplitude, the lag 180 deg on), and 0 has no swing and no lag to read (a sinusoid sweep needs no zero-rate reference)",
                        ));
                    }
                    let key = "experiment.table_freq_hz";
                    if p.clean(&["board.lpf_cutoff_hz"]) {
                        p.check(
                            ft.is_finite() && ft > 0.0 && ft < cutoff_hz,
                            key,
                            ft,
                            format!(
                                "must be > 0 and below board.lpf_cutoff_hz = {} Hz",
                                cutoff_hz
                            ),
                        );
                    } else {
                        p.positive(key, ft);
                    }
                    if p.clean(&[key]) {
                        p.check(
                            e.average_s * ft >= 1.0,
                            "experiment.average_s",
                            e.average_s,
                            format!("must cover at least one rate-table period ({} s)", 1.0 / ft),
                        );
                    }
                }
            },
        }
        // A Hann window over few modulation periods is read exactly: its leak is computed from
        // the window and removed (the stage-2 and table leaks), so no warning is due (one
        // claimed "more than 0.1 mdeg" where the reading was within 2e-6 mdeg).
    }

    /// The dump's rules. Its window is weighed against the point's run only when the rest of
    /// the config is valid (the run's length depends on nearly every key), and a window key
    /// derived from the run is judged only then.
    fn validate_dump(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let (Some(given), Some(dump)) = (&self.dump, self.dump_resolved()) else {
            return;
        };
        let upstream_ok = p.is_empty();
        let (rate_dps, start_s, duration_s) = (
            dump.rate_dps.unwrap_or(f64::NAN),
            dump.start_s.unwrap_or(f64::NAN),
            dump.duration_s.unwrap_or(f64::NAN),
        );
        // A key is the user's own unless it equals what the dump's defaults derive.
        let derived = |clear: &dyn Fn(&mut crate::config::DumpConfig)| {
            let mut raw = self.clone();
            let mut d = given.clone();
            clear(&mut d);
            raw.dump = Some(d);
            raw.dump_resolved().unwrap_or(dump.clone())
        };
        let own = |v: f64, derived: Option<f64>| !derived.is_some_and(|d| same(v, d));
        let own_start = own(start_s, derived(&|d| d.start_s = None).start_s);
        let own_duration = own(duration_s, derived(&|d| d.duration_s = None).duration_s);
        if p.clean(&["experiment.rates_dps"]) {
            let emulated = self.emulated_rates_dps();
            p.check(
                emulated.contains(&rate_dps),
                "dump.rate_dps",
                rate_dps,
                format!("must be one of the emulated rates {emulated:?}"),
            );
        }
        if own_start || upstream_ok {
            p.non_negative("dump.start_s", start_s);
        }
        if own_duration || upstream_ok {
            p.positive("dump.duration_s", duration_s);
        }
        if upstream_ok && p.is_empty() {
            // The point runs settling plus its own averaging window (whole half periods).
            let pt = self.plan_point(rate_dps);
            let n_out = self
                .n_settle_out()
                .saturating_add(pt.n_avg())
                .saturating_add(1);
            let total = n_out as f64 / self.fs_out_hz();
            // A start past the end is the start's fault, whatever the length.
            let starts_within = p.check(
                start_s < total,
                "dump.start_s",
                start_s,
                format!("the window must start within that point's run ({total} s)"),
            );
            if starts_within {
                p.check(
                    start_s + duration_s <= total,
                    "dump.duration_s",
                    duration_s,
                    format!(
                        "the window start_s + duration_s must end within that point's run ({total} s; it starts at start_s = {start_s} s)"
                    ),
                );
            }
        }
        if p.clean(&["board.fs_hz"]) {
            // Far below a sample the window holds nothing: the dump was one row at its start.
            p.check(
                duration_s * self.fs_hz() >= 1.0,
                "dump.duration_s",
                duration_s,
                format!(
                    "the window must hold at least one full-rate sample (1 / fs_hz = {:e} s)",
                    1.0 / self.fs_hz()
                ),
            );
            p.check(
                duration_s * self.fs_hz() <= 5e7,
                "dump.duration_s",
                duration_s,
                "the window must hold at most 5e7 full-rate samples (keep dumps small)",
            );
        }
        let nodes = dump.nodes.unwrap_or_default();
        p.check(
            !nodes.is_empty(),
            "dump.nodes",
            "[]",
            "must list at least one node",
        );
        for (i, n) in nodes.iter().enumerate() {
            p.check(
                DUMP_NODES.contains(&n.as_str()),
                &format!("dump.nodes[{i}]"),
                format!("\"{n}\""),
                format!("must be one of {DUMP_NODES:?}"),
            );
            if let Some(j) = nodes[..i].iter().position(|m| m == n) {
                p.check(
                    false,
                    &format!("dump.nodes[{i}]"),
                    format!("\"{n}\""),
                    format!("is already listed as dump.nodes[{j}]: list each node once"),
                );
            }
        }
        if p.clean(&["board.fs_hz", "board.decimation"]) {
            let (fs, m) = (self.fs_hz(), self.decimation());
            for (what, why) in gyroemu_board::Probe::wav_problems(&nodes, fs, m) {
                warnings.push(format!(
                    "dump: the {what} recording gets no WAV ({why}); its CSV and SigMF are written"
                ));
            }
        }
    }
}
