//! Config parsing and validation before any sample is computed. Each error names the key,
//! the value and the rule (and the line and column when TOML parsing located it).

use crate::config::{Config, ExperimentKind, RateTable, WindowKind, DUMP_NODES};
use gyroemu_theory::mechanical_tau_s;
use thiserror::Error;

/// A config the emulator refuses.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("config error: {}{}{}", .location.as_ref().map(|l| format!("{l}: ")).unwrap_or_default(), .key.as_ref().map(|k| format!("key `{k}`")).unwrap_or_default(), .detail)]
pub struct ConfigError {
    /// `line L, column C` where TOML parsing knows it.
    pub location: Option<String>,
    /// Dotted key path, e.g. `device.q`.
    pub key: Option<String>,
    /// What is wrong and the allowed range.
    pub detail: String,
}

impl ConfigError {
    /// An error about one key's value.
    pub fn key(key: &str, value: impl std::fmt::Display, rule: impl std::fmt::Display) -> Self {
        Self {
            location: None,
            key: Some(key.to_string()),
            detail: format!(" = {}: {rule}", readable(value.to_string())),
        }
    }
}

/// A number as the user would write it: very large or very small magnitudes in exponent
/// form (`1e300`, `-1e-9`) instead of hundreds of digits; anything else unchanged.
fn readable(value: String) -> String {
    match value.parse::<f64>() {
        Ok(x) if x.is_finite() && x != 0.0 && !(1e-5..1e16).contains(&x.abs()) => {
            format!("{x:e}")
        }
        _ => value,
    }
}

/// Parses TOML text into a config; unknown keys, wrong types and missing keys are errors.
pub fn parse_config(text: &str) -> Result<Config, ConfigError> {
    if text.trim().is_empty() {
        return Err(ConfigError {
            location: None,
            key: None,
            detail: "the config file is empty".into(),
        });
    }
    toml::from_str::<Config>(text).map_err(|e| {
        let message = e.message().trim().to_string();
        let Some(span) = e.span() else {
            return ConfigError {
                location: None,
                key: None,
                detail: message,
            };
        };
        let start = floor_char_boundary(text, span.start);
        let before = &text[..start];
        let line = before.matches('\n').count() + 1;
        let col = before[before.rfind('\n').map(|i| i + 1).unwrap_or(0)..]
            .chars()
            .count()
            + 1;
        ConfigError {
            location: Some(format!("line {line}, column {col}")),
            key: Some(key_at(text, start, &message)),
            detail: format!(": {message}"),
        }
    })
}

