//! A lane-parallel oscillator for the per-sample loop: a unit phasor per lane rotated by its
//! step every sample (a complex multiply), re-set every `RESYNC` samples from the exact 64-bit
//! phase accumulator of [`Nco`]. Between re-sets the rounding of the rotation grows by at most
//! a few ulp per sample, so the output stays within ~1e-14 of the NCO's and never drifts.

use crate::nco::step_of;
use crate::trig::{phasor_of_word, phasors_in_lanes, table};
use crate::Nco;
use gyroemu_core::{f64x4, ParamError, ParamResult, Sample, Stage};

/// Samples between exact re-sets of the rotated phasor.
pub const RESYNC: u32 = 64;

/// The widest sample type's lanes (eight: f64 lanes of a 512-bit register).
const MAX_LANES: usize = 8;

/// Up to eight NCOs (one per lane) advanced together; output `(cos, sin)` per lane.
#[derive(Clone, Debug)]
pub struct RotatingNco<S: Sample> {
    re: S,
    im: S,
    rot_re: S,
    rot_im: S,
    /// Per lane: the exact phase word of the sample `count` ticks ahead (the next re-set).
    phase: [u64; MAX_LANES],
    step: [u64; MAX_LANES],
    phase0: [u64; MAX_LANES],
    step0: [u64; MAX_LANES],
    fs_hz: [f64; MAX_LANES],
    count: u32,
}

impl<S: Sample> RotatingNco<S> {
    /// Lane `i` follows `ncos[i]` from its current phase (lanes past the slice repeat the
    /// last NCO). `ncos` must not be empty.
    pub fn new(ncos: &[Nco]) -> Self {
        let pick = |i: usize| &ncos[i.min(ncos.len() - 1)];
        let phase: [u64; MAX_LANES] = core::array::from_fn(|i| pick(i).phase_word());
        let step: [u64; MAX_LANES] = core::array::from_fn(|i| pick(i).step_word());
        let fs_hz: [f64; MAX_LANES] = core::array::from_fn(|i| pick(i).fs_hz());
        let rot = |i: usize| phasor_of_word(step[i]);
        let mut s = Self {
            re: S::splat(0.0),
            im: S::splat(0.0),
            rot_re: S::from_fn(|i| rot(i).re),
            rot_im: S::from_fn(|i| rot(i).im),
            phase,
            step,
            phase0: phase,
            step0: step,
            fs_hz,
            count: 0,
        };
        s.resync();
        s
    }

    /// Changes lane `lane`'s frequency to `f_hz` (finite, `|f_hz| < fs/2` of that lane's
    /// [`Nco`]) from the next tick on, with the phase continuous; the other lanes are not
    /// touched (not a bit). The lane's phase word of the next sample is recovered exactly
    /// from the accumulator, its phasor is re-set exactly from it (as at a re-set) and its
    /// step and rotation are replaced, so from here on the lane is within ~1e-14 of an
    /// [`Nco`] given the same [`Nco::set_frequency_hz`] at the same sample. A bad lane or
    /// frequency is refused and changes nothing. [`Stage::reset`] restores the frequencies the
    /// oscillator was built with.
    pub fn set_frequency_hz(&mut self, lane: usize, f_hz: f64) -> ParamResult<()> {
        check_lane::<S>(lane)?;
        let step = step_of(f_hz, self.fs_hz[lane])?;
        let next = self.next_phase_word(lane);
        self.set_step(lane, step);
        self.phase[lane] = next.wrapping_add(step.wrapping_mul(u64::from(self.count)));
        let p = phasor_of_word(next);
        self.re = self.re.with_lane(lane, p.re);
        self.im = self.im.with_lane(lane, p.im);
        Ok(())
    }

    /// Lane `lane` steps by `step` from the next tick: its step word and its rotation, as
    /// `new` computes them (the other lanes untouched).
    fn set_step(&mut self, lane: usize, step: u64) {
        self.step[lane] = step;
        let r = phasor_of_word(step);
        self.rot_re = self.rot_re.with_lane(lane, r.re);
        self.rot_im = self.rot_im.with_lane(lane, r.im);
    }

