//! The readout board assembled from the stage crates. Generic over the sample type: `f64` runs
//! one operating point, `f64x4` four and `F64x8` (AVX-512, `group.rs`) eight in SIMD lanes
//! through the very same stage code (the carrier NCO is shared, each lane has its own rate,
//! plant and noise stream).

use crate::fault::NonFinite;
use crate::flicker::FlickerSources;
use crate::lanes::MAX_LANES;
use crate::params::{build_adc, build_dac, build_lowpass, build_tia, BoardParams, Shape};
use crate::point::{Point, RunOptions, RunOutput};
use crate::seeding::lane_set_rng;
use gyroemu_am::{AmModulator, Dac, DrivePattern, Quantizer};
use gyroemu_core::gauss::NormalBlock;
use gyroemu_core::noise::{held_white_sigma, white_sigma};
use gyroemu_core::{ParamError, Sample};
use gyroemu_lpf::LowPassBank;
use gyroemu_mixer::{Stage1Mixer, Stage2Mixer, TableMixer};
use gyroemu_nco::{Nco, PhaseShifter, RotatingNco};
use gyroemu_resonator::{thermomechanical_accel_psd, Resonator};
use gyroemu_tia::{input_referred_noise_a_per_rthz, Tia};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// The sample loop's shapes, chosen once per run (const generics keep the per-sample path free
/// of the shape test).
pub(crate) const CORIOLIS: u8 = 0;
pub(crate) const RATE_TABLE: u8 = 1;
pub(crate) const ROTATING: u8 = 2;
/// A rate table whose lanes follow different tables (another frequency,
/// [`Board::with_table_hz`], or another start, [`Board::with_starts`]).
pub(crate) const RATE_TABLE_LANES: u8 = 3;

/// Shape `k` is a rate table (shared or per lane).
pub(crate) const fn is_table(k: u8) -> bool {
    k == RATE_TABLE || k == RATE_TABLE_LANES
}

/// The seeded noise of one lane group: each lane's (operating point's) normals, drawn ahead,
/// four a sample (force on both modes, then input current on both modes), and the per-sample
/// standard deviations of the force (per unit mass) and input-current sources.
#[derive(Clone, Debug)]
pub(crate) struct NoiseState<S> {
    pub(crate) normals: NormalBlock,
    pub(crate) sigma_force: [S; 2],
    pub(crate) sigma_current: [S; 2],
}

/// The per-sample standard deviations of the force (per unit mass) and of the input-referred
/// current, per mode, each with the physical density at that mode's resonance: the force a
/// held white sequence (the plant holds its input over a sample), the current a plain white
/// one (the TIA takes its input sample by sample; a sinc correction made its density at f0
/// 1/sinc^2(f0/fs) too high, 1.3 % at 16 samples per period, 46 % at 3).
pub(crate) fn noise_sigmas(p: &BoardParams) -> ([f64; 2], [f64; 2]) {
    let Some(n) = &p.noise else {
        return ([0.0; 2], [0.0; 2]);
    };
    let fs = p.fs_hz();
    let f0 = [p.plant.mode1.f0_hz, p.plant.mode2.f0_hz];
    let q = [p.plant.mode1.q, p.plant.mode2.q];
    let force = core::array::from_fn(|k| {
        n.effective_mass_kg.map_or(0.0, |m| {
            let psd = thermomechanical_accel_psd(n.temperature_k, m, f0[k], q[k]);
            held_white_sigma(psd, fs, f0[k])
        })
    });
    let i_n = input_referred_noise_a_per_rthz(
        n.tia_current_noise_a_per_rthz,
        n.tia_voltage_noise_v_per_rthz,
        p.tia.gain_ohm,
    );
    let current = [white_sigma(i_n * i_n, fs); 2];
    (force, current)
}

/// The modulation frequency of a rotating operating point, Hz (0 for the other shapes).
pub(crate) fn modulation_hz(shape: Shape, rate_rad_s: f64) -> f64 {
    match shape {
        Shape::Rotating => rate_rad_s / core::f64::consts::TAU,
        _ => 0.0,
    }
}

/// The plant's constant rate for an operating point: the rate of a Coriolis point; a rate
/// table starts from rest and a rotating excitation keeps the device at rest.
pub(crate) fn plant_rate(shape: Shape, rate_rad_s: f64) -> f64 {
    match shape {
        Shape::Coriolis => rate_rad_s,
        _ => 0.0,
    }
}

/// The table oscillator: the plant holds the rate over each step and its midpoint value makes
/// that step second-order accurate, so the table NCO runs half a sample ahead.
pub(crate) fn table_nco(p: &BoardParams) -> Result<Nco, ParamError> {
    table_nco_at(own_table_hz(p.shape), p.fs_hz())
}

