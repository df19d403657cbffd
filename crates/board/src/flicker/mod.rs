//! The board's flicker (1/f) sources (issue 14 point 2), on streams of their own (so turning
//! them on leaves the white noise's bits as they were):
//!
//! * the TIA's voltage noise above its corner, referred to the input like its white part
//!   (`(e_n / R)^2 corner / f`), drawn every input sample: only its density near the carrier
//!   reaches the read-out;
//! * the drive amplitude (relative) and phase of each drive, and the carrier's phase, all
//!   slow: drawn once per decimation block at the output rate (their band ends at half of
//!   it) and held over the block. The carrier's phase moves the drives and the stage-1
//!   demodulation alike; a drive's moves only that drive.
//!
//! Every source is a seeded [`Flicker`] started in its stationary state, lane-parallel like
//! the white noise, so a lane gives the bits of that point alone.

mod lane_rng;
mod tia;

use crate::params::{BoardParams, NoiseParams};
use gyroemu_core::detmath::sin_cos;
use gyroemu_core::flicker::{Flicker, FlickerParams};
use gyroemu_core::{ParamResult, Sample, Stage};
use lane_rng::LaneRng;
use tia::TiaBlock;

/// Salt of the flicker streams' seeds (apart from the white noise's).
const FLICKER_SALT: u64 = 0xF11C_4E25_0000_0001;

/// One source: its generator, or nothing when its level is 0.
type Source<S> = Option<Flicker<S>>;

/// The slow sources' values over one decimation block, per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockFlicker<S> {
    /// `1 + a_k`: each drive's relative amplitude.
    pub(crate) amplitude: [S; 2],
    /// `(cos, sin)` of the carrier's phase plus drive k's phase.
    pub(crate) drive_rot: [(S, S); 2],
    /// `(cos, sin)` of the carrier's phase (the demodulation's).
    pub(crate) carrier_rot: (S, S),
}

/// Every flicker source of one board (one point per lane).
#[derive(Clone, Debug)]
pub(crate) struct FlickerSources<S: Sample> {
    rng: LaneRng,
    tia: [Source<S>; 2],
    amplitude: [Source<S>; 2],
    phase: [Source<S>; 2],
    carrier: Source<S>,
    /// The values of the block running now.
    pub(crate) block: BlockFlicker<S>,
    /// The TIA sources' values over the block running now, or nothing (drawn per sample).
    tia_block: Option<TiaBlock<S>>,
    /// The slow sources' Gaussians drawn in one fill per stream set (else one `pair` per
    /// source, as the reference board draws them: the same bits).
    batch_slow: bool,
}

/// The slow sources: two drive amplitudes, two drive phases, the carrier's phase.
pub(super) const SLOW: usize = 5;

/// Source `s`'s next value from `w[*k]` (then `*k` moves on), or 0 when it is off (it
/// takes nothing).
#[inline(always)]
fn tick_next<S: Sample>(s: &mut Source<S>, w: &[S; SLOW], k: &mut usize) -> S {
    match s {
        Some(f) => {
            *k += 1;
            f.tick(w[*k - 1])
        }
        None => S::splat(0.0),
    }
}

/// `(cos, sin)` of `x` in each lane (one `sin_cos` per lane).
#[inline(always)]
fn rot<S: Sample>(x: S) -> (S, S) {
    let (mut co, mut si) = ([0.0; 8], [0.0; 8]);
    for l in 0..S::LANES {
        (si[l], co[l]) = sin_cos(x.lane(l));
    }
    (S::load(&co[..S::LANES]), S::load(&si[..S::LANES]))
}

