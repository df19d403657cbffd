//! Validation before any sample is computed: every rule names the key, the value and the rule.

use crate::config::{Config, ExperimentKind, RateTable, WindowKind};
use crate::parse::ConfigError;
use gyroemu_board::{Shape, DUMP_NODES};
use gyroemu_theory::mechanical_tau_s;

/// Most input samples one operating point may run: 2^53, so every sample index and count
/// is exact as an f64.
pub const MAX_RUN_SAMPLES: f64 = 9_007_199_254_740_992.0;

pub(crate) fn check(
    ok: bool,
    key: &str,
    value: impl std::fmt::Display,
    rule: &str,
) -> Result<(), ConfigError> {
    if ok {
        Ok(())
    } else {
        Err(ConfigError::key(key, value, rule))
    }
}

pub(crate) fn positive(key: &str, v: f64) -> Result<(), ConfigError> {
    check(
        v.is_finite() && v > 0.0,
        key,
        v,
        "must be a finite number > 0",
    )
}

fn finite(key: &str, v: f64) -> Result<(), ConfigError> {
    check(v.is_finite(), key, v, "must be a finite number")
}

pub(crate) fn non_negative(key: &str, v: f64) -> Result<(), ConfigError> {
    check(
        v.is_finite() && v >= 0.0,
        key,
        v,
        "must be a finite number >= 0",
    )
}