/// The table frequency a board of `shape` follows, Hz (0 outside rate tables).
pub(crate) fn own_table_hz(shape: Shape) -> f64 {
    match shape {
        Shape::RateTable { freq_hz } => freq_hz,
        _ => 0.0,
    }
}

/// [`table_nco`] at table frequency `f_hz`.
fn table_nco_at(f_hz: f64, fs_hz: f64) -> Result<Nco, ParamError> {
    Nco::new(f_hz, fs_hz, core::f64::consts::PI * f_hz / fs_hz)
}

/// A lane's modulation oscillator for the operating point at `rate_rad_s` of `shape`, as a
/// board that has run `start` samples holds it (built and refilled lanes alike).
pub(crate) fn lane_modulation(
    shape: Shape,
    rate_rad_s: f64,
    fs_hz: f64,
    start: u64,
) -> Result<Nco, ParamError> {
    let mut n = Nco::new(modulation_hz(shape, rate_rad_s), fs_hz, 0.0)?;
    n.jump(start);
    Ok(n)
}

/// A lane's rate-table oscillator at table frequency `f_hz`, where the lane starts on the
/// time axis (a rate table's phase counts from sample 0 of that axis; built and refilled
/// lanes alike).
pub(crate) fn lane_table(f_hz: f64, fs_hz: f64, start: u64) -> Result<Nco, ParamError> {
    let mut n = table_nco_at(f_hz, fs_hz)?;
    n.jump(start);
    Ok(n)
}

/// The table harmonics a board demodulates (none but the mean outside rate-table runs).
pub(crate) fn table_harmonics(p: &BoardParams) -> usize {
    match p.shape {
        Shape::RateTable { .. } => p.table_harmonics,
        _ => 0,
    }
}

/// The phase shifter of the drive's quadrature copy (the nominal one is exactly -j: cos ->
/// sin with no rounding); the config's rules that rebuild the drives call it too.
pub fn drive_shifter(p: &BoardParams) -> Result<PhaseShifter, ParamError> {
    match p.phase_shifter_error_deg {
        0.0 => Ok(PhaseShifter::quadrature()),
        e => PhaseShifter::new((90.0 + e).to_radians()),
    }
}

/// The drive pattern of a shape.
pub(crate) fn pattern(shape: Shape) -> DrivePattern {
    match shape {
        Shape::Rotating => DrivePattern::Rotating,
        _ => DrivePattern::Coriolis,
    }
}

/// The lanes of one board may start at the input samples `starts` of the time axis
/// ([`Board::with_starts`]): they share the carrier oscillator, so its phase word must be the
/// same at every start (its step times each difference of starts is a whole number of turns:
/// at `fs = 16 f0`, any multiple of 16 samples). Exact integer arithmetic on the words.
pub fn starts_share_carrier(p: &BoardParams, starts: &[u64]) -> bool {
    let Ok(carrier) = Nco::new(p.carrier_hz, p.fs_hz(), 0.0) else {
        return false;
    };
    let word = |n: u64| carrier.step_word().wrapping_mul(n);
    starts.iter().all(|&n| word(n) == word(starts[0]))
}

/// The latest start [`Board::with_starts`] takes: 2^53 input samples, the longest run a config
/// may ask for (beyond it a sample index is no longer exact as an f64, and a start plus the
/// run could pass `u64`).
pub const MAX_START: u64 = 1 << 53;

/// The rules of [`Board::with_starts`]: starts within [`MAX_START`] that share the carrier.
fn check_starts(p: &BoardParams, starts: &[u64]) -> Result<(), ParamError> {
    let bad = |v: String, rule: &str| Err(ParamError::new(crate::params::STAGE, "starts", v, rule));
    if let Some(&n) = starts.iter().find(|&&n| n > MAX_START) {
        return bad(
            n.to_string(),
            "a lane starts at most 2^53 input samples into the time axis",
        );
    }
    if !starts_share_carrier(p, starts) {
        return bad(
            format!("{starts:?}"),
            "the lanes share the carrier: its phase must be the same at every start (a whole number of carrier turns apart)",
        );
    }
    Ok(())
}

/// The longest run of the block loop ([`Board::block`]'s second pass buffers one). The
/// oscillators' re-sets cut runs at 64 samples already (`gyroemu_nco::RESYNC`).
pub(crate) const RUN: usize = 64;