    /// The oscillator stands at an exact re-set: every lane's phasor is computed afresh from
    /// its phase word at the next tick (after a multiple of [`RESYNC`] ticks since it was
    /// built or reset).
    pub fn at_resync(&self) -> bool {
        self.count == 0
    }

    /// Lane `lane` takes over `nco` (its phase word and step) at an exact re-set
    /// ([`RotatingNco::at_resync`]): from the next tick the lane gives the bits of a
    /// `RotatingNco` built from `nco` alone, whose re-sets fall on the same ticks. The other
    /// lanes are not touched. Refused (changing nothing) off a re-set, for a lane past
    /// `S::LANES`, or for an `nco` of another sample rate.
    pub fn set_lane_at_resync(&mut self, lane: usize, nco: &Nco) -> ParamResult<()> {
        let bad = |param: &'static str, v: String, rule: &str| {
            Err(ParamError::new("rotating_nco", param, v, rule.to_string()))
        };
        check_lane::<S>(lane)?;
        if !self.at_resync() {
            return bad(
                "count",
                self.count.to_string(),
                "a lane is replaced only at an exact re-set (ticks to it: 0)",
            );
        }
        if nco.fs_hz() != self.fs_hz[lane] {
            return bad(
                "fs_hz",
                nco.fs_hz().to_string(),
                "must be the lane's sample rate",
            );
        }
        // The next re-set computes the phasor from `phase`.
        self.phase[lane] = nco.phase_word();
        self.set_step(lane, nco.step_word());
        Ok(())
    }

    /// Lane `lane`'s realised (step-quantised) frequency, signed, in Hz (`lane < S::LANES`).
    pub fn f_hz(&self, lane: usize) -> f64 {
        (self.step[lane] as i64) as f64 * (self.fs_hz[lane] / 18_446_744_073_709_551_616.0)
    }

    /// Lane `lane`'s phase step per sample, 2^-64 turn (`lane < S::LANES`).
    pub fn step_word(&self, lane: usize) -> u64 {
        self.step[lane]
    }

    /// Lane `lane`'s exact phase word (2^-64 turn) of the sample the next tick outputs.
    pub fn next_phase_word(&self, lane: usize) -> u64 {
        self.phase[lane].wrapping_sub(self.step[lane].wrapping_mul(u64::from(self.count)))
    }

    /// The ticks left before the next exact re-set, at least 1: a re-set that is due runs
    /// now. A loop that ticks at most this many times with [`RotatingNco::tick_ready`] has no
    /// call in it, so the compiler may keep the loop's states in registers.
    #[inline(always)]
    pub fn ready(&mut self) -> u32 {
        if self.count == 0 {
            self.resync();
        }
        self.count
    }

    /// [`Stage::tick`] without the re-set's check: at most [`RotatingNco::ready`] times
    /// after it (a wrapped count would skip the re-sets; the test
    /// `runs_within_ready_give_the_ticks_bits` holds both to the same bits).
    #[inline(always)]
    pub fn tick_ready(&mut self) -> (S, S) {
        debug_assert!(self.count > 0, "tick_ready past the re-set");
        let out = (self.re, self.im);
        let re = self.re * self.rot_re - self.im * self.rot_im;
        self.im = self.im * self.rot_re + self.re * self.rot_im;
        self.re = re;
        self.count -= 1;
        out
    }

    /// Sets the phasor exactly from the accumulator and advances the accumulator by one
    /// re-set interval. Out of line and cold: it runs once per 64 samples, and keeping it
    /// out of the sample loop leaves the loop's registers to the recursions.
    #[cold]
    #[inline(never)]
    fn resync(&mut self) {
        // In groups of four lanes, the base build's vector width, whatever `S` is: this
        // function is out of line, so an eight-lane type's arithmetic here is not compiled for
        // AVX-512 (done in F64x8 it cost the eight-lane chain 13 to 19 %).
        let t = table();
        let (mut re, mut im) = ([0.0; MAX_LANES], [0.0; MAX_LANES]);
        for q in 0..S::LANES.div_ceil(4) {
            let (r, i) = phasors_in_lanes::<f64x4>(t, &self.phase[4 * q..4 * q + 4]);
            re[4 * q..4 * q + 4].copy_from_slice(&r.to_array());
            im[4 * q..4 * q + 4].copy_from_slice(&i.to_array());
        }
        self.re = S::from_fn(|i| re[i]);
        self.im = S::from_fn(|i| im[i]);
        for i in 0..S::LANES {
            self.phase[i] = self.phase[i].wrapping_add(self.step[i].wrapping_mul(RESYNC as u64));
        }
        self.count = RESYNC;
    }

    /// The phasor of each lane's `words[i]` (the lanes past `S::LANES` left at 0).
    fn phasors(&self, words: [u64; MAX_LANES]) -> [gyroemu_core::Complex64; MAX_LANES] {
        core::array::from_fn(|i| {
            if i < S::LANES {
                phasor_of_word(words[i])
            } else {
                gyroemu_core::Complex64::new(0.0, 0.0)
            }
        })
    }
}

