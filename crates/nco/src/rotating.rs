//! A lane-parallel oscillator for the per-sample loop: a unit phasor per lane rotated by its
//! step every sample (a complex multiply), re-set every `RESYNC` samples from the exact 64-bit
//! phase accumulator of [`Nco`]. Between re-sets the rounding of the rotation grows by at most
//! a few ulp per sample, so the output stays within ~1e-14 of the NCO's and never drifts.

use crate::trig::phasor_of_word;
use crate::Nco;
use gyroemu_core::{Sample, Stage};

/// Samples between exact re-sets of the rotated phasor.
pub const RESYNC: u32 = 64;

/// Up to four NCOs (one per lane) advanced together; output `(cos, sin)` per lane.
#[derive(Clone, Debug)]
pub struct RotatingNco<S: Sample> {
    re: S,
    im: S,
    rot_re: S,
    rot_im: S,
    phase: [u64; 4],
    step: [u64; 4],
    phase0: [u64; 4],
    count: u32,
}

impl<S: Sample> RotatingNco<S> {
    /// Lane `i` follows `ncos[i]` from its current phase (lanes past the slice repeat the
    /// last NCO). `ncos` must not be empty.
    pub fn new(ncos: &[Nco]) -> Self {
        let pick = |i: usize| &ncos[i.min(ncos.len() - 1)];
        let phase: [u64; 4] = core::array::from_fn(|i| pick(i).phase_word());
        let step: [u64; 4] = core::array::from_fn(|i| pick(i).step_word());
        let rot = |i: usize| phasor_of_word(step[i]);
        let mut s = Self {
            re: S::splat(0.0),
            im: S::splat(0.0),
            rot_re: S::from_fn(|i| rot(i).re),
            rot_im: S::from_fn(|i| rot(i).im),
            phase,
            step,
            phase0: phase,
            count: 0,
        };
        s.resync();
        s
    }

    /// Sets the phasor exactly from the accumulator and advances the accumulator by one
    /// re-set interval. Out of line and cold: it runs once per 64 samples, and keeping it
    /// out of the sample loop leaves the loop's registers to the recursions.
    #[cold]
    #[inline(never)]
    fn resync(&mut self) {
        let p: [gyroemu_core::Complex64; 4] =
            core::array::from_fn(|i| phasor_of_word(self.phase[i]));
        self.re = S::from_fn(|i| p[i].re);
        self.im = S::from_fn(|i| p[i].im);
        for i in 0..4 {
            self.phase[i] = self.phase[i].wrapping_add(self.step[i].wrapping_mul(RESYNC as u64));
        }
        self.count = RESYNC;
    }
}

impl<S: Sample> Stage for RotatingNco<S> {
    type Input = ();
    type Output = (S, S);

    /// The phasor at the current sample, then one step of rotation.
    #[inline(always)]
    fn tick(&mut self, _: ()) -> (S, S) {
        if self.count == 0 {
            self.resync();
        }
        let out = (self.re, self.im);
        let re = self.re * self.rot_re - self.im * self.rot_im;
        self.im = self.im * self.rot_re + self.re * self.rot_im;
        self.re = re;
        self.count -= 1;
        out
    }

    fn reset(&mut self) {
        self.phase = self.phase0;
        self.resync();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_core::f64x4;

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