/// Per-sample work shared by every lane; all fields are built before the first sample.
#[derive(Clone)]
pub struct Board<S: Sample> {
    pub(crate) shape: Shape,
    pub(crate) lanes: usize,
    /// Carrier e^{j w0 t}, shared by all lanes.
    pub(crate) carrier: RotatingNco<f64>,
    pub(crate) shifter: PhaseShifter,
    /// Modulation e^{j Omega t}, one Omega per lane (rotating runs).
    pub(crate) modulation: RotatingNco<S>,
    /// Rate-table sine shared by the lanes (rate-table runs).
    pub(crate) table_nco: RotatingNco<f64>,
    /// Rate-table sine of each lane, ticked in place of the shared one when the lanes follow
    /// different tables (another frequency, [`Board::with_table_hz`], or another start,
    /// [`Board::with_starts`]; `table_shared` false). Built either way, so
    /// that loop ticks a field it always has: behind an `Option`, each sample tested it and
    /// kept its phasor in memory (the bandwidth sweep's loop at 0.84 of the shared table's
    /// rate a group-sample; Xeon).
    pub(crate) table_lanes: RotatingNco<S>,
    /// Every lane follows the same table from the same start: the shared `table_nco` serves,
    /// the cheaper in the sample loop.
    pub(crate) table_shared: bool,
    pub(crate) rate: S,
    pub(crate) am: AmModulator<S>,
    pub(crate) dac: [Dac<S>; 2],
    pub(crate) plant: Resonator<S>,
    pub(crate) tia: [Tia<S>; 2],
    pub(crate) mix1: [Stage1Mixer<S>; 2],
    /// The two stage-1 mixers have the same reference phase (their carrier factors agree).
    pub(crate) mix1_same_ref: bool,
    /// Stage-1 low-pass of I1, Q1, I2, Q2 (one design).
    pub(crate) lp: LowPassBank<S, 4>,
    pub(crate) decimation: usize,
    pub(crate) mix2: Stage2Mixer<S>,
    /// Demodulation at the table harmonics (rate-table runs).
    pub(crate) table_mix: TableMixer<S>,
    pub(crate) fs_hz: f64,
    /// Each lane's realised table frequency, Hz (lanes past the points repeat the last).
    pub(crate) table_f_hz: [f64; MAX_LANES],
    /// Phase-shifter error on the modulation's quadrature copy (rotating runs): (cos, sin).
    pub(crate) mod_shift: Option<(S, S)>,
    pub(crate) noise: NoiseState<S>,
    /// Each lane's first input sample on the run's time axis ([`Board::with_starts`]; lanes
    /// past the points repeat the last).
    pub(crate) starts: [u64; MAX_LANES],
    /// The flicker sources (absent: none asked for).
    pub(crate) flicker: Option<FlickerSources<S>>,
    /// ADC after each TIA (absent: ideal).
    pub(crate) adc: Option<[Quantizer<S>; 2]>,
    /// Noise sources present (their draws are made).
    pub(crate) noise_on: bool,
    /// Noise, a converter's quantiser or TIA rails present: the sample loop takes its
    /// imperfect shape, which also counts clipped and zero samples.
    pub(crate) imperfect: bool,
    /// The board as built, for locating a non-finite value by replay.
    pub(crate) pristine: Option<Box<Board<S>>>,
    /// Raised: the run stops at its next progress report (see [`Board::set_cancel`]).
    pub(crate) cancel: Option<Arc<AtomicBool>>,
    /// The board has run (its oscillators no longer stand where it was built): refills,
    /// checked against a run from the start, are refused on it.
    pub(crate) ran: bool,
}

impl<S: Sample> Board<S> {
    /// Builds the board for up to `S::LANES` operating points (rates in rad/s: rotation,
    /// excitation or table amplitude, by `p.shape`; unused lanes repeat the last point); lane
    /// `i` draws noise stream `streams[i]` (a sweep passes each point's index, so its noise
    /// does not depend on the lane group or shard that runs it).
    pub fn new(p: &BoardParams, rates_rad_s: &[f64], streams: &[u64]) -> Result<Self, ParamError> {
        Self::build(p, rates_rad_s, None, streams, &[0])
    }

    /// [`Board::new`] with lane `i` starting at input sample `starts[i]` of the run's time
    /// axis instead of at 0: its oscillators (the modulation's phase at that sample, and the
    /// shared carrier's) are those of a board that has run `starts[i]` samples, while its
    /// plant, filters and noise start from rest, as after power-up. So a lane holds the bits
    /// of a board built with the single start `starts[i]`, and a long point's window can run
    /// as segments side by side, each settling anew (`gyroemu-experiment`'s split sweeps).
    /// The lanes share one carrier, so the starts must agree on its phase
    /// ([`starts_share_carrier`]); a rate table's phase counts from sample 0 of the time axis,
    /// so a lane started late has its own table, at its phase there. A refusal names the
    /// rule.
    pub fn with_starts(
        p: &BoardParams,
        rates_rad_s: &[f64],
        streams: &[u64],
        starts: &[u64],
    ) -> Result<Self, ParamError> {
        one_per_point("starts", starts.len(), rates_rad_s.len(), "start")?;
        Self::build(p, rates_rad_s, None, streams, starts)
    }

