//! The experiment description read from TOML: units in every key, unknown keys rejected,
//! documented defaults.

use serde::{Deserialize, Serialize};

/// A whole experiment: device, drive, board and sweep (plus optional signal dumps).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    pub device: DeviceConfig,
    pub drive: DriveConfig,
    /// The readout board (absent: every key at its default).
    #[serde(default)]
    pub board: BoardConfig,
    pub experiment: ExperimentConfig,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dump: Option<DumpConfig>,
    /// Noise sources (absent: a noiseless board).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<NoiseConfig>,
    /// The analyses of `gyroemu selfcal` (absent: only the two sweeps and their comparison).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub selfcal: Option<SelfcalConfig>,
    /// The stepped-sine frequency response of `gyroemu sweep` (absent: every key at its
    /// default, derived from the device; read it with [`Config::sweep_resolved`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sweep: Option<SweepConfig>,
    /// A carrier PLL that locks the drive onto the resonance before the sweep (absent: the
    /// carrier is `drive.carrier_hz`, open loop).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pll: Option<PllConfig>,
    /// The production lot of `gyroemu montecarlo` (absent: that command refuses the config).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub montecarlo: Option<MonteCarloConfig>,
}

/// The carrier PLL (`crates/pll`): at zero rate the board drives the device and the PLL steers
/// the carrier onto the resonance of one mode from its demodulated output; the sweep then runs
/// with the carrier held where the lock ended.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PllConfig {
    /// The loop's natural frequency, Hz; default the geometric mean of the slowest loop a PI
    /// on the frequency can make (2 zeta w_n tau >= 1) and the fastest the low-pass allows
    /// (read it with [`Config::pll_natural_hz`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub natural_hz: Option<f64>,
    /// The loop's damping ratio.
    #[serde(default = "default_damping")]
    pub damping: f64,
    /// Length of the lock run, s; default 16 mechanical time constants plus 10 loop time
    /// constants [`Config::pll_time_constant_s`] (read it with [`Config::pll_lock_s`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lock_s: Option<f64>,
    /// The mode whose output the PLL locks on: 1 or 2.
    #[serde(default = "default_pll_mode")]
    pub mode: usize,
}

/// The resonator (THEORY.md section 2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceConfig {
    /// Resonance of mode 1 (and of mode 2 unless offset), Hz.
    pub f0_hz: f64,
    /// Quality factor of mode 1 (and of mode 2 unless `q_mode2` is set).
    pub q: f64,
    /// Angular gain lambda.
    pub angular_gain: f64,
    /// Mode 2 resonance minus mode 1 resonance, Hz (frequency mismatch).
    #[serde(default)]
    pub mode2_f0_offset_hz: f64,
    /// Quality factor of mode 2 (Q mismatch); defaults to `q`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub q_mode2: Option<f64>,
    /// Quadrature (stiffness) coupling k12, (rad/s)^2.
    #[serde(default)]
    pub quadrature_coupling_rad2_s2: f64,
    /// Motional current per unit velocity, A/(m/s).
    #[serde(default = "default_transduction")]
    pub transduction_a_s_per_m: f64,
}

/// Drive amplitudes (force per unit mass, m/s^2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveConfig {
    /// Mode-1 drive amplitude F1 (F0 on mode 1 in the rotating run).
    pub f1: f64,
    /// Mode-2 drive amplitude F2, 90 degrees after mode 1 (F0 on mode 2 in the rotating run);
    /// default F1 (filled in by `parse_config`, read it with [`Config::f2`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f2: Option<f64>,
    /// Frequency of the drive's carrier (and of the stage-1 demodulation), Hz; default the
    /// mode-1 resonance `device.f0_hz` (read it with [`Config::carrier_hz`]). Set it apart
    /// from f0 for a detuned open-loop drive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub carrier_hz: Option<f64>,
}

