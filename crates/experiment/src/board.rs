//! The readout board assembled from the stage crates, run sample by sample. Generic over the
//! sample type: `f64` runs one operating point, `f64x4` runs four in SIMD lanes through the
//! very same stage code (the carrier NCO is shared, each lane has its own rate and plant).

use crate::config::{Config, ExperimentKind, RateTable};
use crate::probe::Probe;
use gyroemu_am::{AmInput, AmModulator, Dac, DrivePattern};
use gyroemu_core::{detmath, Complex64, ParamError, Sample, Stage};
use gyroemu_lpf::{DecimateMode, KahanSum, LowPass, LowPassDesign};
use gyroemu_mixer::{Iq, Stage1Mixer, Stage2Mixer};
use gyroemu_nco::{Nco, PhaseShifter, RotatingNco};
use gyroemu_resonator::{ModeParams, Resonator, ResonatorParams};
use gyroemu_tia::{Tia, TiaParams};

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

/// Per-sample work shared by every lane; all fields are built before the first sample.
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
    /// Stage-1 low-pass of I1, Q1, I2, Q2.
    lp: [LowPass<S>; 4],
    decimation: usize,
    mix2: Stage2Mixer<S>,
    fs_hz: f64,
    table_f_hz: f64,
}

impl<S: Sample> Board<S> {
    /// Builds the board for up to `S::LANES` operating points (rates in rad/s; unused lanes
    /// repeat the last point).
    pub fn new(cfg: &Config, rates_rad_s: &[f64]) -> Result<Self, ParamError> {
        assert!(!rates_rad_s.is_empty() && rates_rad_s.len() <= S::LANES);
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
        let lp = || LowPass::new(design, fs);
        if cfg.board.decimation == 0 {
            return Err(ParamError::new(
                "decimator",
                "decimation",
                0,
                "must be an integer >= 1",
            ));
        }
        Ok(Self {
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
            mix1: [Stage1Mixer::new(0.0)?, Stage1Mixer::new(0.0)?],
            lp: [lp()?, lp()?, lp()?, lp()?],
            decimation: cfg.board.decimation,
            mix2: Stage2Mixer::default(),
            fs_hz: fs,
            table_f_hz,
        })
    }