    /// [`Board::new`] for a rate-table board whose lane `i` follows its own table at
    /// `table_hz[i]` (> 0), in place of `p`'s: a lane then holds the bits of a board built
    /// with that frequency in `p` (the bandwidth sweep packs its table frequencies so).
    pub fn with_table_hz(
        p: &BoardParams,
        rates_rad_s: &[f64],
        table_hz: &[f64],
        streams: &[u64],
    ) -> Result<Self, ParamError> {
        let starts = vec![0; rates_rad_s.len()];
        Self::with_table_hz_starts(p, rates_rad_s, table_hz, streams, &starts)
    }

    /// [`Board::with_table_hz`] with lane `i` starting at input sample `starts[i]` of the
    /// time axis ([`Board::with_starts`]): the segments of the bandwidth sweep's long points.
    pub fn with_table_hz_starts(
        p: &BoardParams,
        rates_rad_s: &[f64],
        table_hz: &[f64],
        streams: &[u64],
        starts: &[u64],
    ) -> Result<Self, ParamError> {
        one_per_point("starts", starts.len(), rates_rad_s.len(), "start")?;
        let Shape::RateTable { .. } = p.shape else {
            return Err(ParamError::new(
                crate::params::STAGE,
                "table_hz",
                table_hz.len(),
                "a table frequency per lane needs a rate-table board",
            ));
        };
        one_per_point("table_hz", table_hz.len(), rates_rad_s.len(), "frequency")?;
        for &f in table_hz {
            gyroemu_core::error::positive(crate::params::STAGE, "table_freq_hz", f)?;
        }
        Self::build(p, rates_rad_s, Some(table_hz), streams, starts)
    }

    fn build(
        p: &BoardParams,
        rates_rad_s: &[f64],
        table_hz: Option<&[f64]>,
        streams: &[u64],
        starts: &[u64],
    ) -> Result<Self, ParamError> {
        let lanes = rates_rad_s.len();
        if lanes == 0 || lanes > S::LANES || streams.len() != lanes {
            return Err(ParamError::new(
                crate::params::STAGE,
                "rates_rad_s",
                lanes,
                format!(
                    "must list 1 to {} operating points, one noise stream each",
                    S::LANES
                ),
            ));
        }
        p.validate()?;
        let lane_rate = |i: usize| rates_rad_s[i.min(lanes - 1)];
        let lane_start = |i: usize| starts[i.min(starts.len() - 1)];
        check_starts(p, starts)?;
        let fs = p.fs_hz();
        let mut carrier = Nco::new(p.carrier_hz, fs, 0.0)?;
        carrier.jump(starts[0]);
        let modulation: Vec<Nco> = (0..S::LANES)
            .map(|i| lane_modulation(p.shape, lane_rate(i), fs, lane_start(i)))
            .collect::<Result<_, ParamError>>()?;
        let table: Vec<Nco> = (0..S::LANES)
            .map(|i| {
                let f = table_hz.map_or(own_table_hz(p.shape), |f| f[i.min(lanes - 1)]);
                lane_table(f, fs, lane_start(i))
            })
            .collect::<Result<_, ParamError>>()?;
        let table_f_hz: [f64; MAX_LANES] =
            core::array::from_fn(|i| table[i.min(S::LANES - 1)].f_hz());
        let on_table = p.shape.is_rate_table();
        let table_shared = (0..S::LANES).all(|i| {
            table_f_hz[i] == table_f_hz[0] && (!on_table || lane_start(i) == lane_start(0))
        });
        let scalar: Vec<Resonator<f64>> = (0..S::LANES)
            .map(|i| Resonator::<f64>::new(&p.plant, plant_rate(p.shape, lane_rate(i))))
            .collect::<Result<_, _>>()?;
        let mix1 = [Stage1Mixer::new(0.0)?, Stage1Mixer::new(0.0)?];
        let seed = p.noise.map_or(0, |n| n.seed);
        let rng = |q: usize| lane_set_rng(seed, streams, q);
        let normals = if S::LANES > 4 {
            NormalBlock::wide(rng(0), rng(1))
        } else {
            NormalBlock::new(rng(0))
        };
        let (sigma_force, sigma_current) = noise_sigmas(p);
        let adc = build_adc(p)?.map(|q| [q, q]);
        let imperfect = p.imperfect();
        let eps = p.phase_shifter_error_deg.to_radians();
        let mod_shift = (p.shape.is_rotating() && eps != 0.0)
            .then(|| (S::splat(eps.cos()), S::splat(eps.sin())));
        let mut board = Self {
            shape: p.shape,
            lanes,
            carrier: RotatingNco::new(&[carrier]),
            shifter: drive_shifter(p)?,
            modulation: RotatingNco::new(&modulation),
            table_f_hz,
            table_nco: RotatingNco::new(&table[..1]),
            table_lanes: RotatingNco::new(&table),
            table_shared,
            rate: S::from_fn(lane_rate),
            am: AmModulator::new(pattern(p.shape), p.drive[0], p.drive[1])?,
            dac: [build_dac(p)?, build_dac(p)?],
            plant: Resonator::<S>::from_lanes(&scalar),
            tia: [build_tia(p)?, build_tia(p)?],
            mix1_same_ref: mix1[0].ref_phase_rad() == mix1[1].ref_phase_rad(),
            mix1,
            lp: LowPassBank::new(&build_lowpass(p)?),
            decimation: p.decimation,
            mix2: Stage2Mixer::default(),
            table_mix: TableMixer::new(table_harmonics(p))?,
            fs_hz: fs,
            mod_shift,
            noise: NoiseState {
                normals,
                sigma_force: sigma_force.map(S::splat),
                sigma_current: sigma_current.map(S::splat),
            },
            adc,
            starts: core::array::from_fn(lane_start),
            noise_on: p.noise.is_some(),
            flicker: FlickerSources::new(p, streams)?,
            imperfect,
            pristine: None,
            cancel: None,
            ran: false,
        };
        board.pristine = Some(Box::new(board.clone()));
        Ok(board)
    }