impl Config {
    /// Checks every rule that does not need the stages built; returns warnings.
    pub fn validate(&self) -> Result<Vec<String>, ConfigError> {
        let d = &self.device;
        let b = &self.board;
        let e = &self.experiment;
        let (fs_hz, cutoff_hz, decimation) =
            (self.fs_hz(), self.lpf_cutoff_hz(), self.decimation());
        let mut warnings = Vec::new();
        positive("device.f0_hz", d.f0_hz)?;
        positive("device.q", d.q)?;
        positive("device.angular_gain", d.angular_gain)?;
        finite("device.mode2_f0_offset_hz", d.mode2_f0_offset_hz)?;
        check(
            self.f0_mode2_hz() > 0.0,
            "device.mode2_f0_offset_hz",
            d.mode2_f0_offset_hz,
            "mode-2 resonance f0_hz + offset must stay > 0",
        )?;
        if let Some(q2) = d.q_mode2 {
            positive("device.q_mode2", q2)?;
        }
        finite(
            "device.quadrature_coupling_rad2_s2",
            d.quadrature_coupling_rad2_s2,
        )?;
        positive("device.transduction_a_s_per_m", d.transduction_a_s_per_m)?;
        positive("drive.f1", self.drive.f1)?;
        positive("drive.f2", self.f2())?;

        positive("board.fs_hz", fs_hz)?;
        let f_max = d.f0_hz.max(self.f0_mode2_hz());
        check(
            fs_hz > 2.0 * f_max,
            "board.fs_hz",
            fs_hz,
            &format!("must be above 2*f0 = {} Hz", 2.0 * f_max),
        )?;
        positive("board.tia_gain_ohm", b.tia_gain_ohm)?;
        if let Some(p) = b.tia_pole_hz {
            check(
                p.is_finite() && p > 0.0 && p < 0.5 * fs_hz,
                "board.tia_pole_hz",
                p,
                &format!(
                    "must be > 0 and below Nyquist (fs_hz/2 = {} Hz)",
                    0.5 * fs_hz
                ),
            )?;
        }
        if let Some(r) = b.tia_rail_v {
            positive("board.tia_rail_v", r)?;
        }
        check(
            (1..=8).contains(&b.lpf_order),
            "board.lpf_order",
            b.lpf_order,
            "must be an integer from 1 to 8",
        )?;
        check(
            decimation >= 1,
            "board.decimation",
            decimation,
            "must be an integer >= 1",
        )?;
        let nyq_out = 0.5 * self.fs_out_hz();
        check(
            cutoff_hz.is_finite() && cutoff_hz > 0.0 && cutoff_hz < nyq_out,
            "board.lpf_cutoff_hz",
            cutoff_hz,
            &format!(
                "must be > 0 and below the Nyquist rate after decimation (fs_hz/decimation/2 = {nyq_out} Hz)"
            ),
        )?;
        check(
            cutoff_hz < d.f0_hz,
            "board.lpf_cutoff_hz",
            cutoff_hz,
            "must be below f0_hz so the low-pass removes the 2*f0 mixing product",
        )?;
        // The design itself: f64 must realise it with its poles inside the unit circle.
        gyroemu_lpf::LowPass::<f64>::new(self.lowpass_design(), fs_hz).map_err(|e| {
            ConfigError::key(
                "board.lpf_cutoff_hz",
                cutoff_hz,
                format!("the stage-1 low-pass cannot be built: {}", e.rule),
            )
        })?;
        if let Some(bits) = b.dac_bits {
            check(
                (2..=32).contains(&bits),
                "board.dac_bits",
                bits,
                "must be an integer from 2 to 32",
            )?;
        }
        positive("board.dac_full_scale", b.dac_full_scale)?;
        check(
            b.phase_shifter_error_deg.is_finite() && b.phase_shifter_error_deg.abs() < 90.0,
            "board.phase_shifter_error_deg",
            b.phase_shifter_error_deg,
            "must be finite and within (-90, 90) degrees",
        )?;

        check(
            !e.rates_dps.is_empty(),
            "experiment.rates_dps",
            "[]",
            "must list at least one rate",
        )?;
        for (i, &r) in e.rates_dps.iter().enumerate() {
            finite(&format!("experiment.rates_dps[{i}]"), r)?;
            if e.kind == ExperimentKind::Rotating {
                let f_mod = r.abs() / 360.0;
                check(
                    f_mod < cutoff_hz,
                    &format!("experiment.rates_dps[{i}]"),
                    r,
                    &format!(
                        "the modulation frequency |rate|/360 must be below board.lpf_cutoff_hz = {} Hz",
                        cutoff_hz
                    ),
                )?;
            }
        }
        if let Some(s) = e.settle_s {
            non_negative("experiment.settle_s", s)?;
            let tau = mechanical_tau_s(d.f0_hz, d.q.max(d.q_mode2.unwrap_or(0.0)));
            if s < 10.6 * tau {
                warnings.push(format!(
                    "experiment.settle_s = {s} is shorter than 10.6 mechanical time constants ({} s): phase errors above 1 mdeg remain",
                    10.6 * tau
                ));
            }
        }
        positive("experiment.average_s", e.average_s)?;
        check(
            e.average_s >= 1.0 / self.fs_out_hz(),
            "experiment.average_s",
            e.average_s,
            &format!(
                "must cover at least one output sample period ({} s)",
                1.0 / self.fs_out_hz()
            ),
        )?;
        // Sample indices and counts must stay exact in f64 (and far from u64 overflow).
        let run_samples = (self.settle_s() + e.average_s) * fs_hz;
        check(
            run_samples <= MAX_RUN_SAMPLES,
            if e.settle_s.is_some_and(|s| s > e.average_s) {
                "experiment.settle_s"
            } else {
                "experiment.average_s"
            },
            e.settle_s.filter(|&s| s > e.average_s).unwrap_or(e.average_s),
            &format!(
                "settling plus averaging must span at most 2^53 = {MAX_RUN_SAMPLES:e} input samples per point (here {run_samples:e} at fs_hz = {})",
                fs_hz
            ),
        )?;
        if e.kind == ExperimentKind::Rotating {
            if let Some(min) = e
                .rates_dps
                .iter()
                .map(|r| r.abs())
                .filter(|&r| r > 0.0)
                .reduce(f64::min)
            {
                let half_period = 180.0 / min;
                check(
                    e.average_s >= half_period,
                    "experiment.average_s",
                    e.average_s,
                    &format!(
                        "must cover at least half a modulation period of the slowest rate ({min} deg/s: {half_period} s)"
                    ),
                )?;
            }
        }
        match (e.rate_table, e.kind) {
            (RateTable::Constant, _) => {
                if e.table_freq_hz.is_some() {
                    return Err(ConfigError::key(
                        "experiment.table_freq_hz",
                        e.table_freq_hz.unwrap_or_default(),
                        "only applies with rate_table = \"sinusoid\"",
                    ));
                }
            }
            (RateTable::Sinusoid, ExperimentKind::Rotating) => {
                return Err(ConfigError::key(
                    "experiment.rate_table",
                    "\"sinusoid\"",
                    "a rate table applies to kind = \"coriolis\" only",
                ))
            }
            (RateTable::Sinusoid, ExperimentKind::Coriolis) => {
                let Some(ft) = e.table_freq_hz else {
                    return Err(ConfigError::key(
                        "experiment.table_freq_hz",
                        "(missing)",
                        "is required with rate_table = \"sinusoid\"",
                    ));
                };
                check(
                    ft.is_finite() && ft > 0.0 && ft < cutoff_hz,
                    "experiment.table_freq_hz",
                    ft,
                    &format!(
                        "must be > 0 and below board.lpf_cutoff_hz = {} Hz",
                        cutoff_hz
                    ),
                )?;
                check(
                    e.average_s * ft >= 1.0,
                    "experiment.average_s",
                    e.average_s,
                    &format!("must cover at least one rate-table period ({} s)", 1.0 / ft),
                )?;
            }
        }
        if e.window == WindowKind::Hann {
            let slowest_hz = match self.shape() {
                Shape::Rotating => e
                    .rates_dps
                    .iter()
                    .map(|r| r.abs() / 360.0)
                    .filter(|&f| f > 0.0)
                    .reduce(f64::min),
                Shape::RateTable { freq_hz } => Some(freq_hz),
                Shape::Coriolis => None,
            };
            if let Some(f) = slowest_hz {
                if e.average_s * f < 10.0 {
                    warnings.push(format!(
                        "experiment.window = \"hann\" spans only {:.2} periods of the slowest modulation ({f} Hz): below 10 periods it leaks more than 0.1 mdeg; use boxcar or average longer",
                        e.average_s * f
                    ));
                }
            }
        }
        self.validate_noise_adc_selfcal(&mut warnings)?;
        self.validate_regime(&mut warnings)?;
        if let Some(dump) = self.dump_resolved() {
            let (rate_dps, start_s, duration_s) = (
                dump.rate_dps.unwrap_or(f64::NAN),
                dump.start_s.unwrap_or(f64::NAN),
                dump.duration_s.unwrap_or(f64::NAN),
            );
            let nodes = dump.nodes.unwrap_or_default();
            let emulated = self.emulated_rates_dps();
            check(
                emulated.contains(&rate_dps),
                "dump.rate_dps",
                rate_dps,
                &format!("must be one of the emulated rates {emulated:?}"),
            )?;
            non_negative("dump.start_s", start_s)?;
            positive("dump.duration_s", duration_s)?;
            // The point runs settling plus its own averaging window (whole half periods).
            let p = self.plan_point(rate_dps);
            let n_out = self
                .n_settle_out()
                .saturating_add(p.n_avg())
                .saturating_add(1);
            let total = n_out as f64 / self.fs_out_hz();
            check(
                start_s + duration_s <= total,
                "dump.duration_s",
                duration_s,
                &format!(
                    "the window start_s + duration_s must end within that point's run ({total} s)"
                ),
            )?;
            let frames = duration_s * fs_hz;
            check(
                frames <= 5e7,
                "dump.duration_s",
                duration_s,
                "the window must hold at most 5e7 full-rate samples (keep dumps small)",
            )?;
            check(
                !nodes.is_empty(),
                "dump.nodes",
                "[]",
                "must list at least one node",
            )?;
            for (i, n) in nodes.iter().enumerate() {
                check(
                    DUMP_NODES.contains(&n.as_str()),
                    &format!("dump.nodes[{i}]"),
                    format!("\"{n}\""),
                    &format!("must be one of {DUMP_NODES:?}"),
                )?;
            }
        }
        Ok(warnings)
    }
}