impl<S: Sample> FlickerSources<S> {
    /// The sources `p` asks for, lane `i` on stream `streams[i]` (lanes past the end repeat
    /// the last); `None` when there are none. The TIA's are drawn a decimation block at a time
    /// (the same bits as [`FlickerSources::per_sample`]).
    pub(crate) fn new(p: &BoardParams, streams: &[u64]) -> ParamResult<Option<Self>> {
        let mut f = Self::per_sample(p, streams)?;
        if let Some(f) = f.as_mut() {
            f.batch_slow = true;
            if let [Some(f0), Some(f1)] = &f.tia {
                f.tia_block = Some(TiaBlock::new(p.decimation, [f0, f1]));
            }
        }
        Ok(f)
    }

    /// [`FlickerSources::new`] with the TIA's sources drawn and run one sample at a time and
    /// the slow sources' Gaussians one `pair` each, as the reference board does: what the
    /// block-wise draws are checked against.
    pub(crate) fn per_sample(p: &BoardParams, streams: &[u64]) -> ParamResult<Option<Self>> {
        let Some(n) = p.noise.filter(NoiseParams::has_flicker) else {
            return Ok(None);
        };
        let mut rng = LaneRng::new(n.seed ^ FLICKER_SALT, streams);
        let (fs, fs_out) = (p.fs_hz(), p.fs_out_hz());
        let [tia_s1, amplitude_s1, phase_s1, carrier_s1] =
            n.flicker_psds_at_1hz(p.tia.gain_ohm).map(|(_, s1)| s1);
        let fast = |s1: f64| FlickerParams {
            fs_hz: fs,
            psd_at_1hz: s1,
            f_lo_hz: n.flicker_f_lo_hz,
            f_hi_hz: 0.5 * fs,
        };
        let slow = |s1: f64| FlickerParams {
            fs_hz: fs_out,
            psd_at_1hz: s1,
            f_lo_hz: n.flicker_f_lo_hz,
            f_hi_hz: 0.5 * fs_out,
        };
        let mut source = |params: FlickerParams| -> ParamResult<Source<S>> {
            if params.psd_at_1hz == 0.0 {
                return Ok(None);
            }
            Flicker::stationary(&params, || rng.pair::<S>().0).map(Some)
        };
        let tia = [source(fast(tia_s1))?, source(fast(tia_s1))?];
        let amplitude = [source(slow(amplitude_s1))?, source(slow(amplitude_s1))?];
        let phase = [source(slow(phase_s1))?, source(slow(phase_s1))?];
        let carrier = source(slow(carrier_s1))?;
        let one = (S::splat(1.0), S::splat(0.0));
        Ok(Some(Self {
            rng,
            tia,
            amplitude,
            phase,
            carrier,
            block: BlockFlicker {
                amplitude: [S::splat(1.0); 2],
                drive_rot: [one; 2],
                carrier_rot: one,
            },
            tia_block: None,
            batch_slow: false,
        }))
    }

    /// Draws the slow sources' next values (at the start of a decimation block), in a fixed
    /// order: amplitude 1, 2, phase 1, 2, carrier phase (a source that is off draws nothing).
    /// Compiled for the lane type's instructions, as the sample loop is (eight lanes: the
    /// filters' multiply-adds inline), with the block's Gaussians in one fill per stream set.
    pub(crate) fn next_block(&mut self) {
        S::with_target_features(
            #[inline(always)]
            || self.next_block_here(),
        );
    }

    #[inline(always)]
    fn next_block_here(&mut self) {
        let mut w = [S::splat(0.0); SLOW];
        let on = self.slow().map(Option::is_some);
        if self.batch_slow {
            self.rng
                .firsts_into(&mut w[..on.iter().filter(|&&o| o).count()]);
        } else {
            // The reference: one pair per source that is on, in the drawing order.
            let mut k = 0;
            for o in on {
                if o {
                    w[k] = self.rng.pair::<S>().0;
                    k += 1;
                }
            }
        }
        // Helpers, not closures: a closure the inliner leaves out of line loses the lane
        // type's instructions (each multiply-add of an eight-lane filter became a call).
        let mut k = 0;
        let a = [
            tick_next(&mut self.amplitude[0], &w, &mut k),
            tick_next(&mut self.amplitude[1], &w, &mut k),
        ];
        let phi = [
            tick_next(&mut self.phase[0], &w, &mut k),
            tick_next(&mut self.phase[1], &w, &mut k),
        ];
        let phi_c = tick_next(&mut self.carrier, &w, &mut k);
        self.block = BlockFlicker {
            amplitude: [S::splat(1.0) + a[0], S::splat(1.0) + a[1]],
            drive_rot: [rot(phi_c + phi[0]), rot(phi_c + phi[1])],
            carrier_rot: rot(phi_c),
        };
        // Then the block's first TIA values: per sample one pair from the same streams,
        // after the slow sources' draws, as `tia_current` draws them one sample at a time.
        if let (Some(b), [Some(f0), Some(f1)]) = (&mut self.tia_block, &mut self.tia) {
            b.left = b.block;
            b.refill(&mut self.rng, [f0, f1]);
        }
    }

