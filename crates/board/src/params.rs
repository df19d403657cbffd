//! Everything that defines a board, as plain validated values (no file format here: the config
//! crate maps its TOML onto these).

use gyroemu_am::{Dac, Quantizer};
use gyroemu_core::error::{finite, non_negative, positive};
use gyroemu_core::{ParamError, ParamResult, Sample};
use gyroemu_lpf::{LowPass, LowPassDesign};
use gyroemu_resonator::ResonatorParams;
use gyroemu_tia::{Tia, TiaParams};

/// The stage name of the board's own parameter errors.
pub const STAGE: &str = "board";

/// What the board excites and how it reads it out: the experiment's shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// Drives 90 degrees apart, device rotating at a constant rate per operating point
    /// (Figs. 4 and 8).
    Coriolis,
    /// Coriolis drives, device on a table whose rate is `amplitude sin(2 pi freq_hz t)`, the
    /// amplitude per operating point (the mechanical bandwidth).
    RateTable {
        /// Table frequency, Hz.
        freq_hz: f64,
    },
    /// Device at rest, drive direction rotating at Omega per operating point (Figs. 5 and 9).
    Rotating,
}

impl Shape {
    /// True for the rotating excitation (the one with a second demodulation stage).
    pub fn is_rotating(self) -> bool {
        self == Shape::Rotating
    }

    /// True for a rate table (its lanes' table oscillators shared or one each).
    pub fn is_rate_table(self) -> bool {
        matches!(self, Shape::RateTable { .. })
    }
}

/// A converter's quantiser: resolution and full scale (input range -fs .. +fs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Converter {
    /// Resolution, bits.
    pub bits: u32,
    /// Full scale, in the unit of the converted signal.
    pub full_scale: f64,
}

/// The seeded noise sources (densities; the board turns them into per-sample deviations).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseParams {
    /// Seed of every stream; each operating point draws the stream of its own index.
    pub seed: u64,
    /// Resonator temperature, K.
    pub temperature_k: f64,
    /// Effective modal mass, kg (absent: no thermomechanical force noise).
    pub effective_mass_kg: Option<f64>,
    /// TIA input current noise density, A/sqrt(Hz).
    pub tia_current_noise_a_per_rthz: f64,
    /// TIA output voltage noise density, V/sqrt(Hz).
    pub tia_voltage_noise_v_per_rthz: f64,
    /// Corner of the TIA voltage noise's flicker: its density is `e_n^2 (1 + corner / f)`,
    /// Hz (0: white only).
    pub tia_voltage_flicker_corner_hz: f64,
    /// Flicker of each drive's relative amplitude, density at 1 Hz, 1/sqrt(Hz) (0: none).
    pub drive_amplitude_flicker_per_rthz: f64,
    /// Flicker of each drive's phase, density at 1 Hz, rad/sqrt(Hz) (0: none).
    pub drive_phase_flicker_rad_per_rthz: f64,
    /// Flicker of the carrier's phase (drives and demodulation alike), density at 1 Hz,
    /// rad/sqrt(Hz) (0: none).
    pub carrier_phase_flicker_rad_per_rthz: f64,
    /// Low corner of every flicker source, Hz: below it their densities flatten.
    pub flicker_f_lo_hz: f64,
}

impl NoiseParams {
    /// The four flicker sources' levels, each with its config key (0: the source is off).
    pub fn flicker_levels(&self) -> [(&'static str, f64); 4] {
        [
            (
                "noise.tia_voltage_flicker_corner_hz",
                self.tia_voltage_flicker_corner_hz,
            ),
            (
                "noise.drive_amplitude_flicker_per_rthz",
                self.drive_amplitude_flicker_per_rthz,
            ),
            (
                "noise.drive_phase_flicker_rad_per_rthz",
                self.drive_phase_flicker_rad_per_rthz,
            ),
            (
                "noise.carrier_phase_flicker_rad_per_rthz",
                self.carrier_phase_flicker_rad_per_rthz,
            ),
        ]
    }

    /// The four flicker sources' densities at 1 Hz as the board designs them, with the keys
    /// of [`NoiseParams::flicker_levels`]: the TIA's input-referred (A^2/Hz) through a gain of
    /// `tia_gain_ohm`, the others the squares of their levels. Validation reads them so a
    /// level whose density overflows is refused with its key before the board is built.
    pub fn flicker_psds_at_1hz(&self, tia_gain_ohm: f64) -> [(&'static str, f64); 4] {
        let i_v = gyroemu_tia::input_referred_noise_a_per_rthz(
            0.0,
            self.tia_voltage_noise_v_per_rthz,
            tia_gain_ohm,
        );
        let [(tia, corner), slow @ ..] = self.flicker_levels();
        let [a, b, c] = slow.map(|(key, x)| (key, x * x));
        [(tia, i_v * i_v * corner), a, b, c]
    }

    /// Whether any flicker source is on.
    pub fn has_flicker(&self) -> bool {
        self.flicker_levels().iter().any(|&(_, v)| v > 0.0)
    }
}

/// The whole board: plant, drive, converters, front end, read-out and the experiment shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoardParams {
    /// The gyroscope and the emulation sample rate (`plant.fs_hz`).
    pub plant: ResonatorParams,
    /// Carrier frequency of the drive and of the stage-1 demodulation, Hz.
    pub carrier_hz: f64,
    /// Drive amplitudes F1, F2 (force per unit mass, m/s^2).
    pub drive: [f64; 2],
    /// Error of the 90-degree phase shifter, degrees (0: exact quadrature).
    pub phase_shifter_error_deg: f64,
    /// The drive DAC's quantiser (absent: ideal; the hold is always there).
    pub dac: Option<Converter>,
    /// The transimpedance front end.
    pub tia: TiaParams,
    /// The ADC after each TIA (absent: ideal).
    pub adc: Option<Converter>,
    /// The stage-1 low-pass.
    pub lowpass: LowPassDesign,
    /// Decimation after the stage-1 low-pass.
    pub decimation: usize,
    /// Noise sources (absent: a noiseless board).
    pub noise: Option<NoiseParams>,
    /// The experiment.
    pub shape: Shape,
    /// Rate-table runs: the table harmonics `-N ..= N` demodulated per mode (1 to
    /// [`gyroemu_mixer::MAX_TABLE_HARMONIC`]; enough that the envelope has nothing beyond).
    /// Not used by the other shapes.
    pub table_harmonics: usize,
}

impl BoardParams {
    /// Sample rate, Hz.
    pub fn fs_hz(&self) -> f64 {
        self.plant.fs_hz
    }