/// The readout board.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoardConfig {
    /// Emulation sample rate, Hz; default 16 times the highest f0 (filled in by
    /// `parse_config`, read it with [`Config::fs_hz`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fs_hz: Option<f64>,
    /// Transimpedance gain, ohm.
    #[serde(default = "default_tia_gain")]
    pub tia_gain_ohm: f64,
    /// TIA pole, Hz (absent: no pole).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tia_pole_hz: Option<f64>,
    /// Whether the TIA inverts.
    #[serde(default = "default_true")]
    pub tia_inverting: bool,
    /// TIA output rails, volts (absent: no saturation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tia_rail_v: Option<f64>,
    /// Order of the stage-1 Butterworth low-pass (1 to 8).
    #[serde(default = "default_lpf_order")]
    pub lpf_order: usize,
    /// Cutoff of the stage-1 low-pass, Hz; default derived from the device and the rates (see
    /// `Config::resolve`; read it with [`Config::lpf_cutoff_hz`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lpf_cutoff_hz: Option<f64>,
    /// Decimation factor after the stage-1 low-pass; default from the sample rate and the
    /// cutoff (read it with [`Config::decimation`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decimation: Option<usize>,
    /// DAC resolution in bits (absent: ideal DAC).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dac_bits: Option<u32>,
    /// DAC full scale (same unit as the drive amplitudes).
    #[serde(default = "default_full_scale")]
    pub dac_full_scale: f64,
    /// Error of the board's 90-degree phase shifter, degrees.
    #[serde(default)]
    pub phase_shifter_error_deg: f64,
    /// ADC resolution in bits after each TIA (absent: ideal ADC).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adc_bits: Option<u32>,
    /// ADC full scale, V (the input range is -full scale to +full scale).
    #[serde(default = "default_adc_full_scale")]
    pub adc_full_scale_v: f64,
}

impl Default for BoardConfig {
    /// Every key at the default it has when left out of a `[board]` table.
    fn default() -> Self {
        Self {
            fs_hz: None,
            tia_gain_ohm: default_tia_gain(),
            tia_pole_hz: None,
            tia_inverting: default_true(),
            tia_rail_v: None,
            lpf_order: default_lpf_order(),
            lpf_cutoff_hz: None,
            decimation: None,
            dac_bits: None,
            dac_full_scale: default_full_scale(),
            phase_shifter_error_deg: 0.0,
            adc_bits: None,
            adc_full_scale_v: default_adc_full_scale(),
        }
    }
}

/// White, seeded noise sources (docs/user-guide.md gives the models).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseConfig {
    /// Seed of the random streams; each operating point draws from its own stream, derived
    /// from the seed and the point's index in `rates_dps`.
    #[serde(default)]
    pub seed: u64,
    /// Resonator temperature, K (thermomechanical noise 4 k T m w0 / Q).
    #[serde(default = "default_temperature")]
    pub temperature_k: f64,
    /// Effective modal mass, kg (absent: no thermomechanical noise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effective_mass_kg: Option<f64>,
    /// TIA input current noise density, A/sqrt(Hz).
    #[serde(default)]
    pub tia_current_noise_a_per_rthz: f64,
    /// TIA output voltage noise density, V/sqrt(Hz) (within the TIA's own bandwidth).
    #[serde(default)]
    pub tia_voltage_noise_v_per_rthz: f64,
    /// Flicker corner of the TIA voltage noise: its density is `e_n^2 (1 + corner / f)`, Hz
    /// (0: white only).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub tia_voltage_flicker_corner_hz: f64,
    /// Flicker of each drive's relative amplitude: density at 1 Hz, 1/sqrt(Hz) (0: none).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub drive_amplitude_flicker_per_rthz: f64,
    /// Flicker of each drive's phase: density at 1 Hz, rad/sqrt(Hz) (0: none).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub drive_phase_flicker_rad_per_rthz: f64,
    /// Flicker of the carrier oscillator's phase (drives and demodulation alike): density at
    /// 1 Hz, rad/sqrt(Hz) (0: none).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub carrier_phase_flicker_rad_per_rthz: f64,
    /// Low corner of the flicker sources, Hz (their densities flatten below it); default 0.02
    /// over the longest record a run makes (read it with [`Config::flicker_f_lo_hz`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flicker_f_lo_hz: Option<f64>,
}

impl Default for NoiseConfig {
    /// Seed 0 at 300 K with every source off (each key at the default it has when left out).
    fn default() -> Self {
        Self {
            seed: 0,
            temperature_k: default_temperature(),
            effective_mass_kg: None,
            tia_current_noise_a_per_rthz: 0.0,
            tia_voltage_noise_v_per_rthz: 0.0,
            tia_voltage_flicker_corner_hz: 0.0,
            drive_amplitude_flicker_per_rthz: 0.0,
            drive_phase_flicker_rad_per_rthz: 0.0,
            carrier_phase_flicker_rad_per_rthz: 0.0,
            flicker_f_lo_hz: None,
        }
    }
}

