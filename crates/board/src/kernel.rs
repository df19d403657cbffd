//! The fused sample loop: every stage on every input sample with no buffers in between (but
//! the eight-lane low-pass pass, [`Board::block`]), one monomorphised loop per experiment
//! shape, noise shape and plant step. Its results equal the reference board's
//! (`reference.rs`, plain `Stage::tick` calls) bit for bit.

use crate::board::{is_table, Board, CORIOLIS, RATE_TABLE, RATE_TABLE_LANES, ROTATING, RUN};
use crate::fault::NonFinite;
use crate::flicker::{turn, BlockFlicker};
use crate::health::{Counters, Health, ADC_CLIP, ADC_ZERO, DAC_CLIP, DAC_ZERO, TIA_RAIL};
use crate::params::Shape;
use crate::point::{LaneResult, Point, RunOptions, RunOutput};
use crate::probe::Probe;
use crate::refill::Prepared;
use core::mem::MaybeUninit;
use gyroemu_am::AmInput;
use gyroemu_core::{Complex64, Sample, Stage};
use gyroemu_lpf::Averager;
use gyroemu_mixer::{
    table_channel, table_reference, Iq, Stage1Mixer, MAX_TABLE_HARMONIC, TABLE_CHANNELS,
    TABLE_HARMONICS,
};
use std::sync::atomic::Ordering;

/// Input samples between progress reports (and cancel checks).
const REPORT_EVERY_IN: u64 = 65_536;

