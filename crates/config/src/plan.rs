//! What a config implies before anything runs: its experiment shape, the board it describes,
//! the operating points it emulates and their settling and averaging windows.

use crate::config::{Config, ExperimentKind, NoiseConfig, RateTable, Spacing, WindowKind};
use gyroemu_board::{BoardParams, Converter, NoiseParams, Point, Shape};
use gyroemu_lpf::{LowPassDesign, Window};
use gyroemu_mixer::MAX_TABLE_HARMONIC;
use gyroemu_resonator::{ModeParams, ResonatorParams};
use gyroemu_theory::{mechanical_tau_s, DrivenDevice};
use gyroemu_tia::TiaParams;

/// Radians per degree.
pub(crate) const DEG: f64 = core::f64::consts::PI / 180.0;

/// A rate-table run demodulates every table harmonic of the envelope above this fraction of
/// its largest one (what it leaves out moves the phase by about as many radians).
pub const TABLE_HARMONIC_REL: f64 = 1e-10;

impl Config {
    /// The experiment's shape: the `kind` and `rate_table` keys read once (validation refuses
    /// a rate table with the rotating excitation).
    pub fn shape(&self) -> Shape {
        let e = &self.experiment;
        match (e.kind, e.rate_table) {
            (ExperimentKind::Rotating, _) => Shape::Rotating,
            (ExperimentKind::Coriolis, RateTable::Constant) => Shape::Coriolis,
            (ExperimentKind::Coriolis, RateTable::Sinusoid) => Shape::RateTable {
                freq_hz: e.table_freq_hz.unwrap_or(0.0),
            },
        }
    }

    /// Mode-2 resonance, Hz.
    pub fn f0_mode2_hz(&self) -> f64 {
        self.device.f0_hz + self.device.mode2_f0_offset_hz
    }

    /// Output rate of the low-pass decimator, Hz.
    pub fn fs_out_hz(&self) -> f64 {
        self.fs_hz() / self.decimation() as f64
    }

    /// The settling time used: the configured one, or 16 mechanical time constants (phase
    /// error below 0.01 mdeg, THEORY.md section 7) plus the low-pass's share
    /// ([`Config::lowpass_settle_s`]).
    pub fn settle_s(&self) -> f64 {
        self.experiment
            .settle_s
            .unwrap_or_else(|| self.default_settle_s())
    }

    /// The default settling: 16 mechanical time constants (of the higher Q) plus the
    /// low-pass's share ([`Config::lowpass_settle_s`]).
    pub fn default_settle_s(&self) -> f64 {
        let q = self.device.q.max(self.device.q_mode2.unwrap_or(0.0));
        16.0 * mechanical_tau_s(self.device.f0_hz, q) + self.lowpass_settle_s()
    }

    /// The stage-1 low-pass's share of a default settling: 40 time constants 1 / (2 pi
    /// lpf_cutoff_hz), times sin(pi/8) / sin(pi/(2 order)) above order 4. Why: a Butterworth's
    /// slowest pole decays at 2 pi fc sin(pi/(2 order)), so 40 time constants leave a
    /// fourth-order filter's start-up at e^-15.3 but an eighth-order one's at e^-7.8, which
    /// moved a rotating reading by 4.6 mdeg and a rate table's by tens of degrees, unwarned;
    /// the factor gives every order the fourth order's e^-15.3.
    pub fn lowpass_settle_s(&self) -> f64 {
        use core::f64::consts::PI;
        let slower = ((PI / 8.0).sin() / self.lowpass_slowest_sin()).max(1.0);
        40.0 * slower / (2.0 * PI * self.lpf_cutoff_hz())
    }

    /// One e-fold of the stage-1 low-pass's start-up, s: its slowest pole decays at 2 pi
    /// lpf_cutoff_hz sin(pi/(2 order)).
    pub fn lowpass_efold_s(&self) -> f64 {
        1.0 / (core::f64::consts::TAU * self.lpf_cutoff_hz() * self.lowpass_slowest_sin())
    }

