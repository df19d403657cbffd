//! Validation of the `[sweep]` keys (`gyroemu sweep`; same error form: key, value, rule). The
//! keys a config leaves out are derived from the device, so a bad device key is reported once,
//! not again through the sweep derived from it.

use crate::config::Config;
use crate::rules::Rules;
use crate::schema::SWEEP_POINTS;
use crate::validate::MAX_RUN_SAMPLES;

/// Most frequencies a sweep may list (the schema's range, one source for the parser's
/// messages and these rules).
pub const MAX_SWEEP_POINTS: usize = SWEEP_POINTS.hi as usize;
/// Fewest frequencies: the resonance fit has four parameters (f0, Q and a complex gain).
pub const MIN_SWEEP_POINTS: usize = SWEEP_POINTS.lo as usize;
/// A mode's fit wants at least this many frequencies within one half-bandwidth of its
/// resonance (fewer: a warning, f0 and Q then rest on the skirts).
pub const MIN_POINTS_NEAR_RESONANCE: usize = 3;

/// The device keys the derived sweep keys come from.
const DEVICE_KEYS: [&str; 4] = [
    "device.f0_hz",
    "device.q",
    "device.q_mode2",
    "device.mode2_f0_offset_hz",
];

impl Config {
    /// The rules of the resolved `[sweep]` (its defaults when the section is absent); appends
    /// warnings.
    pub(crate) fn validate_sweep_rules(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let given = self.sweep.clone().unwrap_or_default();
        let s = self.sweep_resolved();
        let nan = f64::NAN;
        let (start, stop) = (s.start_hz.unwrap_or(nan), s.stop_hz.unwrap_or(nan));
        let (settle, average) = (s.settle_s.unwrap_or(nan), s.average_s.unwrap_or(nan));
        // A key equal to what the device derives is as bad as the device keys.
        let raw = {
            let mut c = self.clone();
            c.sweep = Some(crate::config::SweepConfig {
                start_hz: None,
                stop_hz: None,
                settle_s: None,
                average_s: None,
                ..given.clone()
            });
            c.sweep_resolved()
        };
        let same = |a: Option<f64>, b: Option<f64>| a.map(f64::to_bits) == b.map(f64::to_bits);
        for (key, derived) in [
            ("sweep.start_hz", same(s.start_hz, raw.start_hz)),
            ("sweep.stop_hz", same(s.stop_hz, raw.stop_hz)),
            ("sweep.settle_s", same(s.settle_s, raw.settle_s)),
            ("sweep.average_s", same(s.average_s, raw.average_s)),
        ] {
            if derived {
                for source in DEVICE_KEYS {
                    p.derived_from(key, source);
                }
                p.derived_from(key, "board.lpf_cutoff_hz");
            }
        }
        if p.positive("sweep.start_hz", start) && p.clean(&["board.lpf_cutoff_hz"]) {
            let cutoff = self.lpf_cutoff_hz();
            p.check(
                start > cutoff,
                "sweep.start_hz",
                start,
                format!("must be above board.lpf_cutoff_hz = {cutoff} Hz (the stage-1 low-pass must remove the mixer's 2 f product)"),
            );
        }
        if p.positive("sweep.stop_hz", stop) {
            if p.clean(&["sweep.start_hz"]) {
                p.check(
                    stop > start,
                    "sweep.stop_hz",
                    stop,
                    format!("must be above sweep.start_hz = {start} Hz"),
                );
            }
            if p.clean(&["board.fs_hz"]) {
                let nyquist = 0.5 * self.fs_hz();
                p.check(
                    stop < nyquist,
                    "sweep.stop_hz",
                    stop,
                    format!("must be below Nyquist (fs_hz/2 = {nyquist} Hz)"),
                );
            }
        }
        p.check(
            SWEEP_POINTS.contains(s.points),
            "sweep.points",
            s.points,
            format!(
                "{} (at least {MIN_SWEEP_POINTS}: the resonance fit has four parameters)",
                SWEEP_POINTS.rule()
            ),
        );
        if p.clean(&[
            "sweep.start_hz",
            "sweep.stop_hz",
            "sweep.points",
            "board.fs_hz",
        ]) {
            // The frequencies the carrier NCO realises: a span of a few ulps gave two distinct
            // ones for ten points, and fits that counted the copies as data.
            let fs = self.fs_hz();
            let mut realised: Vec<u64> = self
                .sweep_frequencies_hz()
                .into_iter()
                .filter_map(|f| gyroemu_nco::Nco::new(f, fs, 0.0).ok())
                .map(|n| n.f_hz().to_bits())
                .collect();
            realised.sort_unstable();
            realised.dedup();
            p.check(
                realised.len() >= MIN_SWEEP_POINTS,
                "sweep.stop_hz",
                stop,
                format!(
                    "start_hz .. stop_hz ({start} .. {stop} Hz) holds only {} distinct frequencies the carrier NCO can realise, of the {} asked: the resonance fit needs {MIN_SWEEP_POINTS}; widen the span",
                    realised.len(),
                    s.points
                ),
            );
        }
        let device_ok = p.clean(&DEVICE_KEYS);
        if p.non_negative("sweep.settle_s", settle) && device_ok {
            let tau = self.slowest_tau_s();
            if settle < 10.6 * tau {
                // Each frequency's average over T keeps at most e^(-settle/tau) tau/T (1 -
                // e^(-T/tau)) of its start-up transient (the mean of a decaying exponential),
                // relative to the response: that much of the magnitude, its asin in phase.
                let t = if average.is_finite() && average > 0.0 {
                    average
                } else {
                    f64::INFINITY
                };
                let rel = ((-settle / tau).exp() * tau / t * -(-t / tau).exp_m1()).min(1.0);
                warnings.push(format!(
                    "sweep.settle_s = {settle} is shorter than 10.6 mechanical time constants ({} s): the start-up transient left in each average over sweep.average_s can move a Bode point by up to {:.1e} of its magnitude and {:.3e} mdeg in phase, and biases the fit",
                    10.6 * tau,
                    rel,
                    rel.asin().to_degrees() * 1e3
                ));
            }
        }
        let rates_ok = p.clean(&["board.fs_hz", "board.decimation"]);
        if p.positive("sweep.average_s", average) && rates_ok {
            p.check(
                average >= 1.0 / self.fs_out_hz(),
                "sweep.average_s",
                average,
                format!(
                    "must cover at least one output sample period ({} s)",
                    1.0 / self.fs_out_hz()
                ),
            );
        }
        if rates_ok && p.clean(&["sweep.settle_s", "sweep.average_s"]) {
            let run_samples = (settle + average) * self.fs_hz();
            let key = if settle > average {
                ("sweep.settle_s", settle)
            } else {
                ("sweep.average_s", average)
            };
            p.check(
                run_samples <= MAX_RUN_SAMPLES,
                key.0,
                key.1,
                format!(
                    "settling plus averaging must span at most 2^53 = {MAX_RUN_SAMPLES:e} input samples per frequency (here {run_samples:e})"
                ),
            );
        }
        if device_ok && p.clean(&["sweep.start_hz", "sweep.stop_hz", "sweep.points"]) {
            let freqs = self.sweep_frequencies_hz();
            for (k, (f0, b)) in self.mode_resonances_hz().into_iter().enumerate() {
                if !(start..=stop).contains(&f0) {
                    warnings.push(format!(
                        "mode {}'s resonance {f0} Hz lies outside sweep.start_hz .. sweep.stop_hz ({start} .. {stop} Hz): its fit extrapolates",
                        k + 1
                    ));
                    continue;
                }
                let near = freqs.iter().filter(|f| (*f - f0).abs() <= b).count();
                if near < MIN_POINTS_NEAR_RESONANCE {
                    warnings.push(format!(
                        "only {near} of the swept frequencies lie within a half-bandwidth ({b} Hz) of mode {}'s resonance {f0} Hz: its f0 and Q rest on the skirts; raise sweep.points, narrow the span or use spacing = \"resonance\"",
                        k + 1
                    ));
                }
            }
        }
        let swept = [
            "sweep.start_hz",
            "sweep.stop_hz",
            "sweep.points",
            "sweep.average_s",
        ];
        if rates_ok && p.clean(&swept) && p.section_clean("board") {
            self.validate_sweep_mixer_products(warnings);
            if p.section_clean("drive") {
                self.validate_sweep_dac(warnings);
            }
        }
    }
}
