//! Defaults a user should not have to choose, derived from the device and the rates: the
//! sample rate, the second drive, the stage-1 low-pass and the decimation, and a dump's window.
//! `parse_config` fills them in, so a config is always complete once parsed; `gyroemu config
//! --resolved FILE` prints the result with the rule behind each derived value.

use crate::config::{Config, DumpConfig, SweepConfig};
use gyroemu_board::{Shape, DUMP_NODES};

/// Samples per carrier period of the default sample rate (the DAC's hold then moves the
/// phase by about 0.01 mdeg or less).
pub const DEFAULT_SAMPLES_PER_PERIOD: f64 = 16.0;
/// The default cutoff sits this many times above the highest modulation frequency...
pub const CUTOFF_OVER_MODULATION: f64 = 10.0;
/// ...and at least f0 over this (a 4th-order low-pass then takes the 2 f0 mixer product down
/// by 1e-9 or more)...
pub const F0_OVER_MIN_CUTOFF: f64 = 100.0;
/// ...and at most f0 over this.
pub const F0_OVER_MAX_CUTOFF: f64 = 10.0;
/// The default decimation keeps this many output samples per cutoff period.
pub const OUTPUT_SAMPLES_PER_CUTOFF: f64 = 20.0;
/// The derived decimation searches at most this many M, the largest (see `decimation`).
pub const DECIMATION_CANDIDATES: usize = 1 << 16;
/// A default dump holds at most this many full-rate frames (small files).
pub const DEFAULT_DUMP_FRAMES: f64 = 50_000.0;

/// The default frequency sweep reaches this many half-bandwidths f0/(2Q) beyond each mode's
/// resonance (the response there is 1/20 of its peak, the phase within 6 degrees of +-90).
pub const SWEEP_SPAN_HALF_BANDWIDTHS: f64 = 10.0;
/// The default settling at each swept frequency, in mechanical time constants of the slower
/// mode (what is left of the start-up transient, e^-16 = 1e-7 of the response, is far below
/// the fit's resolution), plus the low-pass settling of the rate sweeps.
pub const SWEEP_SETTLE_TAUS: f64 = 16.0;
/// The default averaging at each swept frequency, in mechanical time constants.
pub const SWEEP_AVERAGE_TAUS: f64 = 2.0;

/// A key the config left out, filled with a derived value.
#[derive(Clone, Debug, PartialEq)]
pub struct Derived {
    /// Dotted key, e.g. `board.fs_hz`.
    pub key: &'static str,
    /// The value, as TOML would write it.
    pub value: String,
    /// How it was derived.
    pub rule: String,
}

impl Config {
    /// The highest f0 of the two modes, Hz.
    fn f0_max_hz(&self) -> f64 {
        self.device.f0_hz.max(self.f0_mode2_hz())
    }

    /// Sample rate, Hz (set, or 16 times the highest f0).
    pub fn fs_hz(&self) -> f64 {
        self.board
            .fs_hz
            .unwrap_or(DEFAULT_SAMPLES_PER_PERIOD * self.f0_max_hz())
    }

    /// Carrier frequency of the drive, Hz (set, or the mode-1 resonance).
    pub fn carrier_hz(&self) -> f64 {
        self.drive.carrier_hz.unwrap_or(self.device.f0_hz)
    }

    /// With a `[pll]`, the config its sweep is expected to run: the carrier on the locked
    /// mode's resonance (where the loop steers it) and the `[pll]` spent; `None` without one.
    /// The regime and settling rules judge this config (validation hands it to them, and
    /// [`Config::noise_phase`] takes it): the nominal carrier is only where the lock starts,
    /// and can sit far down the resonance's skirt.
    pub fn expected_lock(&self) -> Option<Config> {
        let p = self.pll.as_ref()?;
        let mut held = self.clone();
        held.drive.carrier_hz = Some(if p.mode == 2 {
            self.f0_mode2_hz()
        } else {
            self.device.f0_hz
        });
        held.pll = None;
        Some(held)
    }

    /// Mode-2 drive amplitude F2 (set, or F1).
    pub fn f2(&self) -> f64 {
        self.drive.f2.unwrap_or(self.drive.f1)
    }

    /// The highest frequency the read-out must pass, Hz: the fastest modulation of a rotating
    /// run, ten harmonics of a rate table (large swings), 0 for a constant rate.
    pub fn modulation_max_hz(&self) -> f64 {
        let finite_max =
            |v: &mut dyn Iterator<Item = f64>| v.filter(|x| x.is_finite()).fold(0.0, f64::max);
        match self.shape() {
            Shape::Rotating => {
                finite_max(&mut self.experiment.rates_dps.iter().map(|r| r.abs() / 360.0))
            }
            Shape::RateTable { freq_hz } if freq_hz.is_finite() => 10.0 * freq_hz,
            _ => 0.0,
        }
    }

