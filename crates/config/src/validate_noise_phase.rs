//! How far the white noise sources scatter a phase reading, against the smallest phase the
//! sweep measures: a run whose readings the noise dominates is told so before it runs, so its
//! numbers never look clean.

use crate::config::{Config, WindowKind};
use crate::plan::DEG;
use gyroemu_board::{ChainResponse, Shape};

/// The noise is said to dominate when a reading's standard deviation passes this fraction of
/// the smallest phase the sweep measures.
pub const NOISE_PHASE_WARN_FRACTION: f64 = 0.1;

/// Standard deviation of a phase reading, rad, for white noise of one-sided density
/// `density_v2_per_hz` (V^2/Hz) at the ADC input near the carrier, a tone of amplitude
/// `amplitude_v` there, averaged over `average_s` with a window of equivalent noise bandwidth
/// `enbw` (1 boxcar, 1.5 Hann). The averaged phasor `mean(2 y e^{-j w t})` of white noise has
/// each component of variance `density enbw / average_s`; its part across the signal moves the
/// phase by that over the amplitude. A reading is the difference of two such phases (a point
/// and the zero-rate reference; the two sidebands' halves in a rotating run): sqrt(2) of it.
pub fn reading_sigma_rad(
    density_v2_per_hz: f64,
    enbw: f64,
    average_s: f64,
    amplitude_v: f64,
) -> f64 {
    core::f64::consts::SQRT_2 * (density_v2_per_hz * enbw / average_s).sqrt() / amplitude_v
}

impl Config {
    /// Per mode, the one-sided density at the ADC input near the carrier (V^2/Hz) of the
    /// white sources: the TIA's input noise (current and e_n / tia_gain_ohm), the Brownian
    /// force through the mode's velocity response and transduction (uncoupled modes), both
    /// through the TIA at the carrier, and an ADC's rounding (step^2/12 a sample, white where
    /// the noise dithers it). `None` without `[noise]`.
    pub(crate) fn carrier_noise_density(&self) -> Option<[f64; 2]> {
        let n = self.noise.as_ref()?;
        let b = &self.board;
        let chain = ChainResponse::new(&self.board_params()).ok()?;
        let fc = self.carrier_hz();
        let tia = chain.tia(fc).norm_sqr();
        let i_n = gyroemu_tia::input_referred_noise_a_per_rthz(
            n.tia_current_noise_a_per_rthz,
            n.tia_voltage_noise_v_per_rthz,
            b.tia_gain_ohm,
        );
        let adc = b.adc_bits.map_or(0.0, |bits| {
            let step = b.adc_full_scale_v / (1u64 << (bits - 1)) as f64;
            step * step / (6.0 * self.fs_hz())
        });
        let plant = self.resonator_params();
        let w = core::f64::consts::TAU * fc;
        Some([plant.mode1, plant.mode2].map(|m| {
            let brownian = n.effective_mass_kg.map_or(0.0, |mass| {
                let s_a = gyroemu_resonator::thermomechanical_accel_psd(
                    n.temperature_k,
                    mass,
                    m.f0_hz,
                    m.q,
                );
                let w0 = core::f64::consts::TAU * m.f0_hz;
                let h_v2 = w * w / ((w0 * w0 - w * w).powi(2) + (w * w0 / m.q).powi(2));
                let t = self.device.transduction_a_s_per_m;
                s_a * h_v2 * t * t
            });
            (i_n * i_n + brownian) * tia + adc
        }))
    }

    /// Per mode, the standard deviation of a phase reading the white sources give at the
    /// sweep's smallest signal ([`reading_sigma_rad`] at its averaging time and window), rad,
    /// with that signal's amplitude (V at the ADC input) and rate (deg/s). `None` without
    /// `[noise]` or when the chain cannot be built. The Brownian part is the resonance's,
    /// correlated over a mode's Q / (pi f0): an average shorter than a few of those sees less
    /// of it than stated (the warning errs towards warning). Flicker is left out.
    pub fn noise_phase_sigma_rad(&self) -> Option<[(f64, f64, f64); 2]> {
        let density = self.carrier_noise_density()?;
        let span = self.tia_output_span()?;
        let enbw = match self.experiment.window {
            WindowKind::Boxcar => 1.0,
            WindowKind::Hann => 1.5,
        };
        let t = self.experiment.average_s;
        Some([0, 1].map(|k| {
            let s = span[k];
            (
                reading_sigma_rad(density[k], enbw, t, s.min),
                s.min,
                s.min_at,
            )
        }))
    }

    /// Warns, per mode, when the white noise scatters a reading
    /// ([`Config::noise_phase_sigma_rad`]) by more than [`NOISE_PHASE_WARN_FRACTION`] of the
    /// smallest phase the sweep measures at a listed non-zero rate: those readings are the
    /// noise's more than the device's.
    pub(crate) fn validate_noise_phase(&self, warnings: &mut Vec<String>) {
        let (Some(density), Some(sigmas)) =
            (self.carrier_noise_density(), self.noise_phase_sigma_rad())
        else {
            return;
        };
        let dev = self.driven_device();
        let smallest = |k: usize| {
            self.experiment
                .rates_dps
                .iter()
                .filter(|&&r| r != 0.0)
                .map(|&r| {
                    let omega = r * DEG;
                    let rad = match self.shape() {
                        Shape::Coriolis => dev.coriolis_phase_rad(omega)[k],
                        Shape::RateTable { freq_hz } => {
                            dev.rate_table_response(omega, freq_hz).0[k]
                        }
                        Shape::Rotating => dev.rotating_psi_rad(omega)[k],
                    };
                    (rad.abs(), r)
                })
                .filter(|(rad, _)| rad.is_finite())
                .min_by(|a, b| a.0.total_cmp(&b.0))
        };
        for (k, &(sigma, amplitude, amplitude_at)) in sigmas.iter().enumerate() {
            let Some((phase, at)) = smallest(k) else {
                continue;
            };
            // A NaN (a dead signal, which other rules name) says nothing here.
            if sigma.is_nan() || sigma <= NOISE_PHASE_WARN_FRACTION * phase {
                continue;
            }
            // Past a radian the averaged noise outgrows the signal: no phase is left to read.
            let scatter = if sigma >= 1.0 {
                format!(
                    "buries the signal (the averaged noise is about {:.1} times its amplitude): each phase reading is noise",
                    sigma / core::f64::consts::SQRT_2
                )
            } else {
                format!(
                    "scatters each phase reading by about {:.3e} deg (1 sigma), more than {NOISE_PHASE_WARN_FRACTION} of the smallest phase the sweep measures ({:.3e} deg at {at} deg/s): its readings are the noise's more than the device's",
                    sigma / DEG,
                    phase / DEG
                )
            };
            warnings.push(format!(
                "the noise at the carrier (about {:.3e} V/sqrt(Hz) at the ADC input, the white sources together), averaged over experiment.average_s = {} s, against the TIA output of mode {} (about {amplitude:.3e} V at {amplitude_at} deg/s) {scatter}; average longer or lower the noise",
                density[k].sqrt(),
                self.experiment.average_s,
                k + 1,
            ));
        }
    }
}