/// The analyses `gyroemu selfcal` adds to its two sweeps; each runs only when its key is set.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SelfcalConfig {
    /// Length of the zero-rate Coriolis record whose Allan deviation is reported, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub allan_record_s: Option<f64>,
    /// Longest averaging time of the self-calibration error against averaging time, s
    /// (the rotating sweep then runs this long; the analysis starts at 1 s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tau_max_s: Option<f64>,
    /// Temperature offsets of the drift scenario, K (empty: no drift scenario).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub drift_delta_t_k: Vec<f64>,
    /// Temperature coefficient of f0, ppm/K (silicon: about -30).
    #[serde(default = "default_f0_tc")]
    pub f0_tc_ppm_per_k: f64,
    /// Temperature coefficient of Q, ppm/K (thermoelastic damping: Q falls as T rises).
    #[serde(default = "default_q_tc")]
    pub q_tc_ppm_per_k: f64,
}

/// How the stepped-sine frequencies are spaced between `start_hz` and `stop_hz`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Spacing {
    /// Evenly in the sum of the two modes' resonance phases `atan((f - f0_k) / b_k)`
    /// (`b_k = f0_k / (2 Q_k)`): dense near each resonance, sparse on the skirts.
    Resonance,
    /// Evenly in frequency.
    Linear,
    /// Evenly in log frequency.
    Log,
}

/// The stepped-sine frequency response of `gyroemu sweep`: each mode driven alone at each
/// frequency, at zero rate, settled, then averaged. Every key has a default derived from the
/// device (see `Config::sweep_resolved`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepConfig {
    /// Lowest frequency, Hz; default 10 half-bandwidths f0/(2Q) below the lower mode.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_hz: Option<f64>,
    /// Highest frequency, Hz; default 10 half-bandwidths above the upper mode.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_hz: Option<f64>,
    /// Number of frequencies (start and stop included).
    #[serde(default = "default_sweep_points")]
    pub points: usize,
    /// How the frequencies are spaced.
    #[serde(default = "default_spacing")]
    pub spacing: Spacing,
    /// Time discarded at each frequency before averaging, s; default 16 mechanical time
    /// constants Q/(pi f0) of the slower mode plus the low-pass settling.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_s: Option<f64>,
    /// Averaging time at each frequency, s; default 2 mechanical time constants.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub average_s: Option<f64>,
}

impl Default for SweepConfig {
    /// Every key at the default it has when left out of a `[sweep]` table.
    fn default() -> Self {
        Self {
            start_hz: None,
            stop_hz: None,
            points: default_sweep_points(),
            spacing: default_spacing(),
            settle_s: None,
            average_s: None,
        }
    }
}

/// A production lot (`gyroemu montecarlo`): each device's parameters drawn around the
/// config's own from the tolerances below, device `i` from `(seed, i)` alone. Every spread is
/// a standard deviation: of the uniform draw, or of the normal before its truncation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloConfig {
    /// Seed of the device draws (the noise streams keep `noise.seed`, per device).
    #[serde(default)]
    pub seed: u64,
    /// Shape of every draw: `normal` (truncated at `truncate_sigma`) or `uniform`.
    #[serde(default = "default_distribution")]
    pub distribution: Distribution,
    /// Normal draws beyond this many standard deviations are drawn again.
    #[serde(default = "default_truncate_sigma")]
    pub truncate_sigma: f64,
    /// Spread of the mode split `device.mode2_f0_offset_hz` (added to it), Hz.
    #[serde(default)]
    pub mode_split_sigma_hz: f64,
    /// Relative spread of Q (both modes scaled together).
    #[serde(default)]
    pub q_sigma_rel: f64,
    /// Relative spread of the Q mismatch (mode 2's Q scaled alone).
    #[serde(default)]
    pub q_mismatch_sigma_rel: f64,
    /// Relative spread of the drive-gain ratio F2/F1 (F2 scaled).
    #[serde(default)]
    pub drive_gain_sigma_rel: f64,
    /// Spread of the phase-shifter error `board.phase_shifter_error_deg` (added to it), deg.
    #[serde(default)]
    pub phase_shifter_sigma_deg: f64,
    /// Relative spread of the angular gain lambda; the self-calibration keeps predicting with
    /// the config's (nominal) lambda.
    #[serde(default)]
    pub lambda_sigma_rel: f64,
    /// A device passes when its |self-calibration error| (mode 1) is at most this.
    pub spec_abs_relative_error: f64,
}