    /// Output rate after decimation, Hz.
    pub fn fs_out_hz(&self) -> f64 {
        self.plant.fs_hz / self.decimation as f64
    }

    /// The board runs its imperfect sample loop: a noise source, a converter or a TIA rail is
    /// on (the loop that also counts clipped and zero samples).
    pub fn imperfect(&self) -> bool {
        self.noise.is_some()
            || self.adc.is_some()
            || self.dac.is_some()
            || self.tia.rail_v.is_some()
    }

    /// Checks every parameter by building each stage once (so the rules are the stages' own),
    /// plus the board's: decimation >= 1, a finite shifter error within (-90, 90) degrees, a
    /// table frequency > 0, finite noise densities >= 0.
    pub fn validate(&self) -> ParamResult<()> {
        self.plant.validate()?;
        positive(STAGE, "carrier_hz", self.carrier_hz)?;
        for (k, f) in self.drive.iter().enumerate() {
            finite(STAGE, ["drive.f1", "drive.f2"][k], *f)?;
        }
        let e = self.phase_shifter_error_deg;
        if !(e.is_finite() && e.abs() < 90.0) {
            return Err(ParamError::new(
                STAGE,
                "phase_shifter_error_deg",
                e,
                "must be finite and within (-90, 90)",
            ));
        }
        if self.decimation == 0 {
            return Err(ParamError::new(STAGE, "decimation", 0, "must be >= 1"));
        }
        if let Shape::RateTable { freq_hz } = self.shape {
            positive(STAGE, "table_freq_hz", freq_hz)?;
            let n = self.table_harmonics;
            if !(1..=gyroemu_mixer::MAX_TABLE_HARMONIC).contains(&n) {
                return Err(ParamError::new(
                    STAGE,
                    "table_harmonics",
                    n,
                    format!("must be 1 to {}", gyroemu_mixer::MAX_TABLE_HARMONIC),
                ));
            }
        }
        if let Some(n) = &self.noise {
            positive(STAGE, "noise.temperature_k", n.temperature_k)?;
            if let Some(m) = n.effective_mass_kg {
                positive(STAGE, "noise.effective_mass_kg", m)?;
            }
            non_negative(
                STAGE,
                "noise.tia_current_noise_a_per_rthz",
                n.tia_current_noise_a_per_rthz,
            )?;
            non_negative(
                STAGE,
                "noise.tia_voltage_noise_v_per_rthz",
                n.tia_voltage_noise_v_per_rthz,
            )?;
            for (key, v) in n.flicker_levels() {
                non_negative(STAGE, key, v)?;
            }
            if n.has_flicker() {
                positive(STAGE, "noise.flicker_f_lo_hz", n.flicker_f_lo_hz)?;
            }
        }
        build_dac::<f64>(self)?;
        build_tia::<f64>(self)?;
        build_adc::<f64>(self)?;
        build_lowpass::<f64>(self)?;
        Ok(())
    }
}

/// The drive DAC the board runs (one per mode, alike).
pub(crate) fn build_dac<S: Sample>(p: &BoardParams) -> ParamResult<Dac<S>> {
    Dac::new(p.fs_hz(), p.dac.map(|c| (c.bits, c.full_scale)))
}

/// The TIA the board runs (one per mode, alike).
pub(crate) fn build_tia<S: Sample>(p: &BoardParams) -> ParamResult<Tia<S>> {
    Tia::new(&p.tia)
}

/// The ADC quantiser after each TIA, if any.
pub(crate) fn build_adc<S: Sample>(p: &BoardParams) -> ParamResult<Option<Quantizer<S>>> {
    p.adc
        .map(|c| Quantizer::new(c.bits, c.full_scale))
        .transpose()
}

/// The stage-1 low-pass the board runs on I and Q of both modes.
pub(crate) fn build_lowpass<S: Sample>(p: &BoardParams) -> ParamResult<LowPass<S>> {
    LowPass::new(p.lowpass, p.fs_hz())
}
