//! How far the white noise sources scatter a phase reading, against the phase the sweep
//! measures at each rate: a run whose readings the noise dominates is told so before it runs,
//! so its numbers never look clean.

use crate::config::{Config, WindowKind};
use crate::plan::DEG;
use crate::validate_regime::LoHi;
use crate::window_weight::{integrate_over_decades, window_weight};
use gyroemu_board::{ChainResponse, Shape};
use gyroemu_core::Complex64;

/// The noise is said to dominate when a reading's standard deviation passes this fraction of
/// the phase it measures.
pub const WARN_NOISE_PHASE_FRACTION: f64 = 0.1;

/// Variance of one averaged phase, rad^2, for white noise of one-sided density
/// `density_v2_per_hz` (V^2/Hz) at the ADC input near the carrier, a tone of amplitude
/// `amplitude_v` there, averaged over `average_s` with a window of equivalent noise bandwidth
/// `enbw` (1 boxcar, 1.5 Hann). The averaged phasor `mean(2 y e^{-j w t})` of white noise has
/// each component of variance `density enbw / average_s`; its part across the signal moves the
/// phase by that over the amplitude.
pub fn phase_variance_rad2(
    density_v2_per_hz: f64,
    enbw: f64,
    average_s: f64,
    amplitude_v: f64,
) -> f64 {
    density_v2_per_hz * enbw / (average_s * amplitude_v * amplitude_v)
}

/// The noise a reading's phase carries at one listed rate: per mode its standard deviation
/// and the phase the theory gives there (rad), and the TIA output at that rate (V).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoisePhase {
    pub rate_dps: f64,
    pub sigma_rad: [f64; 2],
    pub theory_rad: [f64; 2],
    pub amplitude_v: [f64; 2],
    /// The noise density at the ADC input near the carrier at this rate (V^2/Hz): the
    /// Brownian part depends on the rate, which splits the modes.
    pub density_v2_per_hz: [f64; 2],
    /// A rate table's read harmonic whose noise comes back the most through the read-out
    /// (`Config::table_harmonic_noise_gains`), as `(|n|, noise power per unit of the DC
    /// reading's)`; `None` for other readings.
    pub table_noise_gain_peak: Option<(usize, f64)>,
}

impl Config {
    /// The TIA's white input noise: its density (A/sqrt(Hz), the current noise and
    /// e_n / tia_gain_ohm in power) and the band it reaches the ADC in (Hz: a one-pole TIA
    /// passes pi/2 of its pole frequency of white noise, the sampling at most fs/2). `None`
    /// without `[noise]`.
    pub(crate) fn tia_white_noise(&self) -> Option<(f64, f64)> {
        let n = self.noise.as_ref()?;
        let b = &self.board;
        let density = gyroemu_tia::input_referred_noise_a_per_rthz(
            n.tia_current_noise_a_per_rthz,
            n.tia_voltage_noise_v_per_rthz,
            b.tia_gain_ohm,
        );
        let band = b
            .tia_pole_hz
            .map_or(f64::INFINITY, |fp| core::f64::consts::FRAC_PI_2 * fp)
            .min(0.5 * self.fs_hz());
        Some((density, band))
    }

    /// Per mode, the one-sided density at the ADC input near the carrier (V^2/Hz) of the
    /// white sources, and of the TIA's voltage flicker at its design's density there (a
    /// corner above the carrier made the readings scatter 3.27 times the white-only figure):
    /// the TIA's input noise (current and e_n / tia_gain_ohm) through the TIA at the carrier,
    /// and an ADC's rounding (step^2/12 a sample) where that
    /// noise dithers it (its RMS at the ADC input at least an LSB; an undithered ADC's error
    /// is systematic, and the ADC-LSB rule states it). The wide-band parts (the TIA's input
    /// noise and the ADC's) count what the decimation folds onto the averaged output too
    /// ([`Config::decimation_fold`]). `None` without `[noise]`. All but the Brownian force's
    /// density, which depends on the rate a reading is taken at
    /// ([`Config::brownian_density`]); its RMS still decides whether the ADC is dithered.
    fn carrier_noise_but_brownian(&self) -> Option<[f64; 2]> {
        let n = self.noise.as_ref()?;
        let b = &self.board;
        let chain = ChainResponse::new(&self.board_params()).ok()?;
        let fc = self.carrier_hz();
        let tia = chain.tia(fc).norm_sqr();
        // The TIA noise's RMS at the ADC input, its gain taken at the carrier.
        let (i_n, band) = self.tia_white_noise()?;
        let tia_rms2 = i_n * i_n * tia * band;
        let plant = self.resonator_params();
        let t = self.device.transduction_a_s_per_m;
        let (fold_tia, fold_white) = self.decimation_fold(&chain);
        // The TIA's voltage flicker near the carrier, as its design realises it (input
        // referred, A^2/Hz), with what the decimation folds back at its own density there.
        let flicker = self.tia_flicker_design().map_or(0.0, |d| {
            let at = |f: f64| d.psd(f.abs()) * chain.tia(f).norm_sqr();
            self.fold_sums(&chain, |f| [at(fc + f)])[0]
        });
        Some([plant.mode1, plant.mode2].map(|m| {
            let w0 = core::f64::consts::TAU * m.f0_hz;
            // The Brownian motion's RMS (equipartition, S_a Q / (4 w0)), as current at the
            // TIA's input: it dithers the ADC too.
            let brownian_rms2 = n.effective_mass_kg.map_or(0.0, |mass| {
                let s_a = gyroemu_resonator::thermomechanical_accel_psd(
                    n.temperature_k,
                    mass,
                    m.f0_hz,
                    m.q,
                );
                s_a * m.q / (4.0 * w0) * t * t
            });
            let rms = (tia_rms2 + brownian_rms2 * tia).sqrt();
            let adc = b.adc_bits.map_or(0.0, |bits| {
                let step = b.adc_full_scale_v / (1u64 << (bits - 1)) as f64;
                if rms >= step {
                    step * step / (6.0 * self.fs_hz())
                } else {
                    0.0
                }
            });
            i_n * i_n * tia * fold_tia + flicker + adc * fold_white
        }))
    }