    /// Stage-1 low-pass cutoff, Hz (set, or ten times the highest modulation frequency, at
    /// least f0/100 and at most f0/10).
    pub fn lpf_cutoff_hz(&self) -> f64 {
        self.board.lpf_cutoff_hz.unwrap_or_else(|| {
            let f0 = self.device.f0_hz;
            (CUTOFF_OVER_MODULATION * self.modulation_max_hz())
                .max(f0 / F0_OVER_MIN_CUTOFF)
                .min(f0 / F0_OVER_MAX_CUTOFF)
        })
    }

    /// Decimation after the low-pass (set, or derived): at most the `M_max` that keeps 20
    /// output samples per cutoff period, and among `M_max/2 ..= M_max` the one that puts the
    /// stage-1 mixer's 2 f_c product, aliased by the decimation, farthest from DC (the largest
    /// such M on a tie). An output rate dividing 2 f_c would fold what the low-pass leaves of
    /// that product onto the averaged DC (at 16 samples per period, every M multiple of 8).
    /// From `M_max` = 2^17 on, only the top [`DECIMATION_CANDIDATES`] are searched: so many
    /// consecutive M still put the product next to the output Nyquist (tested), and a
    /// mistyped rate (`M_max` up to 1e9) is refused at once instead of after a second's search.
    pub fn decimation(&self) -> usize {
        self.board.decimation.unwrap_or_else(|| {
            let m = (self.fs_hz() / (OUTPUT_SAMPLES_PER_CUTOFF * self.lpf_cutoff_hz())).floor();
            if !(m.is_finite() && m >= 1.0) {
                return 1;
            }
            let m_max = m.min(1e9) as usize;
            let two_fc_per_sample = 2.0 * self.carrier_hz() / self.fs_hz();
            // Distance of the aliased 2 f_c from DC, in output periods (0 .. 1/2).
            let dist = |m: usize| {
                let a = (two_fc_per_sample * m as f64).rem_euclid(1.0);
                a.min(1.0 - a)
            };
            let lowest = m_max
                .div_ceil(2)
                .max(m_max - (DECIMATION_CANDIDATES - 1).min(m_max - 1));
            (lowest..=m_max)
                .rev()
                .fold((m_max, -1.0), |best, m| {
                    let d = dist(m);
                    if d > best.1 + 1e-12 {
                        (m, d)
                    } else {
                        best
                    }
                })
                .0
        })
    }

    /// The dump with every key filled in (see [`DumpConfig`] for the defaults), if any.
    pub fn dump_resolved(&self) -> Option<DumpConfig> {
        let d = self.dump.as_ref()?;
        let rate = d.rate_dps.unwrap_or_else(|| {
            self.experiment
                .rates_dps
                .iter()
                .copied()
                .filter(|r| r.is_finite())
                .fold(0.0, |a: f64, r| if r.abs() > a.abs() { r } else { a })
        });
        let fs = self.fs_hz();
        let start = d.start_s.unwrap_or_else(|| self.settle_s());
        let duration = d.duration_s.unwrap_or_else(|| {
            let f0 = self.device.f0_hz;
            let want = match self.shape() {
                Shape::Rotating if rate != 0.0 => 4.0 * 360.0 / rate.abs(),
                Shape::RateTable { freq_hz } => 4.0 / freq_hz,
                _ => 200.0 / f0,
            };
            // Within the point's run: settling plus its averaging window.
            let p = self.plan_point(rate);
            // Saturating: this runs before validation has bounded settle_s and average_s.
            let n_out = self.n_settle_out().saturating_add(p.window.samples());
            let total = n_out as f64 / self.fs_out_hz();
            want.min(DEFAULT_DUMP_FRAMES / fs)
                .max(20.0 / f0)
                .min(total - start)
        });
        Some(DumpConfig {
            rate_dps: Some(rate),
            start_s: Some(start),
            duration_s: Some(duration),
            nodes: Some(
                d.nodes
                    .clone()
                    .unwrap_or_else(|| DUMP_NODES.iter().map(|n| n.to_string()).collect()),
            ),
        })
    }