    /// A flag that, once raised, makes a run stop at its next progress report (every 65 536
    /// input samples or so) and return at once: only the lanes whose window had ended are
    /// then marked [`RunOutput::complete`]; the others' averages are meaningless (Ctrl-C of
    /// a sweep).
    pub fn set_cancel(&mut self, flag: Arc<AtomicBool>) {
        self.cancel = Some(flag);
    }

    /// The operating points this board runs (lanes in use).
    pub fn lanes(&self) -> usize {
        self.lanes
    }

    /// Runs `n_settle` decimated samples of settling, then averages each lane over its point's
    /// window (plus what `opts` asks). `progress` is called with the number of input samples
    /// done, every 65 536 or so. A value that stops being finite ends the run with the stage
    /// and the sample where it happened.
    pub fn run(
        &mut self,
        n_settle: u64,
        points: &[Point],
        opts: RunOptions,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, NonFinite> {
        self.dispatch(n_settle, points, opts, &[], progress)
            .map_err(|k| self.locate_fault(k, &[]))
    }

    /// The plant takes its sparse step: at a constant rate the decoupled one (exact zeros
    /// across the modes in every lane: no rotation and no quadrature coupling), on a rate
    /// table the one split by mode (`Resonator::rate_split_by_mode`). Both leave out only
    /// products by exact zeros. Public so tests can check that a run took the shortcut it is
    /// compared through.
    pub fn plant_decoupled(&self) -> bool {
        match self.shape {
            Shape::RateTable { .. } => self.plant.rate_split_by_mode(),
            _ => self.plant.decoupled(),
        }
    }

    /// Whether this rate-table board's lanes follow tables of their own (another frequency
    /// or another start on the time axis: `RATE_TABLE_LANES`, the per-lane oscillator ticked
    /// in the sample loop) rather than one table shared by every lane. Public so tests can
    /// check which loop a board runs.
    pub fn table_per_lane(&self) -> bool {
        self.shape.is_rate_table() && !self.table_shared
    }

    /// The TIA's two flicker sources run as one of eight lanes (a four-lane board where the
    /// process runs eight): public, like [`Board::plant_decoupled`], so tests can check
    /// which path the reference comparison covered.
    pub fn tia_flicker_joined(&self) -> bool {
        self.flicker.as_ref().is_some_and(|f| f.tia_joined())
    }
}

/// Refuses a per-lane list `key` of `len` entries unless it has one `what` per point.
fn one_per_point(
    key: &'static str,
    len: usize,
    points: usize,
    what: &str,
) -> Result<(), ParamError> {
    if len == points {
        return Ok(());
    }
    Err(ParamError::new(
        crate::params::STAGE,
        key,
        len,
        format!("must list one {what} per point ({points})"),
    ))
}