    /// sin(pi/(2 order)) of the Butterworth low-pass, the order clamped to the orders the
    /// rules allow: a refused order must not make the derived settling, and so the run's
    /// span, a second refusal.
    fn lowpass_slowest_sin(&self) -> f64 {
        let r = crate::schema::LPF_ORDER;
        let order = (self.board.lpf_order as u64).clamp(r.lo, r.hi) as f64;
        (core::f64::consts::PI / (2.0 * order)).sin()
    }

    /// Settling in decimated samples (the whole output periods that cover `settle_s`).
    pub fn n_settle_out(&self) -> u64 {
        (self.settle_s() * self.fs_out_hz()).ceil() as u64
    }

    /// The plant parameters.
    pub fn resonator_params(&self) -> ResonatorParams {
        let d = &self.device;
        ResonatorParams {
            mode1: ModeParams {
                f0_hz: d.f0_hz,
                q: d.q,
            },
            mode2: ModeParams {
                f0_hz: self.f0_mode2_hz(),
                q: d.q_mode2.unwrap_or(d.q),
            },
            angular_gain: d.angular_gain,
            quadrature_coupling_rad2_s2: d.quadrature_coupling_rad2_s2,
            transduction_a_s_per_m: d.transduction_a_s_per_m,
            fs_hz: self.fs_hz(),
        }
    }

    /// The device and its drive, for the theory.
    pub fn driven_device(&self) -> DrivenDevice {
        DrivenDevice {
            plant: self.resonator_params(),
            drive: [self.drive.f1, self.f2()],
            phase_shifter_error_deg: self.board.phase_shifter_error_deg,
            carrier_hz: self.carrier_hz(),
        }
    }

    /// The largest listed rate magnitude, rad/s (0 if none is finite).
    pub fn max_rate_rad_s(&self) -> f64 {
        self.experiment
            .rates_dps
            .iter()
            .filter(|r| r.is_finite())
            .fold(0.0, |a: f64, r| a.max(r.abs()))
            * DEG
    }

    /// Rate-table runs: the table harmonics `-N ..= N` the board demodulates, the fewest that
    /// leave nothing above `TABLE_HARMONIC_REL` (1e-10) of the envelope at the largest amplitude
    /// (from the plant's exact periodic steady state), at most [`MAX_TABLE_HARMONIC`]; `None`
    /// when the swing needs more. 0 for the other shapes.
    pub fn table_harmonics_needed(&self) -> Option<usize> {
        let Shape::RateTable { freq_hz } = self.shape() else {
            return Some(0);
        };
        self.driven_device()
            .rate_table_harmonics_needed(
                self.max_rate_rad_s(),
                freq_hz,
                TABLE_HARMONIC_REL,
                MAX_TABLE_HARMONIC,
            )
            .map(|n| n.max(1))
    }

    /// [`Config::table_harmonics_needed`], or all the board has (validation warns).
    pub fn table_harmonics(&self) -> usize {
        self.table_harmonics_needed().unwrap_or(MAX_TABLE_HARMONIC)
    }

    /// The stage-1 low-pass.
    pub fn lowpass_design(&self) -> LowPassDesign {
        LowPassDesign::Butterworth {
            order: self.board.lpf_order,
            cutoff_hz: self.lpf_cutoff_hz(),
        }
    }