    /// The slow sources in their drawing order.
    #[inline(always)]
    fn slow(&self) -> [&Source<S>; SLOW] {
        let [a0, a1] = &self.amplitude;
        let [p0, p1] = &self.phase;
        [a0, a1, p0, p1, &self.carrier]
    }

    /// The TIA's sources run joined in eight lanes (`tia::Joined`).
    pub(crate) fn tia_joined(&self) -> bool {
        self.tia_block.as_ref().is_some_and(TiaBlock::joined)
    }

    /// Makes the TIA flicker of up to the rest of the chunk ready (running the block's next
    /// chunk if the last is used up) and returns how many samples it covers: a loop then
    /// reads them with [`FlickerSources::tia_current_ready`], with no call per sample.
    /// `u64::MAX` when the board has no TIA source or draws it per sample (`per_sample`).
    /// Call only within a decimation block (after `next_block`, before its last sample).
    #[inline(always)]
    pub(crate) fn tia_ready(&mut self) -> u64 {
        if let (Some(b), [Some(f0), Some(f1)]) = (&mut self.tia_block, &mut self.tia) {
            if b.pos == b.len {
                b.refill(&mut self.rng, [f0, f1]);
            }
            return (b.len - b.pos) as u64;
        }
        u64::MAX
    }

    /// [`FlickerSources::tia_current`] within what [`FlickerSources::tia_ready`] made ready:
    /// the same values, with no refill (a call) in the loop that reads them. Zero without
    /// TIA sources; a board that draws them per sample must use `tia_current`.
    #[inline(always)]
    pub(crate) fn tia_current_ready(&mut self) -> [S; 2] {
        debug_assert!(self.tia[0].is_none() || self.tia_block.is_some());
        match &mut self.tia_block {
            Some(b) => {
                debug_assert!(b.pos < b.len, "read past what tia_ready made ready");
                let i = b.pos;
                b.pos += 1;
                b.at(i)
            }
            None => [S::splat(0.0); 2],
        }
    }

    /// This sample's flicker of the TIA's input-referred current, per mode (A).
    #[inline(always)]
    pub(crate) fn tia_current(&mut self) -> [S; 2] {
        if self.tia[0].is_none() {
            return [S::splat(0.0); 2];
        }
        if self.tia_block.is_some() {
            // Drawn a chunk at a time: the kernel's pair, one sample at a time.
            self.tia_ready();
            return self.tia_current_ready();
        }
        let (w0, w1) = self.rng.pair::<S>();
        let mut out = [S::splat(0.0); 2];
        for (k, w) in [w0, w1].into_iter().enumerate() {
            if let Some(f) = &mut self.tia[k] {
                out[k] = f.tick(w);
            }
        }
        out
    }
}

/// `(re, im)` of the carrier phasor `c` turned by `(cos, sin)` of an angle, per lane.
#[inline(always)]
pub(crate) fn turn<S: Sample>(c_re: f64, c_im: f64, (co, si): (S, S)) -> (S, S) {
    let (re, im) = (S::splat(c_re), S::splat(c_im));
    (re * co - im * si, im * co + re * si)
}
