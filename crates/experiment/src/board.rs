//! The readout board assembled from the stage crates, run sample by sample. Generic over the
//! sample type: `f64` runs one operating point, `f64x4` runs four in SIMD lanes through the
//! very same stage code (the carrier NCO is shared, each lane has its own rate and plant).

use crate::config::{Config, ExperimentKind, RateTable};
use crate::probe::Probe;
use gyroemu_am::{AmInput, AmModulator, Dac, DrivePattern, Quantizer};
use gyroemu_core::noise::{held_white_sigma, stream_seed, NoiseRng};
use gyroemu_core::{detmath, Complex64, ParamError, Sample, Stage};
use gyroemu_lpf::{DecimateMode, KahanSum, LowPass, LowPassBank, LowPassDesign};
use gyroemu_mixer::{Iq, Stage1Mixer, Stage2Mixer};
use gyroemu_nco::{Nco, PhaseShifter, RotatingNco};
use gyroemu_resonator::{thermomechanical_accel_psd, ModeParams, Resonator, ResonatorParams};
use gyroemu_tia::{input_referred_noise_a_per_rthz, Tia, TiaParams};
use std::sync::atomic::Ordering;

/// At most this many lanes (the width of `f64x4`).
pub const MAX_LANES: usize = 4;

/// One operating point: the rate in rad/s (rotation rate, excitation rate, or rate-table
/// amplitude) and its averaging window in decimated samples after settling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Rate, rad/s.
    pub rate_rad_s: f64,
    /// Whole decimated samples in the averaging window.
    pub n_avg: u64,
    /// How the samples of the window are weighted.
    pub window: PointWindow,
}

/// The weights of a point's averaging window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PointWindow {
    /// Weight 1 on `n_avg` samples and `frac` (in [0, 1)) on the next: the fractional end of a
    /// whole number of half periods, so the average spans exactly that time.
    Boxcar { frac: f64 },
    /// Hann weights over `n_avg` samples.
    Hann,
}

impl Point {
    /// The averaged span in decimated samples.
    pub fn span_samples(&self) -> f64 {
        match self.window {
            PointWindow::Boxcar { frac } => self.n_avg as f64 + frac,
            PointWindow::Hann => self.n_avg as f64,
        }
    }
}

/// What one lane measured, averaged after settling.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LaneResult {
    /// Mean stage-1 phasor per mode (Coriolis, constant rate).
    pub z: [Complex64; 2],
    /// Stage-2 averages C and S per mode (rotating).
    pub c: [Complex64; 2],
    /// Stage-2 averages C and S per mode (rotating).
    pub s: [Complex64; 2],
    /// Rate-table run: complex amplitude of the phase (lag) at the table frequency, per mode.
    pub table_phase: [Complex64; 2],
}

/// The plant parameters a config describes.
pub fn resonator_params(c: &Config) -> ResonatorParams {
    ResonatorParams {
        mode1: ModeParams {
            f0_hz: c.device.f0_hz,
            q: c.device.q,
        },
        mode2: ModeParams {
            f0_hz: c.f0_mode2_hz(),
            q: c.device.q_mode2.unwrap_or(c.device.q),
        },
        angular_gain: c.device.angular_gain,
        quadrature_coupling_rad2_s2: c.device.quadrature_coupling_rad2_s2,
        transduction_a_s_per_m: c.device.transduction_a_s_per_m,
        fs_hz: c.board.fs_hz,
    }
}

/// The TIA parameters a config describes.
pub fn tia_params(c: &Config) -> TiaParams {
    TiaParams {
        gain_ohm: c.board.tia_gain_ohm,
        pole_hz: c.board.tia_pole_hz,
        inverting: c.board.tia_inverting,
        rail_v: c.board.tia_rail_v,
        fs_hz: c.board.fs_hz,
    }
}

/// The stage-1 low-pass a config describes.
pub fn lowpass_design(c: &Config) -> LowPassDesign {
    LowPassDesign::Butterworth {
        order: c.board.lpf_order,
        cutoff_hz: c.board.lpf_cutoff_hz,
    }
}

/// The stage-1 low-pass decimator a config describes (the board runs the same low-pass and
/// keeps its output on input index kM + M - 1, the phase `Decimator` documents).
pub fn decimator_mode(c: &Config) -> DecimateMode {
    DecimateMode::Filter(lowpass_design(c))
}

