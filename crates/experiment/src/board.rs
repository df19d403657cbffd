//! The readout board assembled from the stage crates, run sample by sample. Generic over the
//! sample type: `f64` runs one operating point, `f64x4` runs four in SIMD lanes through the
//! very same stage code (the carrier NCO is shared, each lane has its own rate and plant).

use crate::config::{Config, ExperimentKind, RateTable};
use crate::probe::Probe;
use gyroemu_am::{AmInput, AmModulator, Dac, DrivePattern};
use gyroemu_core::{detmath, Complex64, ParamError, Sample, Stage};
use gyroemu_lpf::{DecimateMode, Decimator, KahanSum, LowPassDesign};
use gyroemu_mixer::{Iq, Stage1Mixer, Stage2Mixer};
use gyroemu_nco::{Nco, PhaseShifter};
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
    /// Weight of the sample just after the window (boxcar: the fractional end of a whole
    /// number of half periods, so the average spans exactly that time).
    pub frac: f64,
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

/// Per-sample work shared by every lane; all fields are built before the first sample.
pub struct Board<S: Sample> {
    kind: ExperimentKind,
    table: bool,
    lanes: usize,
    carrier: Nco,
    shifter: PhaseShifter,
    modulation: [Nco; MAX_LANES],
    table_nco: Nco,
    rate: S,
    am: AmModulator<S>,
    dac: [Dac<S>; 2],
    plant: Resonator<S>,
    tia: [Tia<S>; 2],
    mix1: [Stage1Mixer<S>; 2],
    lp: [Decimator<S>; 4],
    lp_ref: [Decimator<S>; 2],
    mix2: Stage2Mixer<S>,
    fs_hz: f64,
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

/// The stage-1 low-pass decimator a config describes.
pub fn decimator_mode(c: &Config) -> DecimateMode {
    DecimateMode::Filter(LowPassDesign::Butterworth {
        order: c.board.lpf_order,
        cutoff_hz: c.board.lpf_cutoff_hz,
    })
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
        let shifter = PhaseShifter::new((90.0 + cfg.board.phase_shifter_error_deg).to_radians())?;
        let mut modulation = [
            carrier.clone(),
            carrier.clone(),
            carrier.clone(),
            carrier.clone(),
        ];
        for (i, m) in modulation.iter_mut().enumerate() {
            let f_mod = if kind == ExperimentKind::Rotating {
                lane_rate(i) / core::f64::consts::TAU
            } else {
                0.0
            };
            *m = Nco::new(f_mod, fs, 0.0)?;
        }
        // The plant holds the rate over each step; the midpoint value makes that step
        // second-order accurate, so the table NCO runs half a sample ahead.
        let f_table = cfg.experiment.table_freq_hz.unwrap_or(0.0);
        let table_nco = Nco::new(f_table, fs, core::f64::consts::PI * f_table / fs)?;
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
        let plant = Resonator::<S>::from_lanes(&scalar);
        let tp = tia_params(cfg);
        let tia = [Tia::new(&tp)?, Tia::new(&tp)?];
        let mix1 = [Stage1Mixer::new(0.0)?, Stage1Mixer::new(0.0)?];
        let mode = decimator_mode(cfg);
        let m = cfg.board.decimation;
        let dec = || Decimator::new(mode, m, fs);
        let lp = [dec()?, dec()?, dec()?, dec()?];
        let lp_ref = [dec()?, dec()?];
        let rate = S::from_fn(lane_rate);
        Ok(Self {
            kind,
            table,
            lanes,
            carrier,
            shifter,
            modulation,
            table_nco,
            rate,
            am,
            dac,
            plant,
            tia,
            mix1,
            lp,
            lp_ref,
            mix2: Stage2Mixer::default(),
            fs_hz: fs,
        })
    }