/// Shape of a Monte Carlo draw (of unit standard deviation before scaling).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Distribution {
    /// Gaussian, truncated at `truncate_sigma` standard deviations.
    Normal,
    /// Flat over +-sqrt(3) standard deviations.
    Uniform,
}

/// Which excitation the sweep uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ExperimentKind {
    /// Drives 90 degrees apart, device rotating (Figs. 4 and 8).
    Coriolis,
    /// Device at rest, drive direction rotating at Omega (Figs. 5 and 9).
    Rotating,
}

/// Shape of the rotation rate in a Coriolis run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RateTable {
    /// Constant rate: the listed value.
    Constant,
    /// Omega_z(t) = rate * sin(2 pi table_freq_hz t): the listed value is the amplitude.
    Sinusoid,
}

/// Averaging window.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WindowKind {
    /// Flat average over whole (half) modulation periods.
    Boxcar,
    /// Hann-weighted average (robust to a non-whole number of periods).
    Hann,
}

/// The sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentConfig {
    /// `coriolis` or `rotating`.
    pub kind: ExperimentKind,
    /// Rotation rates (Coriolis) or excitation rates Omega (rotating), deg/s.
    pub rates_dps: Vec<f64>,
    /// Time discarded before averaging, s (absent: 16 mechanical time constants plus the
    /// low-pass settling).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_s: Option<f64>,
    /// Averaging time, s.
    pub average_s: f64,
    /// Averaging window.
    #[serde(default = "default_window")]
    pub window: WindowKind,
    /// Rate-table profile (Coriolis only).
    #[serde(default = "default_rate_table")]
    pub rate_table: RateTable,
    /// Rate-table frequency for `rate_table = "sinusoid"`, Hz.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table_freq_hz: Option<f64>,
}

/// A windowed dump of the board's internal signals for one operating point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DumpConfig {
    /// Which operating point, deg/s (one of the emulated rates: `rates_dps`, plus 0 in a
    /// constant-rate Coriolis run); default the largest listed rate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_dps: Option<f64>,
    /// Start of the window, s from the start of the run; default the end of settling.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_s: Option<f64>,
    /// Length of the window, s; default four modulation periods of the dumped point (rotating,
    /// rate table) or 200 carrier periods (Coriolis), within 1 ms .. 0.5 s and the run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<f64>,
    /// Nodes to dump: any of `drive`, `displacement`, `velocity`, `tia`, `stage1`
    /// (full rate), `lowpass`, `stage2` (decimated rate); default all of them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nodes: Option<Vec<String>>,
}

/// A flicker level left at 0 is not written (configs without flicker keep their text, and the
/// hash that names their saved points).
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}
fn default_damping() -> f64 {
    core::f64::consts::FRAC_1_SQRT_2
}
fn default_pll_mode() -> usize {
    1
}
/// Frequencies of a `[sweep]` by default.
pub const DEFAULT_SWEEP_POINTS: usize = 61;

fn default_sweep_points() -> usize {
    DEFAULT_SWEEP_POINTS
}
fn default_spacing() -> Spacing {
    Spacing::Resonance
}
fn default_transduction() -> f64 {
    1e-6
}
fn default_tia_gain() -> f64 {
    1e6
}
fn default_true() -> bool {
    true
}
fn default_lpf_order() -> usize {
    4
}
fn default_full_scale() -> f64 {
    1.0
}
fn default_window() -> WindowKind {
    WindowKind::Boxcar
}
fn default_rate_table() -> RateTable {
    RateTable::Constant
}
fn default_adc_full_scale() -> f64 {
    1.0
}
fn default_temperature() -> f64 {
    300.0
}
fn default_distribution() -> Distribution {
    Distribution::Normal
}
fn default_truncate_sigma() -> f64 {
    4.0
}
fn default_f0_tc() -> f64 {
    -30.0
}
fn default_q_tc() -> f64 {
    -3000.0
}