    /// Per mode, the Brownian force's density at the ADC input near the carrier (V^2/Hz) as a
    /// function of the constant rate (rad/s): each mode's white force (of its own f0 and Q)
    /// through the rotating plant's velocity response at the carrier (the Coriolis coupling,
    /// the quadrature coupling and the mode split all in it), transduction and the TIA; 0
    /// without a Brownian source. What does not depend on the rate is found once (a rate
    /// table takes it at 33 rates over its swing). Rotation splits the modes to about
    /// f0 +- lambda Omega / 2 pi, so a carrier detuned onto one of them sees its resonance: the
    /// uncoupled modes' density had stated 28 times less scatter than a detuned Coriolis run
    /// at 3600 deg/s read.
    pub(crate) fn brownian_density(&self) -> impl Fn(f64) -> [f64; 2] + '_ {
        let mass = self.noise.as_ref().and_then(|n| n.effective_mass_kg);
        let chain = ChainResponse::new(&self.board_params()).ok();
        let temperature_k = self.noise.as_ref().map_or(0.0, |n| n.temperature_k);
        let plant = self.resonator_params();
        let fc = self.carrier_hz();
        let s_a = mass.map(|mass| {
            [plant.mode1, plant.mode2].map(|m| {
                gyroemu_resonator::thermomechanical_accel_psd(temperature_k, mass, m.f0_hz, m.q)
            })
        });
        let t = self.device.transduction_a_s_per_m;
        let tia = chain.as_ref().map(|c| c.tia(fc).norm_sqr());
        move |omega_rad_s: f64| {
            let Some(s_a) = s_a else {
                return [0.0; 2];
            };
            let Some(tia) = tia else {
                return [f64::NAN; 2];
            };
            // Mode j's unit force alone, then mode k's velocity phasor at the carrier.
            let unit = |j: usize| {
                let mut f = [Complex64::new(0.0, 0.0); 2];
                f[j] = Complex64::new(1.0, 0.0);
                gyroemu_resonator::continuous_steady_state(&plant, omega_rad_s, fc, f)
            };
            let x = [unit(0), unit(1)];
            [0, 1]
                .map(|k| (0..2).map(|j| s_a[j] * x[j][2 + k].norm_sqr()).sum::<f64>() * t * t * tia)
        }
    }

    /// The TIA voltage flicker's design (input-referred: `(e_n / tia_gain_ohm)^2 corner / f`
    /// up to fs/2), when `[noise]` has one.
    pub(crate) fn tia_flicker_design(&self) -> Option<gyroemu_core::flicker::FlickerDesign> {
        self.flicker_design(self.flicker_psds_at_1hz()[0], self.fs_hz())
    }

    /// Per mode, the variance (rad^2) the slow phase flicker leaves on one reading
    /// ([`SlowReading`], under the reading's window).
    /// Each drive's phase flicker turns its mode's response through the envelope low-pass
    /// `|H|^2 = 1 / (1 + (f / f_env)^2)`, `f_env = f0 / (2 Q)`; the carrier's turns the drives
    /// and the stage-1 reference alike, so only `1 - |H|^2` of it stays; the stage-1 low-pass
    /// weighs both. A Coriolis phase is the mean of that over the span (0 Hz), a rate table's
    /// amplitude the in-phase part of its fundamental. A rotating psi keeps neither to first
    /// order (the slow part turns both sidebands alike, into alpha), so it is not asked.
    /// Each drive's amplitude flicker moves a mode's phase only through the other drive's
    /// share of its response (a Coriolis phase is that of F2/F1 times the coupling: to first
    /// order, sin(2 theta)/2 times the two amplitudes' difference), so it is 0 at rest and
    /// uncoupled, and is counted likewise, with sidebands F_j / 2 in place of j F_j / 2.
    ///
    /// The response follows its drives' phase through the plant rotating at `omega_rad_s` (the
    /// reading's rate; a rate table's and the rotating runs' at rest): per mode k and drive j,
    /// with `X0_k` the mode's carrier phasor and `X_kj(+-f)` its response to drive j's
    /// sidebands `j F_j / 2` at `fc +- f`, the phase moves by `T_kj(f) = (X_kj(f) / X0_k -
    /// conj(X_kj(-f) / X0_k)) / j` per radian of drive j's phase. The drives' flicker is
    /// independent between them (`sum_j |T_kj|^2`); the carrier's turns both and the
    /// reference (`|1 - sum_j T_kj|^2`). On resonance and uncoupled this is the envelope's
    /// low-pass above; detuned, a drive's phase flicker at the offset from a mode lands on
    /// that mode and comes back amplified (a carrier 10 Hz above f0 at 3000 deg/s, one split
    /// mode 1.7 Hz from it, scattered 7.5 times the low-pass's figure).
    pub(crate) fn slow_flicker_variance(&self, reading: SlowReading) -> [f64; 2] {
        self.slow_flicker_variance_at(reading, 0.0)
    }

    /// [`Config::slow_flicker_variance`] of a reading at the constant rate `omega_rad_s`.
    pub(crate) fn slow_flicker_variance_at(
        &self,
        reading: SlowReading,
        omega_rad_s: f64,
    ) -> [f64; 2] {
        let fs_out = self.fs_out_hz();
        // As the board draws them: once per decimation block, up to fs_out / 2.
        let [_, amplitude_s1, drive_s1, carrier_s1] = self.flicker_psds_at_1hz();
        let (amplitude, drive, carrier) = (
            self.flicker_design(amplitude_s1, fs_out),
            self.flicker_design(drive_s1, fs_out),
            self.flicker_design(carrier_s1, fs_out),
        );
        if amplitude.is_none() && drive.is_none() && carrier.is_none() {
            return [0.0; 2];
        }
        let chain = ChainResponse::new(&self.board_params()).ok();
        let low = |f: f64| {
            chain
                .as_ref()
                .map_or(1.0, |c| (c.lowpass(f) / c.lowpass(0.0)).norm_sqr())
        };
        let f_top = 0.5 * fs_out;
        let fc = self.carrier_hz();
        let plant = self.resonator_params();
        let force = self.driven_device().coriolis_force();
        let respond = |f: f64, j: usize| {
            let mut u = [Complex64::new(0.0, 0.0); 2];
            u[j] = force[j];
            gyroemu_resonator::continuous_steady_state(&plant, omega_rad_s, fc + f, u)
        };
        let carrier_x = gyroemu_resonator::continuous_steady_state(&plant, omega_rad_s, fc, force);
        let j_unit = Complex64::new(0.0, 1.0);
        // Per mode, the phase transfer at f (Hz) of each drive's phase (`e` = j: sidebands
        // j F_j / 2) or of its relative amplitude (`e` = 1: sidebands F_j / 2).
        let follow = |f: f64, e: Complex64| -> [[Complex64; 2]; 2] {
            let up = [respond(f, 0), respond(f, 1)];
            let down = [respond(-f, 0), respond(-f, 1)];
            core::array::from_fn(|k| {
                core::array::from_fn(|j| {
                    // The responses to F_j, times e / 2.
                    let x0 = carrier_x[2 + k];
                    if x0.norm() == 0.0 {
                        // An undriven mode has no phase to turn (other rules name it).
                        return Complex64::new(0.0, 0.0);
                    }
                    let a = up[j][2 + k] * (0.5 * e) / x0;
                    let b = down[j][2 + k] * (0.5 * e) / x0;
                    (a - b.conj()) / j_unit
                })
            })
        };
        [0, 1].map(|k| {
            let density = |f: f64| {
                let t = follow(f, j_unit)[k];
                let d =
                    drive.as_ref().map_or(0.0, |d| d.psd(f)) * (t[0].norm_sqr() + t[1].norm_sqr());
                let c = carrier.as_ref().map_or(0.0, |d| d.psd(f))
                    * (Complex64::new(1.0, 0.0) - t[0] - t[1]).norm_sqr();
                let a = amplitude.as_ref().map_or(0.0, |d| {
                    let t = follow(f, Complex64::new(1.0, 0.0))[k];
                    d.psd(f) * (t[0].norm_sqr() + t[1].norm_sqr())
                });
                (d + c + a) * low(f)
            };
            reading.variance(&density, self.flicker_f_lo_hz(), f_top)
        })
    }

    /// The variance of the quadrature part of the amplitude flicker `d`'s tone at `freq_hz`
    /// over `span_s`, `<a sin(2 pi freq t)>`: a quarter of [`SlowReading::Tone`]'s in-phase
    /// fundamental `2 <a cos>`. What a rotating psi reads of each drive's amplitude at twice
    /// the modulation, and a rate table's amplitude at twice the table's.
    ///
    /// On a rotating psi, mode k's drive is `F_k (1 + a_k(t)) cos(Omega t)` (or `sin`): the
    /// part of `a_k` at 2 Omega carries each sideband onto the other (at +-Omega, through the
    /// same plant response), so the sidebands' phases move by `-+<a_k sin(2 Omega t)>` and
    /// psi, half their difference, by that. (The mean of `a_k` scales both sidebands alike,
    /// and the phase flicker turns them alike: neither moves psi to first order.)
    fn amplitude_quarter_tone(
        &self,
        d: &gyroemu_core::flicker::FlickerDesign,
        freq_hz: f64,
        span_s: f64,
        hann: bool,
    ) -> f64 {
        let tone = SlowReading::Tone {
            freq_hz,
            span_s,
            hann,
        };
        0.25 * tone.variance(
            &|f| d.psd(f),
            self.flicker_f_lo_hz(),
            0.5 * self.fs_out_hz(),
        )
    }

    /// `sum_k |L(k fs_out)|^2 / |L(0)|^2 g(k fs_out)` over the multiples of the output rate of
    /// both signs in the input band, k = 0 included (L the stage-1 low-pass), for each of the
    /// `N` values `g` gives: what a density `g` at the carrier offset `f` (demodulated to `f`)
    /// puts on the decimated output's DC. Outwards from DC, both signs at once, until the
    /// low-pass's weight is below 1e-8 of the sum (a first-order filter's 1/k^2 tail then adds
    /// under 1e-4 of it): a decimation of 2.4e6 had summed every term, 0.1 s per validation.
    pub(crate) fn fold_sums<const N: usize>(
        &self,
        chain: &ChainResponse,
        g: impl Fn(f64) -> [f64; N],
    ) -> [f64; N] {
        let fs_out = self.fs_out_hz();
        let k_max = (0.5 * self.fs_hz() / fs_out).floor() as u64;
        let dc = chain.lowpass(0.0).norm_sqr();
        let (mut sum, mut weight) = (g(0.0), 1.0);
        for k in 1..=k_max {
            let f = k as f64 * fs_out;
            let l = [f, -f].map(|f| chain.lowpass(f).norm_sqr() / dc);
            let (up, down) = (g(f), g(-f));
            for i in 0..N {
                sum[i] += l[0] * up[i] + l[1] * down[i];
            }
            weight += l[0] + l[1];
            if l[0] + l[1] < 1e-8 * weight {
                break;
            }
        }
        sum
    }

    /// What the decimation folds onto the decimated output's DC, against the low-pass's own
    /// DC ([`Config::fold_sums`]): `(sum_k |L(k fs_out)|^2 |H(fc + k fs_out)|^2 / |H(fc)|^2,
    /// sum_k |L(k fs_out)|^2) / |L(0)|^2` (H the TIA). Why: the demodulated noise at each
    /// multiple of fs_out lands on DC when the output is taken every M samples; a low-pass that
    /// leaves it (first order near the output Nyquist) made the read-out scatter 1.29 times the
    /// stated sigma.
    pub(crate) fn decimation_fold(&self, chain: &ChainResponse) -> (f64, f64) {
        let fc = self.carrier_hz();
        let tia_fc = chain.tia(fc).norm_sqr();
        let [tia, white] = self.fold_sums(chain, |f| [chain.tia(fc + f).norm_sqr() / tia_fc, 1.0]);
        (tia, white)
    }

    /// At each listed non-zero rate, the noise a reading's phase carries
    /// ([`phase_variance_rad2`] at the point's own averaging span, window and TIA output):
    /// in a Coriolis sweep its own phase's plus the zero-rate reference's it is read against;
    /// in a rotating one twice its own (the two sidebands, each of half the amplitude, whose
    /// half difference psi is); on a rate table twice its own (the fundamental's amplitude
    /// weighs two harmonics). `None` without `[noise]` or when the chain cannot be built. The
    /// Brownian part is the resonance's, correlated over a mode's Q / (pi f0): an average
    /// shorter than a few of those sees less of it than stated (the warning errs towards
    /// warning). Of flicker, the TIA's voltage flicker near the carrier is counted, and the
    /// drives' amplitude and phase flicker and the carrier's (`Config::slow_flicker_variance`)
    /// on a Coriolis or rate-table reading; on a rotating psi, which keeps neither phase
    /// flicker to first order, the amplitude flicker at twice the modulation
    /// (`Config::amplitude_quarter_tone`).
    pub fn noise_phase(&self) -> Option<Vec<NoisePhase>> {
        // With a [pll], the reading's noise and phase at the carrier the lock holds.
        if let Some(held) = self.expected_lock() {
            return held.noise_phase();
        }
        let rest = self.carrier_noise_but_brownian()?;
        let shape = self.shape();
        // The density at a reading's rate: the Brownian part through the plant rotating at
        // it (a rate table's the largest over its swing, a bound; a rotating run's plant does
        // not rotate), the rest as at rest. By rate, once: a sweep may list 1e5 rates.
        let brownian = self.brownian_density();
        let mut density_by_rate: std::collections::HashMap<u64, [f64; 2]> = Default::default();
        for &rate in self.experiment.rates_dps.iter().chain(&[0.0]) {
            density_by_rate.entry(rate.to_bits()).or_insert_with(|| {
                let b = match shape {
                    Shape::Coriolis => brownian(rate * DEG),
                    Shape::Rotating => brownian(0.0),
                    Shape::RateTable { .. } => (-16..=16)
                        .map(|i| brownian(rate * DEG * i as f64 / 16.0))
                        .fold([0.0f64; 2], |m, d| [m[0].max(d[0]), m[1].max(d[1])]),
                };
                [0, 1].map(|k| rest[k] + b[k])
            });
        }
        let density = |rate: f64| density_by_rate[&rate.to_bits()];
        // By rate: a sweep may list 1e5 rates, too many to search each time.
        let per_rate: std::collections::HashMap<u64, [LoHi; 2]> = self
            .tia_output_per_rate()?
            .into_iter()
            .map(|(r, a)| (r.to_bits(), a))
            .collect();
        let amps = |rate: f64| per_rate.get(&rate.to_bits());
        let enbw = match self.experiment.window {
            WindowKind::Boxcar => 1.0,
            WindowKind::Hann => 1.5,
        };
        let fs_out = self.fs_out_hz();
        let variance = |rate: f64, k: usize| {
            let a = amps(rate)?;
            let span_s = self.plan_point(rate).span_samples() / fs_out;
            Some(phase_variance_rad2(density(rate)[k], enbw, span_s, a[k].0))
        };
        // The zero-rate reference a Coriolis reading is taken against, once for every rate.
        let reference = [0, 1].map(|k| variance(0.0, k).unwrap_or(f64::NAN));
        let dev = self.driven_device();
        // The slow flicker sources' share of a reading over `span_s` (rad^2 per mode), under
        // the window's own weight (not its white-noise bandwidth: a Hann window takes 1.06 to
        // 1.12 times the boxcar's of the drive's 1/f phase, not 1.5).
        let hann = self.experiment.window == WindowKind::Hann;
        // The drives' amplitude flicker, for a rotating psi and a rate table's amplitude:
        // designed once (a sweep may list 1e5 rates).
        let amplitude_design = self.flicker_design(self.flicker_psds_at_1hz()[1], fs_out);
        let slow_of = |span_s: f64, rate: f64| match shape {
            // The plant rotates at a Coriolis reading's rate (a rate table's swings: at rest).
            Shape::Coriolis => {
                self.slow_flicker_variance_at(SlowReading::Mean { span_s, hann }, rate * DEG)
            }
            Shape::RateTable { freq_hz } => self.slow_flicker_variance(SlowReading::Tone {
                freq_hz,
                span_s,
                hann,
            }),
            Shape::Rotating => {
                let v = amplitude_design.as_ref().map_or(0.0, |d| {
                    self.amplitude_quarter_tone(d, 2.0 * rate.abs() / 360.0, span_s, hann)
                });
                [v, v]
            }
        };
        // Once per span (and per rate for a Coriolis reading, whose plant rotates at it, and
        // a rotating one, whose modulation sets what of the amplitude flicker it reads): a
        // sweep may list 1e5 rates of one span, and each is a quadrature of hundreds of
        // points (the zero-rate reference's span among them). Only with flicker.
        let span = |rate: f64| self.plan_point(rate).span_samples() / fs_out;
        let flicker_on = self.noise.as_ref().is_some_and(|n| {
            n.drive_phase_flicker_rad_per_rthz > 0.0
                || n.carrier_phase_flicker_rad_per_rthz > 0.0
                || n.drive_amplitude_flicker_per_rthz > 0.0
        });
        let key = |rate: f64| {
            let r = if matches!(shape, Shape::RateTable { .. }) {
                0.0
            } else {
                rate
            };
            (span(rate).to_bits(), r.to_bits())
        };
        let mut slow_by_key: std::collections::HashMap<(u64, u64), [f64; 2]> = Default::default();
        for &rate in self.experiment.rates_dps.iter().chain(&[0.0]) {
            slow_by_key.entry(key(rate)).or_insert_with(|| {
                if flicker_on {
                    slow_of(span(rate), rate)
                } else {
                    [0.0; 2]
                }
            });
        }
        let slow = |rate: f64| slow_by_key[&key(rate)];
        // A rate table's reading: how its harmonics' noise reaches the amplitude read
        // ([`crate::noise_table`]), per span the harmonics' noise gains (the TIA's gain across
        // them included), per rate and mode the envelope's weights.
        let chain = ChainResponse::new(&self.board_params()).ok();
        let (n, fc) = (self.table_harmonics(), self.carrier_hz());
        // The harmonics' gains depend on the span alone: once per span, as the read-out
        // takes them (the TIA's gain across the harmonics included), with their peak.
        type Gains = (Vec<f64>, (usize, f64));
        // Per mode the variance's factors over one harmonic's own (first and second order),
        // and the peak harmonic's gain.
        type Reading = ([(f64, f64); 2], Option<(usize, f64)>);
        let gains_by_span: std::cell::RefCell<std::collections::HashMap<u64, Gains>> =
            Default::default();
        let table_gain = |rate: f64| -> Reading {
            let (Shape::RateTable { freq_hz }, Some(chain)) = (shape, chain.as_ref()) else {
                return ([(2.0, 0.0); 2], None);
            };
            let tia0 = chain.tia(fc);
            let (gains, peak) = gains_by_span
                .borrow_mut()
                .entry(span(rate).to_bits())
                .or_insert_with(|| {
                    let raw = self.table_harmonic_noise_gains(chain, freq_hz, n, span(rate), hann);
                    let mut peak = (0, 0.0f64);
                    for (i, &g) in raw.iter().enumerate() {
                        if g > peak.1 {
                            peak = (i.abs_diff(n), g);
                        }
                    }
                    let read = raw
                        .iter()
                        .enumerate()
                        .map(|(i, g)| {
                            let f = (i as f64 - n as f64) * freq_hz;
                            g * (tia0 / chain.tia(fc + f)).norm_sqr()
                        })
                        .collect();
                    (read, peak)
                })
                .clone();
            const M: usize = 24;
            let env = dev.rate_table_envelopes(rate * DEG, freq_hz, M);
            let g = |f: f64| chain.dac_hold(f) * self.device.transduction_a_s_per_m;
            let factors = [0, 1].map(|k| {
                let Some(lo) = amps(rate).map(|a| a[k].0) else {
                    return (f64::NAN, f64::NAN);
                };
                // The envelope the read-out forms, in volts at the ADC at the carrier's TIA
                // gain (it divides out each harmonic's own).
                let v: Vec<Complex64> = env[k]
                    .iter()
                    .enumerate()
                    .map(|(i, &x)| x * g(fc + (i as f64 - M as f64) * freq_hz) * tia0)
                    .collect();
                crate::noise_table::table_reading_gains(&v, lo, &gains)
            });
            (factors, Some(peak))
        };
        let reference_flicker = slow(0.0);
        // A rate table's amplitude scales with F2/F1 as a Coriolis phase does, so the drives'
        // amplitude flicker moves it by `d ln A / d ln F2` times their difference, to first
        // order (at rest, where `slow` weighs the flicker, that transfer is 0). The reading
        // `2 <A (1 + s a(t)) cos^2(w_t t)>` takes the flicker's mean and a quarter of its tone
        // at 2 f_t; the derivative by a step of F2 (the device, once; its solves per rate).
        let table_amplitude = match (shape, amplitude_design.as_ref()) {
            (Shape::RateTable { freq_hz }, Some(d)) => {
                let mut c = self.clone();
                c.drive.f2 = Some(self.f2() * (1.0 + TABLE_F2_STEP));
                Some((d, freq_hz, c.driven_device()))
            }
            _ => None,
        };
        let mean_and_tone_by_span: std::cell::RefCell<std::collections::HashMap<u64, f64>> =
            Default::default();
        let table_amplitude_flicker = |rate: f64, theory: [f64; 2]| -> [f64; 2] {
            let Some((d, freq_hz, stepped)) = table_amplitude.as_ref() else {
                return [0.0; 2];
            };
            let span_s = span(rate);
            let v = *mean_and_tone_by_span
                .borrow_mut()
                .entry(span_s.to_bits())
                .or_insert_with(|| {
                    let psd = |f: f64| d.psd(f);
                    let (f_lo, f_top) = (self.flicker_f_lo_hz(), 0.5 * fs_out);
                    SlowReading::Mean { span_s, hann }.variance(&psd, f_lo, f_top)
                        + self.amplitude_quarter_tone(d, 2.0 * *freq_hz, span_s, hann)
                });
            let up = stepped.rate_table_response(rate * DEG, *freq_hz).0;
            [0, 1].map(|k| {
                let s = (up[k] / theory[k]).abs().ln() / TABLE_F2_STEP.ln_1p();
                // Two drives, each its own flicker: s for F2, -s for F1.
                let v_k = 2.0 * theory[k] * theory[k] * s * s * v;
                if v_k.is_finite() {
                    v_k
                } else {
                    0.0
                }
            })
        };
        let points = self
            .experiment
            .rates_dps
            .iter()
            .filter(|&&r| r != 0.0)
            .map(|&rate| {
                let omega = rate * DEG;
                let theory_rad = match shape {
                    Shape::Coriolis => dev.coriolis_phase_rad(omega),
                    Shape::RateTable { freq_hz } => dev.rate_table_response(omega, freq_hz).0,
                    Shape::Rotating => dev.rotating_psi_rad(omega),
                };
                let table_amp = table_amplitude_flicker(rate, theory_rad);
                let flicker = [0, 1].map(|k| slow(rate)[k] + table_amp[k]);
                let (gain, table_noise_gain_peak) = match shape {
                    Shape::RateTable { .. } => table_gain(rate),
                    _ => ([(2.0, 0.0); 2], None),
                };
                let sigma_rad = [0, 1].map(|k| {
                    let own = variance(rate, k).unwrap_or(f64::NAN);
                    match shape {
                        Shape::Coriolis => {
                            (own + reference[k] + flicker[k] + reference_flicker[k]).sqrt()
                        }
                        _ => (gain[k].0 * own + gain[k].1 * own * own + flicker[k]).sqrt(),
                    }
                });
                let amplitude_v = [0, 1].map(|k| amps(rate).map_or(f64::NAN, |a| a[k].0));
                NoisePhase {
                    rate_dps: rate,
                    sigma_rad,
                    theory_rad,
                    amplitude_v,
                    density_v2_per_hz: density(rate),
                    table_noise_gain_peak,
                }
            })
            .collect();
        Some(points)
    }

    /// Warns, per mode, when the white noise scatters the reading at some listed rate
    /// ([`Config::noise_phase`]) by more than [`WARN_NOISE_PHASE_FRACTION`] of the phase
    /// measured there (the worst rate is named): those readings are the noise's more than
    /// the device's.
    pub(crate) fn validate_noise_phase(&self, warnings: &mut Vec<String>) {
        let Some(points) = self.noise_phase() else {
            return;
        };
        self.validate_table_noise_skirt(&points, warnings);
        for k in 0..2 {
            // The worst ratio; a NaN (a dead signal, which other rules name) says nothing.
            let worst = points
                .iter()
                .map(|p| (p.sigma_rad[k] / p.theory_rad[k].abs(), p))
                .filter(|(ratio, _)| !ratio.is_nan())
                .max_by(|a, b| a.0.total_cmp(&b.0));
            let Some((ratio, p)) = worst else {
                continue;
            };
            if ratio <= WARN_NOISE_PHASE_FRACTION {
                continue;
            }
            let (sigma, amplitude, density) =
                (p.sigma_rad[k], p.amplitude_v[k], p.density_v2_per_hz[k]);
            // The averaged noise against the signal, per reading (sqrt(2) of one phase's).
            let noise_to_signal = sigma / core::f64::consts::SQRT_2;
            let scatter = if noise_to_signal >= 1.0 {
                format!(
                    "buries the signal (the averaged noise is about {noise_to_signal:.1} times its amplitude): each phase reading there is noise"
                )
            } else {
                format!(
                    "scatters its phase reading by about {:.3e} deg (1 sigma), more than {WARN_NOISE_PHASE_FRACTION} of the {:.3e} deg measured there: the readings are the noise's more than the device's",
                    sigma / DEG,
                    p.theory_rad[k].abs() / DEG
                )
            };
            // The slow flicker is in the sigma, not in the carrier's density (of a rotating psi,
            // only the amplitude flicker at twice the modulation).
            let slow = self.noise.as_ref().and_then(|n| {
                let amplitude = n.drive_amplitude_flicker_per_rthz > 0.0;
                let phase = n.drive_phase_flicker_rad_per_rthz > 0.0
                    || n.carrier_phase_flicker_rad_per_rthz > 0.0;
                match self.shape() {
                    Shape::Rotating => amplitude.then_some(
                        ", and the drives' amplitude flicker at twice the modulation, which the reading sees",
                    ),
                    _ => (amplitude || phase)
                        .then_some(", and the drives' and the carrier's flicker the reading sees"),
                }
            });
            warnings.push(format!(
                "the noise at the carrier (about {:.3e} V/sqrt(Hz) at the ADC input, the white sources and the TIA's voltage flicker together, with the noise the decimation folds onto the output){}, averaged over the point's span, against the TIA output of mode {} at {} deg/s (about {amplitude:.3e} V) {scatter}; average longer (experiment.average_s) or lower the noise",
                density.sqrt(),
                slow.unwrap_or(""),
                k + 1,
                p.rate_dps,
            ));
        }
    }
}