    /// Runs `n_settle` decimated samples of settling, then averages each lane over its window.
    /// `progress` is called with the number of input samples done, every 65 536 or so.
    #[allow(clippy::needless_range_loop)] // mode and lane indices address parallel arrays
    pub fn run(
        &mut self,
        n_settle: u64,
        points: &[Point],
        mut probe: Option<&mut Probe>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Vec<LaneResult> {
        let lanes = self.lanes;
        let m = self.lp[0].factor();
        let n_out = n_settle + points.iter().map(|p| p.n_avg + 1).max().unwrap_or(1);
        let mut acc = Accumulators::<S>::default();
        let mut weight_sum = [0.0f64; MAX_LANES];
        let mut prev_z = [Iq::<S>::default(); 2];
        let mut unwrapped = [S::splat(0.0); 2];
        let mut n: u64 = 0;
        let report_every = (65_536 / m as u64).max(1);
        for k in 0..n_out {
            let mut out = None;
            for _ in 0..m {
                out = self.step(n, probe.as_deref_mut());
                n += 1;
            }
            // All decimators share factor and phase, so they output on the same input sample.
            let Some((z, r)) = out else { continue };
            if let Some(p) = probe.as_deref_mut() {
                p.record_decimated(k, &z, &r, self.kind);
            }
            if k % report_every == 0 {
                progress(n);
            }
            if k < n_settle {
                prev_z = z;
                continue;
            }
            let j = k - n_settle;
            let w = S::from_fn(|i| {
                let p = &points[i.min(lanes - 1)];
                window_weight(j, p)
            });
            for i in 0..lanes {
                weight_sum[i] += w.lane(i);
            }
            match (self.kind, self.table) {
                (ExperimentKind::Coriolis, false) => {
                    for md in 0..2 {
                        acc.ch[2 * md].add(w * z[md].i);
                        acc.ch[2 * md + 1].add(w * z[md].q);
                    }
                }
                (ExperimentKind::Coriolis, true) => {
                    // Phase lag of z, unwrapped, demodulated at the table frequency.
                    // Reference phase of the table at the input sample this output stands for.
                    let n_in = (k * m as u64 + m as u64 - 1) as f64;
                    let (ts, tc) =
                        detmath::sin_cos_turns(n_in * self.table_nco.f_hz() / self.fs_hz);
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
                (ExperimentKind::Rotating, _) => {
                    let o = self.mix2.tick((z[0], r));
                    let o2 = self.mix2.tick((z[1], r));
                    for (base, o) in [(0, o), (4, o2)] {
                        acc.ch[base].add(w * o.c.i);
                        acc.ch[base + 1].add(w * o.c.q);
                        acc.ch[base + 2].add(w * o.s.i);
                        acc.ch[base + 3].add(w * o.s.q);
                    }
                }
            }
        }
        progress(n);
        (0..lanes)
            .map(|i| {
                let v = |c: usize| acc.ch[c].value().lane(i) / weight_sum[i];
                let ph = |c: usize| Complex64::new(v(c), v(c + 1));
                match (self.kind, self.table) {
                    (ExperimentKind::Coriolis, false) => LaneResult {
                        z: [ph(0), ph(2)],
                        ..Default::default()
                    },
                    (ExperimentKind::Coriolis, true) => LaneResult {
                        table_phase: [ph(0), ph(2)],
                        ..Default::default()
                    },
                    (ExperimentKind::Rotating, _) => LaneResult {
                        c: [ph(0), ph(4)],
                        s: [ph(2), ph(6)],
                        ..Default::default()
                    },
                }
            })
            .collect()
    }

    /// One input sample through the whole chain; returns the decimated stage-1 outputs and
    /// the filtered modulation references when the decimators produce them.
    #[inline(always)]
    fn step(&mut self, n: u64, probe: Option<&mut Probe>) -> Option<([Iq<S>; 2], [S; 2])> {
        let c = self.carrier.tick(());
        let cq = self.shifter.apply(c);
        let mods: [Complex64; MAX_LANES] = [
            self.modulation[0].tick(()),
            self.modulation[1].tick(()),
            self.modulation[2].tick(()),
            self.modulation[3].tick(()),
        ];
        let mod_cos = S::from_fn(|i| mods[i].re);
        let mod_sin = S::from_fn(|i| mods[i].im);
        let drive = self.am.tick(AmInput {
            carrier_i: S::splat(c.re),
            carrier_q: S::splat(cq.re),
            mod_cos,
            mod_sin,
        });
        let u = [self.dac[0].tick(drive[0]), self.dac[1].tick(drive[1])];
        let p = if self.table {
            let t = self.table_nco.tick(());
            self.plant.tick_with_rate(u, self.rate * S::splat(t.im))
        } else {
            self.plant.tick(u)
        };
        let y = [
            self.tia[0].tick(p.current[0]),
            self.tia[1].tick(p.current[1]),
        ];
        let z = [self.mix1[0].tick((y[0], c)), self.mix1[1].tick((y[1], c))];
        if let Some(pr) = probe {
            pr.record_full(n, &u, &p, &y, &z);
        }
        let i1 = self.lp[0].tick(z[0].i);
        let q1 = self.lp[1].tick(z[0].q);
        let i2 = self.lp[2].tick(z[1].i);
        let q2 = self.lp[3].tick(z[1].q);
        let rc = self.lp_ref[0].tick(mod_cos);
        let rs = self.lp_ref[1].tick(mod_sin);
        match (i1, q1, i2, q2, rc, rs) {
            (Some(i1), Some(q1), Some(i2), Some(q2), Some(rc), Some(rs)) => {
                Some(([Iq::new(i1, q1), Iq::new(i2, q2)], [rc, rs]))
            }
            _ => None,
        }
    }
}

/// Weight of decimated sample `j` (counted from the end of settling) in a lane's window.
#[inline]
fn window_weight(j: u64, p: &Point) -> f64 {
    if p.frac < 0.0 {
        // Hann over n_avg samples (frac < 0 marks it).
        if j < p.n_avg {
            let (s, _) = detmath::sin_cos_turns(0.5 * (j as f64 + 0.5) / p.n_avg as f64);
            s * s
        } else {
            0.0
        }
    } else if j < p.n_avg {
        1.0
    } else if j == p.n_avg {
        p.frac
    } else {
        0.0
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