    /// The board this config describes.
    pub fn board_params(&self) -> BoardParams {
        let b = &self.board;
        BoardParams {
            plant: self.resonator_params(),
            carrier_hz: self.carrier_hz(),
            drive: [self.drive.f1, self.f2()],
            phase_shifter_error_deg: b.phase_shifter_error_deg,
            dac: b.dac_bits.map(|bits| Converter {
                bits,
                full_scale: b.dac_full_scale,
            }),
            tia: TiaParams {
                gain_ohm: b.tia_gain_ohm,
                pole_hz: b.tia_pole_hz,
                inverting: b.tia_inverting,
                rail_v: b.tia_rail_v,
                fs_hz: self.fs_hz(),
            },
            adc: b.adc_bits.map(|bits| Converter {
                bits,
                full_scale: b.adc_full_scale_v,
            }),
            lowpass: self.lowpass_design(),
            decimation: self.decimation(),
            noise: self
                .noise
                .as_ref()
                .map(|n| noise_params(n, self.flicker_f_lo_hz())),
            shape: self.shape(),
            table_harmonics: self.table_harmonics(),
        }
    }

    /// The rates emulated: the listed ones, plus 0 for a constant-rate Coriolis run when it is
    /// not listed (the reference the shifts are measured against).
    pub fn emulated_rates_dps(&self) -> Vec<f64> {
        let mut r = self.experiment.rates_dps.clone();
        if self.shape() == Shape::Coriolis && !r.contains(&0.0) {
            r.push(0.0);
        }
        r
    }

    /// The averaging window of a point, in decimated samples after settling: whole half
    /// modulation periods (rotating) or whole table periods (rate table) with the fractional
    /// end that makes the span exact, or a Hann window of the averaging time.
    pub fn plan_point(&self, rate_dps: f64) -> Point {
        let e = &self.experiment;
        let fs_out = self.fs_out_hz();
        let rate_rad_s = rate_dps * DEG;
        if e.window == WindowKind::Hann {
            return Point {
                rate_rad_s,
                window: Window::Hann {
                    n: (e.average_s * fs_out).floor().max(1.0) as u64,
                },
            };
        }
        // The period whose whole multiples make the boxcar exact.
        let period_s = match self.shape() {
            Shape::Rotating if rate_dps != 0.0 => Some(180.0 / rate_dps.abs()),
            Shape::RateTable { freq_hz } => Some(1.0 / freq_hz),
            _ => None,
        };
        let span_s = match period_s {
            Some(p) => (e.average_s / p).floor().max(1.0) * p,
            None => e.average_s,
        };
        let x = span_s * fs_out;
        Point {
            rate_rad_s,
            window: Window::Boxcar {
                n: x.floor() as u64,
                frac: if period_s.is_some() {
                    x - x.floor()
                } else {
                    0.0
                },
            },
        }
    }

    /// The stepped-sine frequencies of the resolved `[sweep]`, Hz: ascending, `start_hz`
    /// and `stop_hz` included (see [`sweep_grid`]).
    pub fn sweep_frequencies_hz(&self) -> Vec<f64> {
        let s = self.sweep_resolved();
        sweep_grid(
            s.start_hz.unwrap_or(f64::NAN),
            s.stop_hz.unwrap_or(f64::NAN),
            s.points,
            s.spacing,
            &self.mode_resonances_hz(),
        )
    }

    /// One swept frequency's run in decimated samples: the settling (whole output periods
    /// covering `sweep.settle_s`) and the boxcar averaging window (the whole output periods in
    /// `sweep.average_s`, at least one).
    pub fn sweep_point(&self) -> (u64, Point) {
        let s = self.sweep_resolved();
        let fs_out = self.fs_out_hz();
        let settle = (s.settle_s.unwrap_or(0.0) * fs_out).ceil() as u64;
        let n = (s.average_s.unwrap_or(0.0) * fs_out).floor().max(1.0) as u64;
        (
            settle,
            Point {
                rate_rad_s: 0.0,
                window: Window::Boxcar { n, frac: 0.0 },
            },
        )
    }
}