    /// Each mode's resonance and half-bandwidth f0/(2Q), Hz, as configured (uncoupled).
    pub fn mode_resonances_hz(&self) -> [(f64, f64); 2] {
        let d = &self.device;
        let q2 = d.q_mode2.unwrap_or(d.q);
        let f2 = self.f0_mode2_hz();
        [(d.f0_hz, d.f0_hz / (2.0 * d.q)), (f2, f2 / (2.0 * q2))]
    }

    /// The longer mechanical time constant Q/(pi f0) of the two modes, s.
    pub fn slowest_tau_s(&self) -> f64 {
        let d = &self.device;
        let q2 = d.q_mode2.unwrap_or(d.q);
        gyroemu_theory::mechanical_tau_s(d.f0_hz, d.q)
            .max(gyroemu_theory::mechanical_tau_s(self.f0_mode2_hz(), q2))
    }

    /// The `[sweep]` section with every key filled in (the section's defaults when it is
    /// absent): `start_hz`/`stop_hz` 10 half-bandwidths beyond the lower/upper resonance,
    /// `settle_s` 16 mechanical time constants of the slower mode plus the low-pass's share
    /// ([`Config::lowpass_settle_s`]), `average_s` 2 mechanical time constants.
    pub fn sweep_resolved(&self) -> SweepConfig {
        let given = self.sweep.clone().unwrap_or_default();
        let [(f1, b1), (f2, b2)] = self.mode_resonances_hz();
        let n = SWEEP_SPAN_HALF_BANDWIDTHS;
        let tau = self.slowest_tau_s();
        SweepConfig {
            start_hz: Some(given.start_hz.unwrap_or((f1 - n * b1).min(f2 - n * b2))),
            stop_hz: Some(given.stop_hz.unwrap_or((f1 + n * b1).max(f2 + n * b2))),
            settle_s: Some(
                given
                    .settle_s
                    .unwrap_or_else(|| SWEEP_SETTLE_TAUS * tau + self.lowpass_settle_s()),
            ),
            average_s: Some(given.average_s.unwrap_or(SWEEP_AVERAGE_TAUS * tau)),
            ..given
        }
    }