/// The sample loop's three shapes, chosen once per run (const generics keep the
/// per-sample path free of the kind test).
const CORIOLIS: u8 = 0;
const RATE_TABLE: u8 = 1;
const ROTATING: u8 = 2;

/// The seeded noise of one lane group: one stream per lane (per operating point) and the
/// per-sample standard deviations of the force (per unit mass) and input-current sources.
#[derive(Clone, Debug)]
struct NoiseState<S> {
    rng: NoiseRng,
    sigma_force: [S; 2],
    sigma_current: [S; 2],
}

/// A value that stopped being finite inside the chain: where and when.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("non-finite value at the output of stage `{stage}` at input sample {sample} (t = {time_s} s) of the operating point at {rate_dps} deg/s: the chain overflowed; check the drive amplitudes, the gains and the full scales")]
pub struct NonFinite {
    /// The first stage (in chain order) whose output was not finite.
    pub stage: &'static str,
    /// Input sample index from the start of the run.
    pub sample: u64,
    /// The same as a time, s.
    pub time_s: f64,
    /// The operating point's rate, deg/s.
    pub rate_dps: f64,
}

/// Optional outputs of a run beyond each lane's average.
#[derive(Clone, Debug, Default)]
pub struct RunExtras {
    /// Per lane, ascending: extra ends `(n, frac)` of the lane's boxcar window (weight 1 on
    /// `n` samples and `frac` on the next); each yields the average as if the window ended
    /// there (the averaging-time analysis). Needs a boxcar point window at least as long.
    pub checkpoints: Vec<Vec<(u64, f64)>>,
    /// Decimated samples per row of the recorded series (0: no series). Each row holds the
    /// mean over its block of the averaged channels (after settling).
    pub series_block: u64,
}

/// What a run returns with [`RunExtras`].
#[derive(Clone, Debug, Default)]
pub struct RunOutput {
    /// Per lane: the average over the point's window.
    pub lanes: Vec<LaneResult>,
    /// Per lane: one result per checkpoint.
    pub checkpoints: Vec<Vec<LaneResult>>,
    /// Per lane: the series rows (Coriolis: I1, Q1, I2, Q2 of the low-passed stage-1 outputs;
    /// rotating: C and S of both modes as in [`LaneResult`], 8 values).
    pub series: Vec<Vec<[f64; 8]>>,
}

/// Per-sample work shared by every lane; all fields are built before the first sample.
#[derive(Clone)]
pub struct Board<S: Sample> {
    kind: ExperimentKind,
    table: bool,
    lanes: usize,
    /// Carrier e^{j w0 t}, shared by all lanes.
    carrier: RotatingNco<f64>,
    shifter: PhaseShifter,
    /// Modulation e^{j Omega t}, one Omega per lane (rotating runs).
    modulation: RotatingNco<S>,
    /// Rate-table sine, shared frequency (rate-table runs).
    table_nco: RotatingNco<f64>,
    rate: S,
    am: AmModulator<S>,
    dac: [Dac<S>; 2],
    plant: Resonator<S>,
    tia: [Tia<S>; 2],
    mix1: [Stage1Mixer<S>; 2],
    /// The two stage-1 mixers have the same reference phase (their carrier factors agree).
    mix1_same_ref: bool,
    /// Stage-1 low-pass of I1, Q1, I2, Q2 (one design).
    lp: LowPassBank<S, 4>,
    decimation: usize,
    mix2: Stage2Mixer<S>,
    fs_hz: f64,
    table_f_hz: f64,
    /// Phase-shifter error on the modulation's quadrature copy (rotating runs): (cos, sin).
    mod_shift: Option<(S, S)>,
    noise: NoiseState<S>,
    /// ADC after each TIA (absent: ideal).
    adc: Option<[Quantizer<S>; 2]>,
    /// Noise or ADC present: the sample loop takes its imperfect shape.
    imperfect: bool,
    /// The board as built, for locating a non-finite value by replay.
    pristine: Option<Box<Board<S>>>,
    /// Raised: the run stops at its next progress report (see [`Board::set_cancel`]).
    cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

impl<S: Sample> Board<S> {
    /// Builds the board for up to `S::LANES` operating points (rates in rad/s; unused lanes
    /// repeat the last point); lane `i` draws noise stream `i`.
    pub fn new(cfg: &Config, rates_rad_s: &[f64]) -> Result<Self, ParamError> {
        let streams: Vec<u64> = (0..rates_rad_s.len() as u64).collect();
        Self::with_streams(cfg, rates_rad_s, &streams)
    }