/// `points` frequencies from `start_hz` to `stop_hz` (both included, ascending), spaced
/// evenly in frequency, in log frequency, or in `g(f) = sum_k atan((f - f0_k) / b_k)` over the
/// modes `(f0_k, b_k)` (resonance and half-bandwidth): the phase of each resonance moves by
/// the same step between neighbours, so the points crowd where the response changes.
pub fn sweep_grid(
    start_hz: f64,
    stop_hz: f64,
    points: usize,
    spacing: Spacing,
    modes: &[(f64, f64)],
) -> Vec<f64> {
    if points < 2 {
        return vec![start_hz; points];
    }
    let last = (points - 1) as f64;
    let at = |i: usize, lo: f64, hi: f64| lo + (hi - lo) * (i as f64 / last);
    let mut f: Vec<f64> = match spacing {
        Spacing::Linear => (0..points).map(|i| at(i, start_hz, stop_hz)).collect(),
        Spacing::Log => (0..points)
            .map(|i| at(i, start_hz.ln(), stop_hz.ln()).exp())
            .collect(),
        Spacing::Resonance => {
            let g = |f: f64| -> f64 { modes.iter().map(|&(f0, b)| ((f - f0) / b).atan()).sum() };
            let (g0, g1) = (g(start_hz), g(stop_hz));
            (0..points)
                .map(|i| {
                    // g rises monotonically: bisection to the last bit.
                    let target = at(i, g0, g1);
                    let (mut lo, mut hi) = (start_hz, stop_hz);
                    for _ in 0..200 {
                        let mid = 0.5 * (lo + hi);
                        if mid <= lo || mid >= hi {
                            break;
                        }
                        if g(mid) < target {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    0.5 * (lo + hi)
                })
                .collect()
        }
    };
    f[0] = start_hz;
    f[points - 1] = stop_hz;
    f
}

impl Config {
    /// Each flicker source's one-sided density at 1 Hz as the board draws it: the TIA's
    /// (input-referred, A^2/Hz), then the drive amplitude's, the drive phase's and the
    /// carrier phase's; zeros without `[noise]`.
    pub(crate) fn flicker_psds_at_1hz(&self) -> [f64; 4] {
        self.noise.as_ref().map_or([0.0; 4], |n| {
            noise_params(n, self.flicker_f_lo_hz())
                .flicker_psds_at_1hz(self.board.tia_gain_ohm)
                .map(|(_, s1)| s1)
        })
    }

    /// A flicker source of density `s1` at 1 Hz drawn at `rate_hz`, designed as the board
    /// designs it (from the flicker corner f_lo up to rate/2); `None` when `s1` is 0 or the
    /// design is refused.
    pub(crate) fn flicker_design(
        &self,
        s1: f64,
        rate_hz: f64,
    ) -> Option<gyroemu_core::flicker::FlickerDesign> {
        if s1 == 0.0 {
            return None;
        }
        gyroemu_core::flicker::FlickerDesign::new(&gyroemu_core::flicker::FlickerParams {
            fs_hz: rate_hz,
            psd_at_1hz: s1,
            f_lo_hz: self.flicker_f_lo_hz(),
            f_hi_hz: 0.5 * rate_hz,
        })
        .ok()
    }
}

/// The board's noise parameters from a `[noise]` section, with the flicker sources' low corner
/// (resolved by [`Config::flicker_f_lo_hz`]).
pub(crate) fn noise_params(n: &NoiseConfig, flicker_f_lo_hz: f64) -> NoiseParams {
    NoiseParams {
        seed: n.seed,
        temperature_k: n.temperature_k,
        effective_mass_kg: n.effective_mass_kg,
        tia_current_noise_a_per_rthz: n.tia_current_noise_a_per_rthz,
        tia_voltage_noise_v_per_rthz: n.tia_voltage_noise_v_per_rthz,
        tia_voltage_flicker_corner_hz: n.tia_voltage_flicker_corner_hz,
        drive_amplitude_flicker_per_rthz: n.drive_amplitude_flicker_per_rthz,
        drive_phase_flicker_rad_per_rthz: n.drive_phase_flicker_rad_per_rthz,
        carrier_phase_flicker_rad_per_rthz: n.carrier_phase_flicker_rad_per_rthz,
        flicker_f_lo_hz,
    }
}