    /// Fills every key left out with its derived value (idempotent) and says what it derived.
    pub fn resolve(&mut self) -> Vec<Derived> {
        let mut out = Vec::new();
        let f0 = self.device.f0_hz;
        if self.drive.f2.is_none() {
            self.drive.f2 = Some(self.drive.f1);
            out.push(Derived {
                key: "drive.f2",
                value: fmt(self.drive.f1),
                rule: "equal to drive.f1".into(),
            });
        }
        if self.drive.carrier_hz.is_none() {
            self.drive.carrier_hz = Some(f0);
            out.push(Derived {
                key: "drive.carrier_hz",
                value: fmt(f0),
                rule: "the mode-1 resonance device.f0_hz".into(),
            });
        }
        if self.board.fs_hz.is_none() {
            let fs = self.fs_hz();
            self.board.fs_hz = Some(fs);
            out.push(Derived {
                key: "board.fs_hz",
                value: fmt(fs),
                rule: format!(
                    "{DEFAULT_SAMPLES_PER_PERIOD} samples per period of the highest f0 ({} Hz)",
                    self.f0_max_hz()
                ),
            });
        }
        if self.board.lpf_cutoff_hz.is_none() {
            let c = self.lpf_cutoff_hz();
            self.board.lpf_cutoff_hz = Some(c);
            out.push(Derived {
                key: "board.lpf_cutoff_hz",
                value: fmt(c),
                rule: format!(
                    "{CUTOFF_OVER_MODULATION} x the highest modulation frequency ({} Hz), at least f0/{F0_OVER_MIN_CUTOFF} = {} Hz and at most f0/{F0_OVER_MAX_CUTOFF} = {} Hz",
                    self.modulation_max_hz(),
                    f0 / F0_OVER_MIN_CUTOFF,
                    f0 / F0_OVER_MAX_CUTOFF
                ),
            });
        }
        if self.board.decimation.is_none() {
            let m = self.decimation();
            self.board.decimation = Some(m);
            out.push(Derived {
                key: "board.decimation",
                value: m.to_string(),
                rule: format!(
                    "at most floor(fs_hz / ({OUTPUT_SAMPLES_PER_CUTOFF} x lpf_cutoff_hz)) ({OUTPUT_SAMPLES_PER_CUTOFF} output samples per cutoff period or more), chosen to alias the 2 x carrier mixer product as far from DC as possible"
                ),
            });
        }
        if self.has_flicker()
            && self
                .noise
                .as_ref()
                .is_some_and(|n| n.flicker_f_lo_hz.is_none())
        {
            let f = self.flicker_f_lo_hz();
            if let Some(n) = self.noise.as_mut() {
                n.flicker_f_lo_hz = Some(f);
            }
            out.push(Derived {
                key: "noise.flicker_f_lo_hz",
                value: fmt(f),
                rule: "0.02 / the longest record a run makes (settling plus the longest of average_s, selfcal.allan_record_s and selfcal.tau_max_s)".into(),
            });
        }
        if let Some(pll) = self.pll.clone() {
            if pll.natural_hz.is_none() {
                let f = self.pll_natural_hz().unwrap_or(f64::NAN);
                let (lo, hi) = pll_bounds_hz(self, pll.damping, pll.mode);
                if let Some(p) = self.pll.as_mut() {
                    p.natural_hz = Some(f);
                }
                out.push(Derived {
                    key: "pll.natural_hz",
                    value: fmt(f),
                    rule: format!(
                        "geometric mean of the slowest loop a PI on the frequency can make ({}) and the fastest the low-pass allows ({})",
                        fmt(lo),
                        fmt(hi)
                    ),
                });
            }
            if pll.lock_s.is_none() {
                let t = self.pll_lock_s().unwrap_or(f64::NAN);
                if let Some(p) = self.pll.as_mut() {
                    p.lock_s = Some(t);
                }
                out.push(Derived {
                    key: "pll.lock_s",
                    value: fmt(t),
                    rule: "16 mechanical time constants plus 10 loop time constants 1/(damping x 2 pi natural_hz)".into(),
                });
            }
        }
        if let (Some(given), Some(full)) = (self.dump.clone(), self.dump_resolved()) {
            let pairs = [
                ("dump.rate_dps", given.rate_dps.is_none(), "the largest listed rate"),
                ("dump.start_s", given.start_s.is_none(), "the end of settling"),
                (
                    "dump.duration_s",
                    given.duration_s.is_none(),
                    "4 modulation periods (200 carrier periods at a constant rate), at most 50 000 frames",
                ),
                ("dump.nodes", given.nodes.is_none(), "every node"),
            ];
            for (key, derived, rule) in pairs {
                if derived {
                    let value = match key {
                        "dump.rate_dps" => fmt(full.rate_dps.unwrap_or(0.0)),
                        "dump.start_s" => fmt(full.start_s.unwrap_or(0.0)),
                        "dump.duration_s" => fmt(full.duration_s.unwrap_or(0.0)),
                        _ => format!("{:?}", full.nodes.clone().unwrap_or_default()),
                    };
                    out.push(Derived {
                        key,
                        value,
                        rule: rule.into(),
                    });
                }
            }
            self.dump = Some(full);
        }
        if let Some(given) = self.sweep.clone() {
            let full = self.sweep_resolved();
            let rules = [
                (
                    "sweep.start_hz",
                    given.start_hz.is_none(),
                    full.start_hz,
                    format!("{SWEEP_SPAN_HALF_BANDWIDTHS} half-bandwidths f0/(2Q) below the lower resonance"),
                ),
                (
                    "sweep.stop_hz",
                    given.stop_hz.is_none(),
                    full.stop_hz,
                    format!("{SWEEP_SPAN_HALF_BANDWIDTHS} half-bandwidths f0/(2Q) above the upper resonance"),
                ),
                (
                    "sweep.settle_s",
                    given.settle_s.is_none(),
                    full.settle_s,
                    format!("{SWEEP_SETTLE_TAUS} mechanical time constants Q/(pi f0) of the slower mode plus 40 low-pass time constants 1/(2 pi lpf_cutoff_hz), times sin(pi/8)/sin(pi/(2 lpf_order)) above order 4"),
                ),
                (
                    "sweep.average_s",
                    given.average_s.is_none(),
                    full.average_s,
                    format!("{SWEEP_AVERAGE_TAUS} mechanical time constants Q/(pi f0) of the slower mode"),
                ),
            ];
            for (key, derived, value, rule) in rules {
                if derived {
                    out.push(Derived {
                        key,
                        value: fmt(value.unwrap_or(f64::NAN)),
                        rule,
                    });
                }
            }
            self.sweep = Some(full);
        }
        out
    }
}

/// A number as TOML writes it.
fn fmt(x: f64) -> String {
    toml::Value::Float(x).to_string()
}