    /// As [`Board::new`], with the noise stream of each lane given (a sweep passes each
    /// point's index, so its noise does not depend on the lane group or shard that runs it).
    pub fn with_streams(
        cfg: &Config,
        rates_rad_s: &[f64],
        streams: &[u64],
    ) -> Result<Self, ParamError> {
        assert!(!rates_rad_s.is_empty() && rates_rad_s.len() <= S::LANES);
        assert_eq!(rates_rad_s.len(), streams.len());
        let lanes = rates_rad_s.len();
        let lane_rate = |i: usize| rates_rad_s[i.min(lanes - 1)];
        let fs = cfg.board.fs_hz;
        let kind = cfg.experiment.kind;
        let table = cfg.experiment.rate_table == RateTable::Sinusoid;
        let carrier = Nco::new(cfg.device.f0_hz, fs, 0.0)?;
        // The nominal shifter is exactly -j (cos -> sin with no rounding).
        let shifter = match cfg.board.phase_shifter_error_deg {
            0.0 => PhaseShifter::quadrature(),
            e => PhaseShifter::new((90.0 + e).to_radians())?,
        };
        let modulation: Vec<Nco> = (0..S::LANES)
            .map(|i| {
                let f_mod = match kind {
                    ExperimentKind::Rotating => lane_rate(i) / core::f64::consts::TAU,
                    ExperimentKind::Coriolis => 0.0,
                };
                Nco::new(f_mod, fs, 0.0)
            })
            .collect::<Result<_, _>>()?;
        // The plant holds the rate over each step; the midpoint value makes that step
        // second-order accurate, so the table NCO runs half a sample ahead.
        let f_table = cfg.experiment.table_freq_hz.unwrap_or(0.0);
        let table_nco = Nco::new(f_table, fs, core::f64::consts::PI * f_table / fs)?;
        let table_f_hz = table_nco.f_hz();
        let pattern = match kind {
            ExperimentKind::Coriolis => DrivePattern::Coriolis,
            ExperimentKind::Rotating => DrivePattern::Rotating,
        };
        let am = AmModulator::new(pattern, cfg.drive.f1, cfg.drive.f2)?;
        let quant = cfg.board.dac_bits.map(|b| (b, cfg.board.dac_full_scale));
        let dac = [Dac::new(fs, quant)?, Dac::new(fs, quant)?];
        let params = resonator_params(cfg);
        // Coriolis lanes differ by their rotation rate; a rate table starts from rest (0).
        let plant_rate = |i: usize| match (kind, table) {
            (ExperimentKind::Coriolis, false) => lane_rate(i),
            _ => 0.0,
        };
        let scalar: Vec<Resonator<f64>> = (0..S::LANES)
            .map(|i| Resonator::<f64>::new(&params, plant_rate(i)))
            .collect::<Result<_, _>>()?;
        let tp = tia_params(cfg);
        let design = lowpass_design(cfg);
        let mix1 = [Stage1Mixer::new(0.0)?, Stage1Mixer::new(0.0)?];
        if cfg.board.decimation == 0 {
            return Err(ParamError::new(
                "decimator",
                "decimation",
                0,
                "must be an integer >= 1",
            ));
        }
        let seed = cfg.noise.as_ref().map_or(0, |n| n.seed);
        let lane_stream = |i: usize| streams[i.min(lanes - 1)];
        let rng = NoiseRng::new(core::array::from_fn(|i| stream_seed(seed, lane_stream(i))));
        let f0 = [params.mode1.f0_hz, params.mode2.f0_hz];
        let q = [params.mode1.q, params.mode2.q];
        let (sigma_force, sigma_current) = match &cfg.noise {
            None => ([0.0; 2], [0.0; 2]),
            Some(n) => {
                let force = core::array::from_fn(|k| {
                    n.effective_mass_kg.map_or(0.0, |m| {
                        let psd = thermomechanical_accel_psd(n.temperature_k, m, f0[k], q[k]);
                        held_white_sigma(psd, fs, f0[k])
                    })
                });
                let i_n = input_referred_noise_a_per_rthz(
                    n.tia_current_noise_a_per_rthz,
                    n.tia_voltage_noise_v_per_rthz,
                    cfg.board.tia_gain_ohm,
                );
                let current = core::array::from_fn(|k| held_white_sigma(i_n * i_n, fs, f0[k]));
                (force, current)
            }
        };
        let adc = match cfg.board.adc_bits {
            None => None,
            Some(b) => {
                let q = Quantizer::new(b, cfg.board.adc_full_scale_v)?;
                Some([q, q])
            }
        };
        let imperfect = cfg.noise.is_some() || adc.is_some();
        let eps = cfg.board.phase_shifter_error_deg.to_radians();
        let mod_shift = (kind == ExperimentKind::Rotating && eps != 0.0)
            .then(|| (S::splat(eps.cos()), S::splat(eps.sin())));
        let mut board = Self {
            kind,
            table,
            lanes,
            carrier: RotatingNco::new(&[carrier]),
            shifter,
            modulation: RotatingNco::new(&modulation),
            table_nco: RotatingNco::new(&[table_nco]),
            rate: S::from_fn(lane_rate),
            am,
            dac,
            plant: Resonator::<S>::from_lanes(&scalar),
            tia: [Tia::new(&tp)?, Tia::new(&tp)?],
            mix1_same_ref: mix1[0].ref_phase_rad() == mix1[1].ref_phase_rad(),
            mix1,
            lp: LowPassBank::new(&LowPass::new(design, fs)?),
            decimation: cfg.board.decimation,
            mix2: Stage2Mixer::default(),
            fs_hz: fs,
            table_f_hz,
            mod_shift,
            noise: NoiseState {
                rng,
                sigma_force: sigma_force.map(S::splat),
                sigma_current: sigma_current.map(S::splat),
            },
            adc,
            imperfect,
            pristine: None,
            cancel: None,
        };
        board.pristine = Some(Box::new(board.clone()));
        Ok(board)
    }