/// The largest char boundary at or below `i` (TOML spans are byte offsets).
fn floor_char_boundary(text: &str, i: usize) -> usize {
    let mut i = i.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// The dotted key a TOML error at byte `offset` is about: the table header above it plus the
/// key of its line (or of the nearest `key =` line above, for a multi-line value), or the
/// field a "missing field" / "unknown field" message names. Best effort: it only labels
/// the message, the line and column stay exact.
fn key_at(text: &str, offset: usize, message: &str) -> String {
    let mut table = String::new();
    let mut key = None;
    let mut on_header = false;
    let mut line_start = 0;
    for raw in text.split_inclusive('\n') {
        if line_start > offset {
            break;
        }
        let l = raw.split('#').next().unwrap_or("").trim();
        on_header = l.starts_with('[');
        if on_header {
            table = l.trim_matches(|c| c == '[' || c == ']').trim().to_string();
            key = None;
        } else if let Some((k, _)) = l.split_once('=') {
            let k = k.trim().trim_matches('"');
            if !k.is_empty() && !k.contains(char::is_whitespace) {
                key = Some(k.to_string());
            }
        }
        line_start += raw.len();
    }
    let named = ["missing field `", "unknown field `"]
        .iter()
        .find_map(|p| message.strip_prefix(p))
        .and_then(|rest| rest.split('`').next())
        .map(str::to_string);
    // A missing field's span is its table, so the key is the table's child.
    let leaf = named.or(key);
    // An unknown table is reported at its own header: the key is the table itself.
    if on_header && leaf.as_deref() == table.rsplit('.').next() {
        return table;
    }
    match (table.is_empty(), leaf) {
        (true, Some(k)) => k,
        (false, Some(k)) => format!("{table}.{k}"),
        (false, None) => table,
        (true, None) => "(top level)".into(),
    }
}

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
    /// Mode-2 resonance, Hz.
    pub fn f0_mode2_hz(&self) -> f64 {
        self.device.f0_hz + self.device.mode2_f0_offset_hz
    }

    /// Output rate of the low-pass decimator, Hz.
    pub fn fs_out_hz(&self) -> f64 {
        self.board.fs_hz / self.board.decimation as f64
    }

    /// The settling time used: the configured one, or 16 mechanical time constants (phase
    /// error below 0.01 mdeg, THEORY.md section 7) plus 40 low-pass time constants.
    pub fn settle_s(&self) -> f64 {
        self.experiment.settle_s.unwrap_or_else(|| {
            let q = self.device.q.max(self.device.q_mode2.unwrap_or(0.0));
            16.0 * mechanical_tau_s(self.device.f0_hz, q)
                + 40.0 / (2.0 * core::f64::consts::PI * self.board.lpf_cutoff_hz)
        })
    }

    /// Settling in decimated samples (the whole output periods that cover `settle_s`).
    pub fn n_settle_out(&self) -> u64 {
        (self.settle_s() * self.fs_out_hz()).ceil() as u64
    }

    /// Checks every rule that does not need the stages built; returns warnings.
    pub fn validate(&self) -> Result<Vec<String>, ConfigError> {
        let d = &self.device;
        let b = &self.board;
        let e = &self.experiment;
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
        positive("drive.f2", self.drive.f2)?;

        positive("board.fs_hz", b.fs_hz)?;
        let f_max = d.f0_hz.max(self.f0_mode2_hz());
        check(
            b.fs_hz > 2.0 * f_max,
            "board.fs_hz",
            b.fs_hz,
            &format!("must be above 2*f0 = {} Hz", 2.0 * f_max),
        )?;
        if b.fs_hz < 8.0 * f_max {
            warnings.push(format!(
                "board.fs_hz = {} is below 8*f0 = {} Hz: the sample hold distorts the drive; 16 samples per period is advised",
                b.fs_hz,
                8.0 * f_max
            ));
        }
        positive("board.tia_gain_ohm", b.tia_gain_ohm)?;
        if let Some(p) = b.tia_pole_hz {
            check(
                p.is_finite() && p > 0.0 && p < 0.5 * b.fs_hz,
                "board.tia_pole_hz",
                p,
                &format!(
                    "must be > 0 and below Nyquist (fs_hz/2 = {} Hz)",
                    0.5 * b.fs_hz
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
            b.decimation >= 1,
            "board.decimation",
            b.decimation,
            "must be an integer >= 1",
        )?;
        let nyq_out = 0.5 * self.fs_out_hz();
        check(
            b.lpf_cutoff_hz.is_finite() && b.lpf_cutoff_hz > 0.0 && b.lpf_cutoff_hz < nyq_out,
            "board.lpf_cutoff_hz",
            b.lpf_cutoff_hz,
            &format!(
                "must be > 0 and below the Nyquist rate after decimation (fs_hz/decimation/2 = {nyq_out} Hz)"
            ),
        )?;
        check(
            b.lpf_cutoff_hz < d.f0_hz,
            "board.lpf_cutoff_hz",
            b.lpf_cutoff_hz,
            "must be below f0_hz so the low-pass removes the 2*f0 mixing product",
        )?;
        // The design itself: f64 must realise it with its poles inside the unit circle.
        gyroemu_lpf::LowPass::<f64>::new(crate::board::lowpass_design(self), b.fs_hz).map_err(
            |e| {
                ConfigError::key(
                    "board.lpf_cutoff_hz",
                    b.lpf_cutoff_hz,
                    format!("the stage-1 low-pass cannot be built: {}", e.rule),
                )
            },
        )?;
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
                    f_mod < b.lpf_cutoff_hz,
                    &format!("experiment.rates_dps[{i}]"),
                    r,
                    &format!(
                        "the modulation frequency |rate|/360 must be below board.lpf_cutoff_hz = {} Hz",
                        b.lpf_cutoff_hz
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
        let run_samples = (self.settle_s() + e.average_s) * b.fs_hz;
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
                b.fs_hz
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
                    ft.is_finite() && ft > 0.0 && ft < b.lpf_cutoff_hz,
                    "experiment.table_freq_hz",
                    ft,
                    &format!(
                        "must be > 0 and below board.lpf_cutoff_hz = {} Hz",
                        b.lpf_cutoff_hz
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
            let slowest_hz = match (e.kind, e.rate_table) {
                (ExperimentKind::Rotating, _) => e
                    .rates_dps
                    .iter()
                    .map(|r| r.abs() / 360.0)
                    .filter(|&f| f > 0.0)
                    .reduce(f64::min),
                (ExperimentKind::Coriolis, RateTable::Sinusoid) => e.table_freq_hz,
                _ => None,
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
        if let Some(dump) = &self.dump {
            let emulated = crate::sweep::emulated_rates_dps(self);
            check(
                emulated.contains(&dump.rate_dps),
                "dump.rate_dps",
                dump.rate_dps,
                &format!("must be one of the emulated rates {emulated:?}"),
            )?;
            non_negative("dump.start_s", dump.start_s)?;
            positive("dump.duration_s", dump.duration_s)?;
            // The point runs settling plus its own averaging window (whole half periods).
            let p = crate::sweep::plan_point(self, dump.rate_dps);
            let n_out = self
                .n_settle_out()
                .saturating_add(p.n_avg)
                .saturating_add(1);
            let total = n_out as f64 / self.fs_out_hz();
            check(
                dump.start_s + dump.duration_s <= total,
                "dump.duration_s",
                dump.duration_s,
                &format!(
                    "the window start_s + duration_s must end within that point's run ({total} s)"
                ),
            )?;
            let frames = dump.duration_s * b.fs_hz;
            check(
                frames <= 5e7,
                "dump.duration_s",
                dump.duration_s,
                "the window must hold at most 5e7 full-rate samples (keep dumps small)",
            )?;
            check(
                !dump.nodes.is_empty(),
                "dump.nodes",
                "[]",
                "must list at least one node",
            )?;
            for (i, n) in dump.nodes.iter().enumerate() {
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