    /// Runs `n_settle` decimated samples of settling, then averages each lane over its window.
    /// `progress` is called with the number of input samples done, every 65 536 or so.
    pub fn run(
        &mut self,
        n_settle: u64,
        points: &[Point],
        probe: Option<&mut Probe>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Vec<LaneResult> {
        match (self.kind, self.table) {
            (ExperimentKind::Coriolis, false) => {
                self.run_kind::<CORIOLIS>(n_settle, points, probe, progress)
            }
            (ExperimentKind::Coriolis, true) => {
                self.run_kind::<RATE_TABLE>(n_settle, points, probe, progress)
            }
            (ExperimentKind::Rotating, _) => {
                self.run_kind::<ROTATING>(n_settle, points, probe, progress)
            }
        }
    }

    #[allow(clippy::needless_range_loop)] // mode and lane indices address parallel arrays
    fn run_kind<const K: u8>(
        &mut self,
        n_settle: u64,
        points: &[Point],
        mut probe: Option<&mut Probe>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Vec<LaneResult> {
        let lanes = self.lanes;
        let m = self.decimation as u64;
        let n_out = n_settle + points.iter().map(|p| p.n_avg + 1).max().unwrap_or(1);
        let mut acc = Accumulators::<S>::default();
        let mut weight_sum = [0.0f64; MAX_LANES];
        let mut prev_z = [Iq::<S>::default(); 2];
        let mut unwrapped = [S::splat(0.0); 2];
        let report_every = (65_536 / m).max(1);
        for k in 0..n_out {
            let n0 = k * m;
            // The recording path only for blocks that touch the dump window.
            let (z, r) = match probe.as_deref_mut() {
                Some(p) if p.wants_block(n0, m) => self.block::<K>(n0, Some(p)),
                _ => self.block::<K>(n0, None),
            };
            if let Some(p) = probe.as_deref_mut() {
                p.record_decimated(k, &z, &r, self.kind);
            }
            if k % report_every == 0 {
                progress(n0 + m);
            }
            if k < n_settle {
                prev_z = z;
                continue;
            }
            let j = k - n_settle;
            let w = S::from_fn(|i| window_weight(j, &points[i.min(lanes - 1)]));
            for i in 0..lanes {
                weight_sum[i] += w.lane(i);
            }
            match K {
                CORIOLIS => {
                    for md in 0..2 {
                        acc.ch[2 * md].add(w * z[md].i);
                        acc.ch[2 * md + 1].add(w * z[md].q);
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
                        acc.ch[2 * md].add(w * unwrapped[md] * S::splat(2.0 * tc));
                        acc.ch[2 * md + 1].add(w * unwrapped[md] * S::splat(-2.0 * ts));
                    }
                    prev_z = z;
                }
                _ => {
                    for (base, zm) in [(0, z[0]), (4, z[1])] {
                        let o = self.mix2.tick((zm, r));
                        acc.ch[base].add(w * o.c.i);
                        acc.ch[base + 1].add(w * o.c.q);
                        acc.ch[base + 2].add(w * o.s.i);
                        acc.ch[base + 3].add(w * o.s.q);
                    }
                }
            }
        }
        progress(n_out * m);
        (0..lanes)
            .map(|i| {
                let v = |c: usize| acc.ch[c].value().lane(i) / weight_sum[i];
                let ph = |c: usize| Complex64::new(v(c), v(c + 1));
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
            })
            .collect()
    }

    /// One decimation block of input samples `n0 .. n0 + M` through the whole chain, fused
    /// (every stage on every sample, no buffers: a two-pass variant through an L1 buffer
    /// measured 17 % slower). Returns the low-passed stage-1 outputs at the block's last
    /// sample (the decimated output) and the modulation references (cos, sin of Omega t)
    /// at that same sample.
    #[inline(always)]
    fn block<const K: u8>(
        &mut self,
        n0: u64,
        mut probe: Option<&mut Probe>,
    ) -> ([Iq<S>; 2], [S; 2]) {
        let zero = S::splat(0.0);
        let mut out = ([Iq::<S>::default(); 2], [zero; 2]);
        for j in 0..self.decimation as u64 {
            let (c_re, c_im) = self.carrier.tick(());
            let cq = self.shifter.apply(Complex64::new(c_re, c_im)).re;
            let (mod_cos, mod_sin) = if K == ROTATING {
                self.modulation.tick(())
            } else {
                (zero, zero)
            };
            let drive = self.am.tick(AmInput {
                carrier_i: S::splat(c_re),
                carrier_q: S::splat(cq),
                mod_cos,
                mod_sin,
            });
            let u = [self.dac[0].tick(drive[0]), self.dac[1].tick(drive[1])];
            let p = if K == RATE_TABLE {
                let (_, sin_t) = self.table_nco.tick(());
                self.plant.tick_with_rate(u, self.rate * S::splat(sin_t))
            } else {
                self.plant.tick(u)
            };
            let y = [
                self.tia[0].tick(p.current[0]),
                self.tia[1].tick(p.current[1]),
            ];
            let carrier = Complex64::new(c_re, c_im);
            let z = [
                self.mix1[0].tick((y[0], carrier)),
                self.mix1[1].tick((y[1], carrier)),
            ];
            if let Some(pr) = probe.as_deref_mut() {
                pr.record_full(n0 + j, &u, &p, &y, &z);
            }
            let i1 = self.lp[0].tick(z[0].i);
            let q1 = self.lp[1].tick(z[0].q);
            let i2 = self.lp[2].tick(z[1].i);
            let q2 = self.lp[3].tick(z[1].q);
            out = ([Iq::new(i1, q1), Iq::new(i2, q2)], [mod_cos, mod_sin]);
        }
        out
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