impl Config {
    /// A noisy rate table whose read-out divides a harmonic by a low-pass gain so small that
    /// the noise the window's sidelobes and the decimation bring to it comes back more than
    /// [`WARN_TABLE_NOISE_GAIN`] times the DC reading's in power. The stated scatter
    /// ([`Config::noise_phase`]) counts it, to second order, as independent between the
    /// harmonics; the noise leaked from near DC is not (each harmonic's window sidelobe takes
    /// the same noise), and readings can scatter several times the figure: a 200 deg/s point
    /// read with 15 harmonics of a 9 Hz table behind a 10 Hz low-pass, 3.1 times.
    fn validate_table_noise_skirt(&self, points: &[NoisePhase], warnings: &mut Vec<String>) {
        let Shape::RateTable { freq_hz } = self.shape() else {
            return;
        };
        let Ok(chain) = ChainResponse::new(&self.board_params()) else {
            return;
        };
        // The largest gain of a read harmonic over the readings, with its harmonic.
        let mut worst = (0.0f64, 0usize);
        for &(h, g) in points
            .iter()
            .filter_map(|p| p.table_noise_gain_peak.as_ref())
        {
            if g > worst.0 {
                worst = (g, h);
            }
        }
        let (gain, h) = worst;
        if gain <= WARN_TABLE_NOISE_GAIN {
            return;
        }
        let f = h as f64 * freq_hz;
        warnings.push(format!(
            "experiment.table_freq_hz = {freq_hz}: the read-out divides the table's {h}th harmonic ({f} Hz) by the low-pass's gain there ({:.3e} of its DC gain), and the noise the averaging window's sidelobes and the decimation bring to it comes back {gain:.3e} times the DC reading's in power; the stated scatter counts it as independent between the harmonics, which noise leaked from near DC is not, so the readings can scatter several times the figure stated (a 200 deg/s point read with 15 harmonics of a 9 Hz table behind a 10 Hz low-pass: 3.1 times); raise board.lpf_cutoff_hz above {f} Hz, or sweep rates that need fewer harmonics",
            chain.lowpass(f).norm() / chain.lowpass(0.0).norm()
        ));
    }
}