/// Refuses a lane past `S::LANES`, naming the lanes there are.
fn check_lane<S: Sample>(lane: usize) -> ParamResult<()> {
    if lane < S::LANES {
        return Ok(());
    }
    Err(ParamError::new(
        "rotating_nco",
        "lane",
        lane,
        format!("must be below the number of lanes ({})", S::LANES),
    ))
}

impl<S: Sample> Stage for RotatingNco<S> {
    type Input = ();
    type Output = (S, S);

    /// The phasor at the current sample, then one step of rotation.
    #[inline(always)]
    fn tick(&mut self, _: ()) -> (S, S) {
        self.ready();
        self.tick_ready()
    }

    fn reset(&mut self) {
        self.phase = self.phase0;
        if self.step != self.step0 {
            self.step = self.step0;
            let rot = self.phasors(self.step);
            self.rot_re = S::from_fn(|i| rot[i].re);
            self.rot_im = S::from_fn(|i| rot[i].im);
        }
        self.resync();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_within_ready_give_the_ticks_bits() {
        // Runs of every length up to past a re-set interval, cut short by `ready` as the
        // board's block loop cuts them: the same bits as ticking one sample at a time.
        let ncos: Vec<Nco> = [15_000.0, 0.0607, -12_345.678_9, 0.486]
            .iter()
            .map(|&f| Nco::new(f, 240_000.0, 0.3).unwrap())
            .collect();
        let mut by_tick = RotatingNco::<f64x4>::new(&ncos);
        let mut by_run = by_tick.clone();
        let (mut want, mut ticked) = (1u32, 0u64);
        for _ in 0..400 {
            let run = by_run.ready().min(want);
            ticked += u64::from(run);
            assert!(run >= 1);
            for _ in 0..run {
                let (a, b) = (by_tick.tick(()), by_run.tick_ready());
                for l in 0..4 {
                    assert_eq!(a.0.lane(l).to_bits(), b.0.lane(l).to_bits());
                    assert_eq!(a.1.lane(l).to_bits(), b.1.lane(l).to_bits());
                }
            }
            want = want % (RESYNC + 3) + 1;
        }
        // The runs crossed many re-sets, and the exact phase followed.
        assert!(ticked > 100 * u64::from(RESYNC), "{ticked}");
        let step = ncos[1].step_word();
        let want_word = ncos[1].phase_word().wrapping_add(step.wrapping_mul(ticked));
        assert_eq!(by_run.next_phase_word(1), want_word);
    }

    #[test]
    fn follows_the_exact_nco_within_1e_14_over_many_resyncs() {
        let fs = 240_000.0;
        let freqs = [15_000.0, 0.0607_f64, -12_345.678_9, 0.486];
        let ncos: Vec<Nco> = freqs
            .iter()
            .map(|&f| Nco::new(f, fs, 0.3).unwrap())
            .collect();
        let mut reference = ncos.clone();
        let mut rot = RotatingNco::<f64x4>::new(&ncos);
        let mut worst: f64 = 0.0;
        for _ in 0..100_000 {
            let (c, s) = rot.tick(());
            for (i, r) in reference.iter_mut().enumerate() {
                let p = r.tick(());
                worst = worst
                    .max((c.lane(i) - p.re).abs())
                    .max((s.lane(i) - p.im).abs());
            }
        }
        assert!(worst < 1e-14, "worst deviation {worst}");
    }
}