/// The loop bounds of the carrier PLL a config allows, Hz: `(lowest, highest)` natural
/// frequency. A PI on the frequency cannot make a loop slower than the envelope damps it
/// (2 zeta w_n tau >= 1, tau = Q/(pi f0) of the locked mode), and the loop must stay within a
/// tenth of the update rate and lag the demodulation low-pass's group delay d by at most
/// `w_n d = 0.05` rad (`gyroemu_pll::MAX_NATURAL_PER_UPDATE`, `MAX_LOWPASS_LAG_RAD`).
pub fn pll_bounds_hz(cfg: &Config, damping: f64, mode: usize) -> (f64, f64) {
    let (f0, q) = if mode == 2 {
        (
            cfg.f0_mode2_hz(),
            cfg.device.q_mode2.unwrap_or(cfg.device.q),
        )
    } else {
        (cfg.device.f0_hz, cfg.device.q)
    };
    let tau = q / (core::f64::consts::PI * f0);
    let lowest = 1.0 / (2.0 * damping * tau * core::f64::consts::TAU);
    let delay_s = gyroemu_lpf::LowPass::<f64>::new(cfg.lowpass_design(), cfg.fs_hz())
        .map(|lp| gyroemu_core::Stage::latency_samples(&lp) / cfg.fs_hz())
        .unwrap_or(f64::NAN);
    let highest = (0.1 * cfg.fs_out_hz()).min(0.05 / (core::f64::consts::TAU * delay_s));
    (lowest, highest)
}

impl Config {
    /// The carrier PLL's natural frequency, Hz (set, or the geometric mean of the bounds of
    /// `pll_bounds_hz`); `None` without a `[pll]` section.
    pub fn pll_natural_hz(&self) -> Option<f64> {
        let p = self.pll.as_ref()?;
        Some(p.natural_hz.unwrap_or_else(|| {
            let (lo, hi) = pll_bounds_hz(self, p.damping, p.mode);
            (lo * hi).sqrt()
        }))
    }

    /// The lock run's length, s (set, or 16 mechanical time constants of the locked mode plus
    /// 10 of the loop's [`Config::pll_time_constant_s`]); `None` without a `[pll]` section.
    pub fn pll_lock_s(&self) -> Option<f64> {
        let p = self.pll.as_ref()?;
        let loop_tau = self.pll_time_constant_s()?;
        Some(p.lock_s.unwrap_or_else(|| {
            let q = self.device.q.max(self.device.q_mode2.unwrap_or(0.0));
            16.0 * q / (core::f64::consts::PI * self.device.f0_hz) + 10.0 * loop_tau
        }))
    }

    /// The closed loop's slowest time constant, s: its poles are `-w_n (zeta -+ sqrt(zeta^2 -
    /// 1))`, so 1/(zeta w_n) up to critical damping and 1/(w_n (zeta - sqrt(zeta^2 - 1))),
    /// about 2 zeta / w_n, above it (1/(zeta w_n) shrank with zeta there, and every default
    /// lock of zeta >= 1.5 ended before the loop settled); `None` without a `[pll]` section.
    pub fn pll_time_constant_s(&self) -> Option<f64> {
        let zeta = self.pll.as_ref()?.damping;
        let w_n = core::f64::consts::TAU * self.pll_natural_hz()?;
        Some(if zeta <= 1.0 {
            1.0 / (zeta * w_n)
        } else {
            // zeta - sqrt(zeta^2 - 1) without the cancellation: 1/(zeta + sqrt(zeta^2 - 1)).
            (zeta + (zeta * zeta - 1.0).sqrt()) / w_n
        })
    }
}

impl Config {
    /// Whether `[noise]` asks for any flicker source.
    pub fn has_flicker(&self) -> bool {
        self.noise
            .as_ref()
            .is_some_and(|n| crate::plan::noise_params(n, 0.0).has_flicker())
    }

    /// The longest record a run of this config makes, s: settling plus the longest of the
    /// averaging time and the selfcal analyses' records.
    pub fn longest_record_s(&self) -> f64 {
        let s = self.selfcal.clone().unwrap_or_default();
        let longest = [s.allan_record_s, s.tau_max_s]
            .into_iter()
            .flatten()
            .fold(self.experiment.average_s, f64::max);
        self.settle_s() + longest
    }

    /// The flicker sources' low corner, Hz (set, or 0.02 / the longest record: a flicker
    /// floor then holds up to about that record's length).
    pub fn flicker_f_lo_hz(&self) -> f64 {
        self.noise
            .as_ref()
            .and_then(|n| n.flicker_f_lo_hz)
            .unwrap_or_else(|| 0.02 / self.longest_record_s())
    }
}