/// The relative step of F2 by which a rate table's amplitude is differentiated.
const TABLE_F2_STEP: f64 = 1e-4;

/// A rate table's read harmonic whose noise power comes back above this many times the DC
/// reading's is warned ([`Config::validate_table_noise_skirt`]).
pub const WARN_TABLE_NOISE_GAIN: f64 = 100.0;

/// How a reading weighs a slow phase fluctuation over frequency: `K(u)` at `u = f T` is the
/// boxcar's `sinc^2(pi u)` or, with `hann`, the mean-normalised Hann window's
/// `(sinc(u) + sinc(u - 1) / 2 + sinc(u + 1) / 2)^2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum SlowReading {
    /// The mean over `span_s` (a Coriolis phase): weight `K(f T)`.
    Mean { span_s: f64, hann: bool },
    /// The in-phase part of the fundamental at `freq_hz` over `span_s` (a rate table's
    /// amplitude): weight `K((f - f_t) T) + K((f + f_t) T)`.
    Tone {
        freq_hz: f64,
        span_s: f64,
        hann: bool,
    },
}

impl SlowReading {
    /// `int_0^f_top density(f) weight(f) df`: on a grid of 64 points a decade in ln f from
    /// f_lo / 1000 (the flat part below it taken as a rectangle) for a mean; on a linear grid
    /// of 4001 points over f_t +- 40 / T for a tone (its weight's tails beyond hold under 1 %).
    fn variance(self, density: &dyn Fn(f64) -> f64, f_lo: f64, f_top: f64) -> f64 {
        match self {
            SlowReading::Mean { span_s, hann } => {
                let a = (1e-3 * f_lo).min(0.01 / span_s);
                if !(a > 0.0 && f_top > a) {
                    return 0.0;
                }
                integrate_over_decades(density(a) * a, a, f_top, |f| {
                    density(f) * window_weight(f * span_s, hann)
                })
            }
            SlowReading::Tone {
                freq_hz,
                span_s,
                hann,
            } => {
                let half = 40.0 / span_s;
                let (lo, hi) = ((freq_hz - half).max(0.0), (freq_hz + half).min(f_top));
                if hi <= lo || hi.is_nan() || lo.is_nan() {
                    return 0.0;
                }
                let n = 4000;
                let df = (hi - lo) / n as f64;
                let g = |f: f64| {
                    density(f)
                        * (window_weight((f - freq_hz) * span_s, hann)
                            + window_weight((f + freq_hz) * span_s, hann))
                };
                (0..=n)
                    .map(|i| {
                        let w = if i == 0 || i == n { 0.5 } else { 1.0 };
                        w * g(lo + i as f64 * df)
                    })
                    .sum::<f64>()
                    * df
            }
        }
    }
}