    /// A flag that, once raised, makes a run stop at its next progress report (every 65 536
    /// input samples or so) and return at once: its averages are then meaningless, so the
    /// caller must test the flag after the run and discard them (Ctrl-C of a sweep).
    pub fn set_cancel(&mut self, flag: std::sync::Arc<std::sync::atomic::AtomicBool>) {
        self.cancel = Some(flag);
    }

    /// Runs `n_settle` decimated samples of settling, then averages each lane over its window.
    /// `progress` is called with the number of input samples done, every 65 536 or so.
    pub fn run(
        &mut self,
        n_settle: u64,
        points: &[Point],
        probe: Option<&mut Probe>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<LaneResult>, NonFinite> {
        let extras = RunExtras::default();
        Ok(self
            .run_with(n_settle, points, probe, &extras, progress)?
            .lanes)
    }

    /// [`Board::run`] with checkpoints and a recorded series.
    pub fn run_with(
        &mut self,
        n_settle: u64,
        points: &[Point],
        probe: Option<&mut Probe>,
        extras: &RunExtras,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, NonFinite> {
        let r = match (self.kind, self.table) {
            (ExperimentKind::Coriolis, false) => {
                self.run_shape::<CORIOLIS>(n_settle, points, probe, extras, progress)
            }
            (ExperimentKind::Coriolis, true) => {
                self.run_shape::<RATE_TABLE>(n_settle, points, probe, extras, progress)
            }
            (ExperimentKind::Rotating, _) => {
                self.run_shape::<ROTATING>(n_settle, points, probe, extras, progress)
            }
        };
        r.map_err(|k| self.locate_fault(k))
    }

    /// The plant takes its decoupled step (exact zeros across the modes in every lane: no
    /// rotation and no quadrature coupling; never on a rate table, whose step varies).
    fn plant_decoupled(&self) -> bool {
        !self.table && self.plant.decoupled()
    }

    /// [`Board::run_kind`] of experiment shape `K`, with the noise and plant shapes chosen.
    fn run_shape<const K: u8>(
        &mut self,
        n_settle: u64,
        points: &[Point],
        probe: Option<&mut Probe>,
        extras: &RunExtras,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, u64> {
        match (self.imperfect, self.plant_decoupled()) {
            (false, false) => {
                self.run_kind::<K, false, false>(n_settle, points, probe, extras, progress)
            }
            (false, true) => {
                self.run_kind::<K, false, true>(n_settle, points, probe, extras, progress)
            }
            (true, false) => {
                self.run_kind::<K, true, false>(n_settle, points, probe, extras, progress)
            }
            (true, true) => {
                self.run_kind::<K, true, true>(n_settle, points, probe, extras, progress)
            }
        }
    }

    /// One block of the checking replay, in the run's plant shape.
    fn replay_block<const K: u8>(&mut self, dec: bool, n0: u64, probe: &mut Probe) {
        if dec {
            self.block::<K, true, true>(n0, Some(probe));
        } else {
            self.block::<K, true, false>(n0, Some(probe));
        }
    }

    /// Replays the run from the board as built, checking every stage's output on every
    /// sample up to block `k_bad` (where the decimated output stopped being finite), and
    /// names the first stage and sample that went non-finite.
    #[cold]
    fn locate_fault(&self, k_bad: u64) -> NonFinite {
        let m = self.decimation as u64;
        let rate_dps = |lane: usize| self.rate.lane(lane).to_degrees();
        let fallback = NonFinite {
            stage: "lowpass",
            sample: k_bad * m + m - 1,
            time_s: (k_bad * m + m - 1) as f64 / self.fs_hz,
            rate_dps: rate_dps(0),
        };
        let Some(pristine) = &self.pristine else {
            return fallback;
        };
        let mut board = (**pristine).clone();
        let mut probe = Probe::finite_check(self.lanes);
        let dec = board.plant_decoupled();
        for k in 0..=k_bad {
            let n0 = k * m;
            match (self.kind, self.table) {
                (ExperimentKind::Coriolis, false) => {
                    board.replay_block::<CORIOLIS>(dec, n0, &mut probe);
                }
                (ExperimentKind::Coriolis, true) => {
                    board.replay_block::<RATE_TABLE>(dec, n0, &mut probe);
                }
                (ExperimentKind::Rotating, _) => {
                    board.replay_block::<ROTATING>(dec, n0, &mut probe);
                }
            }
            if let Some((stage, sample, lane)) = probe.fault() {
                return NonFinite {
                    stage,
                    sample,
                    time_s: sample as f64 / self.fs_hz,
                    rate_dps: rate_dps(lane),
                };
            }
        }
        fallback
    }

    /// The sample loop of one experiment shape. Returns the decimated index at which an
    /// output stopped being finite, if one did.
    ///
    /// Its own function per shape: inlined into the dispatcher beside the other shapes, the
    /// sample loop's registers were allocated worse (measured 249 against 326 M/s).
    #[allow(clippy::needless_range_loop)] // mode and lane indices address parallel arrays
    #[inline(never)]
    fn run_kind<const K: u8, const NZ: bool, const DEC: bool>(
        &mut self,
        n_settle: u64,
        points: &[Point],
        mut probe: Option<&mut Probe>,
        extras: &RunExtras,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, u64> {
        let lanes = self.lanes;
        let m = self.decimation as u64;
        let n_out = n_settle + points.iter().map(|p| p.n_avg + 1).max().unwrap_or(1);
        let mut acc = Accumulators::<S>::default();
        let mut weight_sum = [0.0f64; MAX_LANES];
        let mut prev_z = [Iq::<S>::default(); 2];
        let mut unwrapped = [S::splat(0.0); 2];
        let report_every = (65_536 / m).max(1);
        let mut ck_next = [0usize; MAX_LANES];
        let mut ck_out: Vec<Vec<LaneResult>> = vec![Vec::new(); lanes];
        let mut series: Vec<Vec<[f64; 8]>> = vec![Vec::new(); lanes];
        let mut series_acc = [S::splat(0.0); 8];
        for k in 0..n_out {
            let n0 = k * m;
            // The recording path only for blocks that touch the dump window.
            let (z, r) = match probe.as_deref_mut() {
                Some(p) if p.wants_block(n0, m) => self.block::<K, NZ, DEC>(n0, Some(p)),
                _ => self.block::<K, NZ, DEC>(n0, None),
            };
            // Each on its own: a sum of large finite values could overflow and false-alarm.
            if ![z[0].i, z[0].q, z[1].i, z[1].q]
                .iter()
                .all(|v| v.all_finite())
            {
                return Err(k);
            }
            if let Some(p) = probe.as_deref_mut() {
                p.record_decimated(k, &z, &r, self.kind);
            }
            if k % report_every == 0 {
                progress(n0 + m);
                if self
                    .cancel
                    .as_ref()
                    .is_some_and(|c| c.load(Ordering::Relaxed))
                {
                    break;
                }
            }
            if k < n_settle {
                prev_z = z;
                continue;
            }
            let j = k - n_settle;
            // This sample's value of every averaged channel, unweighted.
            let mut x = [S::splat(0.0); 8];
            match K {
                CORIOLIS => {
                    for md in 0..2 {
                        x[2 * md] = z[md].i;
                        x[2 * md + 1] = z[md].q;
                    }
                }
                RATE_TABLE => {
                    // Phase lag of z, unwrapped, demodulated at the table frequency, with the
                    // reference at the input sample this output stands for.
                    let n_in = (n0 + m - 1) as f64;
                    let (ts, tc) = detmath::sin_cos_turns(n_in * self.table_f_hz / self.fs_hz);
                    for md in 0..2 {
                        let d = S::from_fn(|i| {
                            let a = z[md].lane(i);
                            let b = prev_z[md].lane(i);
                            // arg(b/a): the lag accrued since the previous sample.
                            (b * a.conj()).arg()
                        });
                        unwrapped[md] += d;
                        x[2 * md] = unwrapped[md] * S::splat(2.0 * tc);
                        x[2 * md + 1] = unwrapped[md] * S::splat(-2.0 * ts);
                    }
                    prev_z = z;
                }
                _ => {
                    for (base, zm) in [(0, z[0]), (4, z[1])] {
                        let o = self.mix2.tick((zm, r));
                        x[base] = o.c.i;
                        x[base + 1] = o.c.q;
                        x[base + 2] = o.s.i;
                        x[base + 3] = o.s.q;
                    }
                }
            }
            for (i, cks) in extras.checkpoints.iter().enumerate().take(lanes) {
                while let Some(&(n, frac)) = cks.get(ck_next[i]) {
                    if n != j {
                        break;
                    }
                    let v: [f64; 8] = core::array::from_fn(|c| {
                        (acc.ch[c].value().lane(i) + frac * x[c].lane(i)) / (n as f64 + frac)
                    });
                    ck_out[i].push(lane_result::<K>(&v));
                    ck_next[i] += 1;
                }
            }
            if extras.series_block > 0 {
                for c in 0..8 {
                    series_acc[c] += x[c];
                }
                if (j + 1).is_multiple_of(extras.series_block) {
                    let scale = 1.0 / extras.series_block as f64;
                    for (i, rows) in series.iter_mut().enumerate() {
                        rows.push(core::array::from_fn(|c| series_acc[c].lane(i) * scale));
                    }
                    series_acc = [S::splat(0.0); 8];
                }
            }
            let w = S::from_fn(|i| window_weight(j, &points[i.min(lanes - 1)]));
            for i in 0..lanes {
                weight_sum[i] += w.lane(i);
            }
            let used = if K == ROTATING { 8 } else { 4 };
            for c in 0..used {
                acc.ch[c].add(w * x[c]);
            }
        }
        progress(n_out * m);
        let lanes_out = (0..lanes)
            .map(|i| {
                let v: [f64; 8] =
                    core::array::from_fn(|c| acc.ch[c].value().lane(i) / weight_sum[i]);
                lane_result::<K>(&v)
            })
            .collect();
        Ok(RunOutput {
            lanes: lanes_out,
            checkpoints: ck_out,
            series,
        })
    }

    /// One decimation block of input samples `n0 .. n0 + M` through the whole chain, fused
    /// (every stage on every sample, no buffers: a two-pass variant through an L1 buffer
    /// measured 17 % slower). Returns the low-passed stage-1 outputs at the block's last
    /// sample (the decimated output) and the modulation references (cos, sin of Omega t)
    /// at that same sample. `NZ`: the noise sources and the ADC are in the chain; `DEC`: the
    /// plant takes its decoupled step.
    #[inline(always)]
    fn block<const K: u8, const NZ: bool, const DEC: bool>(
        &mut self,
        n0: u64,
        mut probe: Option<&mut Probe>,
    ) -> ([Iq<S>; 2], [S; 2]) {
        let zero = S::splat(0.0);
        let mut out = ([Iq::<S>::default(); 2], [zero; 2]);
        for j in 0..self.decimation as u64 {
            let (c_re, c_im) = self.carrier.tick(());
            // The rotating drive uses only the in-phase carrier.
            let cq = if K == ROTATING {
                0.0
            } else {
                self.shifter.apply(Complex64::new(c_re, c_im)).re
            };
            let (mod_cos, mod_sin) = if K == ROTATING {
                self.modulation.tick(())
            } else {
                (zero, zero)
            };
            // The drive's quadrature copy passes the (imperfect) phase shifter:
            // sin(Omega t - eps); the stage-2 references stay exact.
            let drive_sin = match self.mod_shift {
                Some((ce, se)) if K == ROTATING => mod_sin * ce - mod_cos * se,
                _ => mod_sin,
            };
            let drive = self.am.tick(AmInput {
                carrier_i: S::splat(c_re),
                carrier_q: S::splat(cq),
                mod_cos,
                mod_sin: drive_sin,
            });
            let mut u = [self.dac[0].tick(drive[0]), self.dac[1].tick(drive[1])];
            if NZ {
                // Brownian force on each mode, after the DAC (it acts on the proof mass).
                let (a, b) = self.noise.rng.normal_pair();
                u[0] = S::from_x4(a).mul_add(self.noise.sigma_force[0], u[0]);
                u[1] = S::from_x4(b).mul_add(self.noise.sigma_force[1], u[1]);
            }
            let mut p = if K == RATE_TABLE {
                let (_, sin_t) = self.table_nco.tick(());
                self.plant.tick_with_rate(u, self.rate * S::splat(sin_t))
            } else if DEC {
                self.plant.tick_decoupled(u)
            } else {
                self.plant.tick(u)
            };
            if NZ {
                // Amplifier noise, referred to the TIA input.
                let (a, b) = self.noise.rng.normal_pair();
                p.current[0] = S::from_x4(a).mul_add(self.noise.sigma_current[0], p.current[0]);
                p.current[1] = S::from_x4(b).mul_add(self.noise.sigma_current[1], p.current[1]);
            }
            let mut y = [
                self.tia[0].tick(p.current[0]),
                self.tia[1].tick(p.current[1]),
            ];
            if NZ {
                if let Some(adc) = &self.adc {
                    y = [adc[0].quantize(y[0]), adc[1].quantize(y[1])];
                }
            }
            // Both stage-1 mixers see the same carrier: when their reference phases agree
            // (always, as built) they share one set of carrier factors.
            let carrier = Complex64::new(c_re, c_im);
            let f0 = self.mix1[0].factors(carrier);
            let f1 = if self.mix1_same_ref {
                f0
            } else {
                self.mix1[1].factors(carrier)
            };
            let z = [Stage1Mixer::mix(y[0], f0), Stage1Mixer::mix(y[1], f1)];
            if let Some(pr) = probe.as_deref_mut() {
                pr.record_full(n0 + j, &u, &p, &y, &z);
            }
            let [i1, q1, i2, q2] = self.lp.tick([z[0].i, z[0].q, z[1].i, z[1].q]);
            out = ([Iq::new(i1, q1), Iq::new(i2, q2)], [mod_cos, mod_sin]);
            if let Some(pr) = probe.as_deref_mut() {
                pr.check_lowpass(n0 + j, &out.0);
            }
        }
        out
    }
}

/// A lane's averaged channels as the result of its experiment shape.
fn lane_result<const K: u8>(v: &[f64; 8]) -> LaneResult {
    let ph = |c: usize| Complex64::new(v[c], v[c + 1]);
    match K {
        CORIOLIS => LaneResult {
            z: [ph(0), ph(2)],
            ..Default::default()
        },
        RATE_TABLE => LaneResult {
            table_phase: [ph(0), ph(2)],
            ..Default::default()
        },
        _ => LaneResult {
            c: [ph(0), ph(4)],
            s: [ph(2), ph(6)],
            ..Default::default()
        },
    }
}

/// Weight of decimated sample `j` (counted from the end of settling) in a lane's window.
#[inline]
fn window_weight(j: u64, p: &Point) -> f64 {
    match p.window {
        _ if j > p.n_avg => 0.0,
        PointWindow::Hann if j == p.n_avg => 0.0,
        PointWindow::Hann => {
            let (s, _) = detmath::sin_cos_turns(0.5 * (j as f64 + 0.5) / p.n_avg as f64);
            s * s
        }
        PointWindow::Boxcar { frac } if j == p.n_avg => frac,
        PointWindow::Boxcar { .. } => 1.0,
    }
}

/// Compensated sums of every averaged channel.
struct Accumulators<S: Sample> {
    ch: [KahanSum<S>; 8],
}

impl<S: Sample> Default for Accumulators<S> {
    fn default() -> Self {
        Self {
            ch: core::array::from_fn(|_| KahanSum::default()),
        }
    }
}

#[cfg(test)]
#[path = "board_tests.rs"]
mod tests;