impl<S: Sample> Board<S> {
    /// Picks the sample loop of this board's shape, noise and plant step. Returns the
    /// decimated index at which an output stopped being finite, if one did.
    pub(crate) fn dispatch(
        &mut self,
        n_settle: u64,
        points: &[Point],
        opts: RunOptions,
        refills: &[Prepared],
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, u64> {
        self.ran = true;
        macro_rules! by_plant {
            ($k:expr) => {
                match (self.imperfect, self.plant_decoupled()) {
                    (false, false) => self
                        .sample_loop::<$k, false, false>(n_settle, points, opts, refills, progress),
                    (false, true) => self
                        .sample_loop::<$k, false, true>(n_settle, points, opts, refills, progress),
                    (true, false) => self
                        .sample_loop::<$k, true, false>(n_settle, points, opts, refills, progress),
                    (true, true) => self
                        .sample_loop::<$k, true, true>(n_settle, points, opts, refills, progress),
                }
            };
        }
        match self.shape {
            Shape::Coriolis => by_plant!(CORIOLIS),
            Shape::RateTable { .. } if !self.table_shared => by_plant!(RATE_TABLE_LANES),
            Shape::RateTable { .. } => by_plant!(RATE_TABLE),
            Shape::Rotating => by_plant!(ROTATING),
        }
    }

    /// One block of the checking replay, in the run's plant shape (inlined into
    /// [`Board::locate_fault`]'s loop, compiled like the sample loop).
    #[inline(always)]
    pub(crate) fn replay_block(&mut self, n0: u64, probe: &mut Probe) {
        let mut counts = Counters::default();
        macro_rules! by_plant {
            ($k:expr) => {
                if self.plant_decoupled() {
                    self.block::<$k, true, true>(n0, Some(probe), &mut counts);
                } else {
                    self.block::<$k, true, false>(n0, Some(probe), &mut counts);
                }
            };
        }
        match self.shape {
            Shape::Coriolis => by_plant!(CORIOLIS),
            Shape::RateTable { .. } if !self.table_shared => by_plant!(RATE_TABLE_LANES),
            Shape::RateTable { .. } => by_plant!(RATE_TABLE),
            Shape::Rotating => by_plant!(ROTATING),
        }
    }

    /// The sample loop of experiment shape `K`; `NOISY`: the noise sources and the ADC are in
    /// the chain; `DECOUPLED`: the plant takes its sparse step (decoupled, or split by mode on
    /// a rate table: [`Board::plant_decoupled`]).
    ///
    /// Its own function per shape: inlined into the dispatcher beside the other shapes, the
    /// sample loop's registers were allocated worse (measurably slower).
    ///
    /// It enters through [`Sample::with_target_features`], so an eight-lane board's loop is
    /// compiled for AVX-512 with every operation inlined.
    #[inline(never)]
    fn sample_loop<const K: u8, const NOISY: bool, const DECOUPLED: bool>(
        &mut self,
        n_settle: u64,
        points: &[Point],
        opts: RunOptions,
        refills: &[Prepared],
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, u64> {
        S::with_target_features(
            #[inline(always)]
            || {
                self.sample_loop_body::<K, NOISY, DECOUPLED>(
                    n_settle, points, opts, refills, progress,
                )
            },
        )
    }

    /// [`Board::sample_loop`]'s body.
    #[allow(clippy::needless_range_loop)] // mode and lane indices address parallel arrays
    #[inline(always)]
    fn sample_loop_body<const K: u8, const NOISY: bool, const DECOUPLED: bool>(
        &mut self,
        n_settle: u64,
        points: &[Point],
        mut opts: RunOptions,
        refills: &[Prepared],
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, u64> {
        let lanes = self.lanes;
        let m = self.decimation as u64;
        let refilled_end = refills
            .iter()
            .map(|p| p.r.at_block + n_settle + p.r.point.window.samples());
        let n_out = (n_settle + points.iter().map(|p| p.window.samples()).max().unwrap_or(1))
            .max(refilled_end.max().unwrap_or(0));
        let windows: Vec<_> = points.iter().take(lanes).map(|p| p.window).collect();
        let channels = if K == ROTATING { 8 } else { 4 };
        let mut avg = Averager::<S, 8>::new(&windows, channels)
            .expect("the points' windows are valid and one per lane");
        let mut table_avg = Averager::<S, TABLE_CHANNELS>::new(
            &windows,
            if is_table(K) {
                self.table_mix.channels()
            } else {
                0
            },
        )
        .expect("the points' windows are valid and one per lane");
        let mut tx = [S::splat(0.0); TABLE_CHANNELS];
        let report_every = (REPORT_EVERY_IN / m).max(1);
        let mut read_next = vec![0usize; lanes];
        let mut early: Vec<Vec<LaneResult>> = vec![Vec::new(); lanes];
        let mut series: Vec<Vec<[f64; 8]>> = vec![Vec::new(); lanes];
        let mut series_acc = [S::splat(0.0); 8];
        // Each lane counts its own run only, so its counts do not depend on its group.
        let mut lane_end: Vec<u64> = points
            .iter()
            .take(lanes)
            .map(|p| n_settle + p.window.samples())
            .collect();
        let mut health: Vec<Health> = lane_end
            .iter()
            .map(|&e| Health {
                samples: e * m,
                ..Default::default()
            })
            .collect();
        // Each lane's points before its last, when refilled (noiseless: only the samples
        // counted); the next refill.
        let mut refilled: Vec<Vec<LaneResult>> = vec![Vec::new(); lanes];
        let mut next_refill = 0;
        let mut counts = Counters::<S>::default();
        // Each lane's totals, and 1 in the lanes still counting (until the next lane's end).
        let mut totals = Counters::<S>::default();
        let counting = |k: u64, lane_end: &[u64]| {
            let active = S::from_fn(|i| f64::from(u8::from(i < lanes && k < lane_end[i])));
            let until = lane_end.iter().copied().filter(|&e| e > k).min();
            (active, until.unwrap_or(u64::MAX))
        };
        let (mut active, mut recount_at) = counting(0, &lane_end);
        // The decimated sample a cancel stopped the run at (its block not averaged).
        let mut stopped_at = None;
        // The block after which the probe is handed on, if it is asked for.
        let hand_on_at = match (opts.on_probe_recorded, opts.probe.as_deref()) {
            (Some(_), Some(p)) => p.recorded_at(m),
            _ => None,
        }
        .unwrap_or(u64::MAX);
        for k in 0..n_out {
            let n0 = k * m;
            // Lanes whose points have ended take their next ones here (checked: at exact
            // re-sets, after their points' ends; noiseless boards only, so the noisy loops
            // are compiled without the test).
            while let Some(p) = refills
                .get(next_refill)
                .filter(|p| !NOISY && p.r.at_block == k)
            {
                let (i, w) = (p.r.lane, p.r.point.window);
                refilled[i].push(LaneResult {
                    health: health[i],
                    ..lane_result::<K>(&avg.mean(i), &table_avg.mean(i), self.table_mix.harmonics())
                });
                self.refill_lane(p, n0);
                for restart in [avg.restart_lane(i, w, k), table_avg.restart_lane(i, w, k)] {
                    restart.expect("a refill starts its window after every sample pushed");
                }
                lane_end[i] = k + n_settle + w.samples();
                health[i] = Health {
                    samples: (n_settle + w.samples()) * m,
                    ..Default::default()
                };
                next_refill += 1;
            }
            // The recording path only for blocks that touch the dump window.
            let (z, r) = match opts.probe.as_deref_mut() {
                Some(p) if p.wants_block(n0, m) => {
                    self.block::<K, NOISY, DECOUPLED>(n0, Some(p), &mut counts)
                }
                _ => self.block::<K, NOISY, DECOUPLED>(n0, None, &mut counts),
            };
            if NOISY {
                if let Some(p) = opts.probe.as_deref_mut() {
                    p.count_block(n0, m, k, &counts);
                }
                if k >= recount_at {
                    (active, recount_at) = counting(k, &lane_end);
                }
                totals.add_where(&counts, active);
                counts = Counters::default();
            }
            // Each on its own: a sum of large finite values could overflow and false-alarm.
            if ![z[0].i, z[0].q, z[1].i, z[1].q]
                .iter()
                .all(|v| v.all_finite())
            {
                return Err(k);
            }
            if let Some(p) = opts.probe.as_deref_mut() {
                p.record_decimated(k, &z, &r, K == ROTATING);
            }
            if k == hand_on_at {
                hand_on_probe(&mut opts);
            }
            if k % report_every == 0 {
                progress(n0 + m);
                if self
                    .cancel
                    .as_ref()
                    .is_some_and(|c| c.load(Ordering::Relaxed))
                {
                    stopped_at = Some(k);
                    break;
                }
            }
            if k < n_settle {
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
                RATE_TABLE | RATE_TABLE_LANES => {
                    // z at every table harmonic, against the table phase of the input sample
                    // this output stands for.
                    tx = self.table_mix.tick((z, self.table_base(n0 + m - 1)));
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
            for (i, reads) in opts.early_reads.iter().enumerate().take(lanes) {
                while let Some(&(n, frac)) = reads.get(read_next[i]) {
                    if n != j {
                        break;
                    }
                    let table = if is_table(K) {
                        table_avg.mean_if_ended(i, frac, &tx)
                    } else {
                        [0.0; TABLE_CHANNELS]
                    };
                    early[i].push(lane_result::<K>(
                        &avg.mean_if_ended(i, frac, &x),
                        &table,
                        self.table_mix.harmonics(),
                    ));
                    read_next[i] += 1;
                }
            }
            if opts.series_block > 0 {
                for c in 0..8 {
                    series_acc[c] += x[c];
                }
                if (j + 1).is_multiple_of(opts.series_block) {
                    let scale = 1.0 / opts.series_block as f64;
                    for (i, rows) in series.iter_mut().enumerate() {
                        rows.push(core::array::from_fn(|c| series_acc[c].lane(i) * scale));
                    }
                    series_acc = [S::splat(0.0); 8];
                }
            }
            push_average(&mut avg, &x);
            if is_table(K) {
                push_average(&mut table_avg, &tx);
            }
        }
        progress(n_out * m);
        for (i, h) in health.iter_mut().enumerate() {
            totals.drain_into(i, h);
        }
        // A lane is complete when its window (and its counts) ended before the stop: every
        // later sample has weight zero, and adding 0 leaves a compensated sum's value as it
        // is, so the lane holds the bits an uninterrupted run returns.
        let complete = lane_end
            .iter()
            .map(|&e| stopped_at.is_none_or(|k| e <= k))
            .collect();
        Ok(RunOutput {
            lanes: (0..lanes)
                .map(|i| LaneResult {
                    health: health[i],
                    ..lane_result::<K>(&avg.mean(i), &table_avg.mean(i), self.table_mix.harmonics())
                })
                .collect(),
            early_reads: early,
            series,
            complete,
            refilled,
        })
    }

    /// One decimation block of input samples `n0 .. n0 + M` through the whole chain, fused
    /// (every stage on every sample; a two-pass variant of the whole chain through an L1
    /// buffer measured slower), in runs of at most [`RUN`] samples with no call inside. In
    /// eight lanes the presets' low-pass pair runs as each run's second pass. Returns the
    /// low-passed stage-1 outputs at the block's last sample (the decimated output) and the
    /// modulation references (cos, sin of Omega t) at that same sample.
    #[inline(always)]
    pub(crate) fn block<const K: u8, const NOISY: bool, const DECOUPLED: bool>(
        &mut self,
        n0: u64,
        mut probe: Option<&mut Probe>,
        counts: &mut Counters<S>,
    ) -> ([Iq<S>; 2], [S; 2]) {
        let zero = S::splat(0.0);
        // Lanes per row of the board's normals (`Board::new`: one or two four-lane sets).
        const { assert!(S::LANES <= 8) };
        let noise_width: usize = S::LANES.next_multiple_of(4);
        let mut out = ([Iq::<S>::default(); 2], [zero; 2]);
        let m = self.decimation as u64;
        let noisy = NOISY && self.noise_on;
        // The slow flicker sources move once per block and hold over it.
        let fb = match &mut self.flicker {
            Some(f) if NOISY => {
                f.next_block();
                Some(f.block)
            }
            _ => None,
        };
        // The presets' low-pass (two biquads) runs the block with its states in registers.
        let mut pair = self.lp.hold_pair();
        // In eight lanes with no probe, the pair runs as a second pass over each run's mixer
        // outputs, its 16 states in registers: in one pass they did not fit beside the
        // chain's, and their spills (16 stores a sample) bounded eight lanes where a 512-bit
        // store takes two 256-bit slots (Intel's cores; the `lane_ceiling` example). Four
        // lanes have 16 registers, too few for the pair alone: they keep one pass.
        let two_pass = S::LANES == 8 && probe.is_none() && pair.is_some();
        // The run's mixer outputs: a local left uninitialised. Zeroed, it was cleared every
        // block (a 16 KB memset); as a field of the board, the eight-lane chains ran up to
        // 11 % slower (Xeon), presumably because a store into the board may alias its other
        // fields for the compiler, which then keeps more of their values in memory.
        let mut lp_run = [const { MaybeUninit::<[S; 4]>::uninit() }; RUN];
        let mut j0 = 0;
        // In runs that the drawn-ahead normals cover: drawing more is a call, kept out of the
        // per-sample loop.
        while j0 < m {
            let mut run = if noisy {
                self.noise.normals.ready(m - j0)
            } else {
                m - j0
            };
            // Nor do the oscillators' exact re-sets run inside it: with no call in the loop
            // the compiler keeps the states in registers (on a CPU with half the 512-bit
            // store rate, as Intel's, the spills bounded eight lanes).
            run = run.min(u64::from(self.carrier.ready()));
            if K == ROTATING {
                run = run.min(u64::from(self.modulation.ready()));
            }
            if is_table(K) {
                run = run.min(u64::from(if K == RATE_TABLE_LANES {
                    self.table_lanes.ready()
                } else {
                    self.table_nco.ready()
                }));
            }
            // Nor does the TIA flicker's next chunk run inside it.
            if let (Some(f), true) = (&mut self.flicker, fb.is_some()) {
                run = run.min(f.tia_ready());
            }
            run = run.min(RUN as u64);
            let base = self.noise.normals.pos();
            for j in j0..j0 + run {
                let (c_re, c_im) = self.carrier.tick_ready();
                // The rotating drive uses only the in-phase carrier.
                let cq = if K == ROTATING {
                    0.0
                } else {
                    self.shifter.apply(Complex64::new(c_re, c_im)).re
                };
                let (mod_cos, mod_sin) = if K == ROTATING {
                    self.modulation.tick_ready()
                } else {
                    (zero, zero)
                };
                // The drive's quadrature copy passes the (imperfect) phase shifter:
                // sin(Omega t - eps); the stage-2 references stay exact.
                let drive_sin = match self.mod_shift {
                    Some((ce, se)) if K == ROTATING => mod_sin * ce - mod_cos * se,
                    _ => mod_sin,
                };
                let drive = match &fb {
                    None => self.am.tick(AmInput {
                        carrier_i: S::splat(c_re),
                        carrier_q: S::splat(cq),
                        mod_cos,
                        mod_sin: drive_sin,
                    }),
                    Some(b) => flicker_drive::<K, S>(
                        &mut self.am,
                        &self.shifter,
                        b,
                        (c_re, c_im),
                        (mod_cos, drive_sin),
                    ),
                };
                let mut u = drive;
                for md in 0..2 {
                    u[md] = match self.dac[md].quantizer() {
                        // The same bits as the DAC's tick, with its clipped and zero samples counted.
                        Some(q) if NOISY => {
                            let (clip, zeros) = counts.0.split_at_mut(DAC_ZERO);
                            q.quantize_counting_fast(
                                drive[md],
                                &mut clip[DAC_CLIP + md],
                                &mut zeros[md],
                            )
                        }
                        _ => self.dac[md].tick(drive[md]),
                    };
                }
                // This sample's normals: force on each mode, then input current on each mode.
                let nz: [S; 4] = if noisy {
                    let row = base + 4 * (j - j0) as usize;
                    core::array::from_fn(|c| S::load(self.noise.normals.row(row + c, noise_width)))
                } else {
                    [zero; 4]
                };
                if noisy {
                    // Brownian force on each mode, after the DAC (it acts on the proof mass).
                    u[0] = nz[0].mul_add(self.noise.sigma_force[0], u[0]);
                    u[1] = nz[1].mul_add(self.noise.sigma_force[1], u[1]);
                }
                let mut p = if is_table(K) {
                    // The shared table is the cheaper in the loop; the lanes' only where
                    // they differ.
                    let sin_t = if K == RATE_TABLE_LANES {
                        self.table_lanes.tick_ready().1
                    } else {
                        S::splat(self.table_nco.tick_ready().1)
                    };
                    let rate = self.rate * sin_t;
                    if DECOUPLED {
                        self.plant.tick_with_rate_split(u, rate)
                    } else {
                        self.plant.tick_with_rate(u, rate)
                    }
                } else if DECOUPLED {
                    self.plant.tick_decoupled(u)
                } else {
                    self.plant.tick(u)
                };
                if noisy {
                    // Amplifier noise, referred to the TIA input.
                    p.current[0] = nz[2].mul_add(self.noise.sigma_current[0], p.current[0]);
                    p.current[1] = nz[3].mul_add(self.noise.sigma_current[1], p.current[1]);
                }
                if let (Some(f), true) = (&mut self.flicker, fb.is_some()) {
                    // The TIA voltage noise's flicker, referred to the input likewise.
                    let t = f.tia_current_ready();
                    p.current[0] += t[0];
                    p.current[1] += t[1];
                }
                let mut y = [
                    self.tia[0].tick(p.current[0]),
                    self.tia[1].tick(p.current[1]),
                ];
                if NOISY {
                    let c = &mut counts.0;
                    for md in 0..2 {
                        if self.tia[md].has_rails() {
                            c[TIA_RAIL + md] += self.tia[md].rail_flags(y[md]);
                        }
                    }
                    if let Some(adc) = &self.adc {
                        let (clip, zeros) = c.split_at_mut(ADC_ZERO);
                        for md in 0..2 {
                            y[md] = adc[md].quantize_counting_fast(
                                y[md],
                                &mut clip[ADC_CLIP + md],
                                &mut zeros[md],
                            );
                        }
                    }
                }
                // Both stage-1 mixers see the same carrier: when their reference phases agree
                // (always, as built) they share one set of carrier factors.
                let carrier = Complex64::new(c_re, c_im);
                let (f0, f1) = match &fb {
                    // The carrier's phase flicker turns the demodulation too, lane by lane
                    // (the board's mixers have a zero reference phase).
                    Some(b) => {
                        let (cr, ci) = turn(c_re, c_im, b.carrier_rot);
                        let f = (cr + cr, -(ci + ci));
                        (f, f)
                    }
                    None => {
                        let f0 = self.mix1[0].factors(carrier);
                        let f1 = if self.mix1_same_ref {
                            f0
                        } else {
                            self.mix1[1].factors(carrier)
                        };
                        (f0, f1)
                    }
                };
                let z = [Stage1Mixer::mix(y[0], f0), Stage1Mixer::mix(y[1], f1)];
                if let Some(pr) = probe.as_deref_mut() {
                    pr.record_full(n0 + j, &u, &p, &y, &z);
                }
                let zs = [z[0].i, z[0].q, z[1].i, z[1].q];
                if two_pass {
                    lp_run[(j - j0) as usize].write(zs);
                    if j + 1 == m {
                        out.1 = [mod_cos, mod_sin];
                    }
                    continue;
                }
                let [i1, q1, i2, q2] = match &mut pair {
                    Some(lp) => lp.tick(zs),
                    None => self.lp.tick(zs),
                };
                let lp = [Iq::new(i1, q1), Iq::new(i2, q2)];
                if let Some(pr) = probe.as_deref_mut() {
                    pr.check_lowpass(n0 + j, &lp);
                }
                // Only the block's last sample is the decimated output: kept on every sample,
                // it cost eight lanes six stores a sample (the loop holds no register for
                // it). Four lanes keep it on every sample: the test cost their Coriolis chain
                // 5 % (Xeon, 12 alternating runs), where their spills are 256-bit.
                if S::LANES != 8 || j + 1 == m {
                    out = (lp, [mod_cos, mod_sin]);
                }
            }
            if let (true, Some(lp)) = (two_pass, &mut pair) {
                for zs in &lp_run[..run as usize] {
                    // SAFETY: with `two_pass`, the first pass wrote entry `j - j0` of every
                    // sample `j` of the run, so entries `..run`.
                    let [i1, q1, i2, q2] = lp.tick(unsafe { zs.assume_init() });
                    out.0 = [Iq::new(i1, q1), Iq::new(i2, q2)];
                }
            }
            if noisy {
                self.noise.normals.advance(run);
            }
            j0 += run;
        }
        if let Some(lp) = &pair {
            self.lp.release_pair(lp);
        }
        out
    }
}

impl<S: Sample> Board<S> {
    /// `e^{-j theta}` of each lane's table at the run's input sample `n`, as `(re, im)`
    /// ([`table_reference`] at the lane's sample of the time axis, `n` past its start; once
    /// for all lanes when they share the table). Out of line (once per decimation block) and
    /// compiled like the loop.
    #[inline(never)]
    fn table_base(&self, n: u64) -> (S, S) {
        S::with_target_features(
            #[inline(always)]
            || {
                // Wrapping: a refilled lane's start is its point's less where the run took it.
                let at = |i: usize| {
                    table_reference(
                        n.wrapping_add(self.starts[i]),
                        self.table_f_hz[i],
                        self.fs_hz,
                    )
                };
                if self.table_shared {
                    let b = at(0);
                    return (S::splat(b.re), S::splat(b.im));
                }
                let b: [Complex64; crate::lanes::MAX_LANES] = core::array::from_fn(|i| {
                    if i < S::LANES {
                        at(i)
                    } else {
                        Complex64::new(0.0, 0.0)
                    }
                });
                (S::from_fn(|i| b[i].re), S::from_fn(|i| b[i].im))
            },
        )
    }

    /// Replays the run (with its `refills`) from the board as built, checking every stage's
    /// output on every sample up to block `k_bad` (where the decimated output stopped being
    /// finite), and names the first stage and sample that went non-finite.
    #[cold]
    pub(crate) fn locate_fault(&self, k_bad: u64, refills: &[Prepared]) -> NonFinite {
        let m = self.decimation as u64;
        let fallback = self.fault_at("lowpass", k_bad * m + m - 1, 0);
        let Some(pristine) = &self.pristine else {
            return fallback;
        };
        let mut board = (**pristine).clone();
        // The loop the run took.
        board.table_shared = self.table_shared;
        let mut probe = Probe::finite_check(self.lanes);
        let mut next = 0;
        S::with_target_features(
            #[inline(always)]
            || {
                for k in 0..=k_bad {
                    while let Some(p) = refills.get(next).filter(|p| p.r.at_block == k) {
                        board.refill_lane(p, k * m);
                        next += 1;
                    }
                    board.replay_block(k * m, &mut probe);
                    if let Some((stage, sample, lane)) = probe.fault() {
                        return board.fault_at(stage, sample, lane);
                    }
                }
                fallback
            },
        )
    }

    /// A fault of `stage` at input sample `n` of the run in `lane`, on the time axis of the
    /// lane's point (a lane that started late, or was refilled, counts from its point's start).
    fn fault_at(&self, stage: &'static str, n: u64, lane: usize) -> NonFinite {
        let sample = self.starts[lane].wrapping_add(n);
        NonFinite {
            stage,
            sample,
            time_s: sample as f64 / self.fs_hz,
            rate_dps: self.rate.lane(lane).to_degrees(),
        }
    }
}

/// Adds a decimated sample to an average: out of line (once per decimation block, kept apart
/// from the sample loop's registers) and compiled like the loop, the push inlined.
#[inline(never)]
fn push_average<S: Sample, const C: usize>(avg: &mut Averager<S, C>, x: &[S; C]) {
    S::with_target_features(
        #[inline(always)]
        || avg.push(x),
    )
}

/// A lane's averaged channels as the result of its experiment shape (`table`: the averaged
/// `TableMixer` channels of a rate-table run, of harmonics `-n ..= n`).
pub(crate) fn lane_result<const K: u8>(v: &[f64; 8], table: &[f64], n: usize) -> LaneResult {
    let ph = |c: usize| Complex64::new(v[c], v[c + 1]);
    match K {
        CORIOLIS => LaneResult {
            z: [ph(0), ph(2)],
            ..Default::default()
        },
        RATE_TABLE | RATE_TABLE_LANES => LaneResult {
            table_z: table_harmonics_of(table, n),
            ..Default::default()
        },
        _ => LaneResult {
            c: [ph(0), ph(4)],
            s: [ph(2), ph(6)],
            ..Default::default()
        },
    }
}

/// The per-mode harmonics `-MAX ..= MAX` of averaged `TableMixer` channels of harmonics
/// `-n ..= n` (zero beyond `n`).
pub(crate) fn table_harmonics_of(table: &[f64], n: usize) -> [[Complex64; TABLE_HARMONICS]; 2] {
    core::array::from_fn(|md| {
        core::array::from_fn(|i| {
            let h = i as isize - MAX_TABLE_HARMONIC as isize;
            if h.unsigned_abs() > n {
                return Complex64::new(0.0, 0.0);
            }
            let ch = table_channel(h, md, n);
            Complex64::new(table[ch], table[ch + 1])
        })
    })
}

/// The two drives with the slow flicker's values of the block: each drive's carrier turned by
/// the carrier's and its own phase, its amplitude scaled (the same arithmetic as the
/// modulator's on the turned carriers; the reference board does it alike).
#[inline(always)]
pub(crate) fn flicker_drive<const K: u8, S: Sample>(
    am: &mut gyroemu_am::AmModulator<S>,
    shifter: &gyroemu_nco::PhaseShifter,
    b: &BlockFlicker<S>,
    (c_re, c_im): (f64, f64),
    (mod_cos, mod_sin): (S, S),
) -> [S; 2] {
    let zero = S::splat(0.0);
    let c1 = turn(c_re, c_im, b.drive_rot[0]);
    let c2 = turn(c_re, c_im, b.drive_rot[1]);
    let d = if K == ROTATING {
        // Both drives ride the in-phase carrier, each its own.
        let d1 = am.tick(AmInput {
            carrier_i: c1.0,
            carrier_q: zero,
            mod_cos,
            mod_sin,
        });
        let d2 = am.tick(AmInput {
            carrier_i: c2.0,
            carrier_q: zero,
            mod_cos,
            mod_sin,
        });
        [d1[0], d2[1]]
    } else {
        // Re{c2 rot}: the phase shifter's rotation on mode 2's carrier.
        let r = shifter.rotation();
        let cq = c2.0 * S::splat(r.re) - c2.1 * S::splat(r.im);
        am.tick(AmInput {
            carrier_i: c1.0,
            carrier_q: cq,
            mod_cos,
            mod_sin,
        })
    };
    [d[0] * b.amplitude[0], d[1] * b.amplitude[1]]
}

/// Hands the run's probe on ([`RunOptions::on_probe_recorded`]); the run records no more.
/// Out of line: once per run, kept out of the sample loop's code.
#[cold]
#[inline(never)]
fn hand_on_probe(opts: &mut RunOptions) {
    if let (Some(hand_on), Some(p)) = (opts.on_probe_recorded, opts.probe.take()) {
        hand_on(p);
    }
}
