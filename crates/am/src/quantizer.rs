//! A mid-tread uniform quantiser (the DAC's or an ADC's resolution).

use gyroemu_core::{error, ParamError, ParamResult, Sample, Stage};

const STAGE: &str = "quantizer";

/// Mid-tread uniform quantiser with `bits` bits over `[-full_scale, +full_scale)`: codes
/// `-2^(bits-1) ..= 2^(bits-1) - 1`, step `2 full_scale / 2^bits`, zero is a level, inputs
/// round to the nearest level (ties away from zero) and out-of-range inputs clip to the end
/// codes. Why: models the finite resolution of the drive DAC (noise power step^2/12).
#[derive(Clone, Copy, Debug)]
pub struct Quantizer<S> {
    bits: u32,
    step_f64: f64,
    step: S,
    code_lo: S,
    code_hi: S,
    /// For [`Quantizer::quantize_counting_fast`]: the rounded reciprocal of the step, the
    /// largest `|x / step|` it takes (the top code) and the largest distance to its code
    /// (`1/2 - MARGIN`).
    inv_step: S,
    fast_hi: S,
    tie_hi: S,
}

/// How far from a half-integer [`Quantizer::quantize_counting_fast`] keeps its product:
/// 2^-16, far above the 2^-20 by which the product and the rounded quotient can differ below
/// 2^31 (its proof).
const MARGIN: f64 = 1.0 / 65536.0;

impl<S: Sample> Quantizer<S> {
    /// `bits` in `2..=32`, `full_scale` finite and > 0 (in the signal's unit).
    pub fn new(bits: u32, full_scale: f64) -> ParamResult<Self> {
        if !(2..=32).contains(&bits) {
            return Err(ParamError::new(STAGE, "bits", bits, "must be in 2..=32"));
        }
        let fs = error::positive(STAGE, "full_scale", full_scale)?;
        let half_codes = (1u64 << (bits - 1)) as f64;
        let step = fs / half_codes; // exact (a power of two) unless the step is subnormal
        let inv = 1.0 / step;
        Ok(Self {
            bits,
            step_f64: step,
            step: S::splat(step),
            code_lo: S::splat(-half_codes),
            code_hi: S::splat(half_codes - 1.0),
            inv_step: S::splat(inv),
            // Off (no |p| is <= -1) where the reciprocal is not normal (a step beyond
            // 2^1022 or a tiny one): the proof needs its relative error <= 2^-53.
            fast_hi: S::splat(if inv.is_normal() {
                half_codes - 1.0
            } else {
                -1.0
            }),
            tie_hi: S::splat(0.5 - MARGIN),
        })
    }

    /// The quantisation step (one LSB), `2 full_scale / 2^bits`.
    pub fn step(&self) -> f64 {
        self.step_f64
    }

    /// The resolution in bits.
    pub fn bits(&self) -> u32 {
        self.bits
    }

    /// `clip(round(x / step)) * step`.
    #[inline(always)]
    pub fn quantize(&self, x: S) -> S {
        (x / self.step)
            .round_away()
            .clamp_to(self.code_lo, self.code_hi)
            * self.step
    }

    /// [`Quantizer::quantize`] (the same bits), adding 1 in each lane to `clipped` where the
    /// input lay beyond the end codes and to `zeros` where the output is exactly 0: how a
    /// board tells a clipped or dead converter from a working one.
    #[inline(always)]
    pub fn quantize_counting(&self, x: S, clipped: &mut S, zeros: &mut S) -> S {
        let code = (x / self.step).round_away();
        let kept = code.clamp_to(self.code_lo, self.code_hi);
        *clipped += code.flag_ne(kept);
        let y = kept * self.step;
        *zeros += y.flag_eq(S::splat(0.0));
        y
    }

    /// [`Quantizer::quantize_counting`]'s bits and counts without its division where it can:
    /// `p = x * (1/step)` rounded to its code `c` (to nearest, ties to even: one instruction
    /// in the x86-64-v3 build, and a lane it keeps is never near a tie) is the answer when
    /// every lane has `|p - c| <= 1/2 - m` (m = 2^-16) and `|p| <= hi` (`hi` the top code);
    /// the lanes whose output is zero are counted. Any other lane (a near-tie, a NaN, `|p|`
    /// beyond the top code, which takes the bottom code and every clipped one) sends the
    /// whole group through the division, whose counts are then added, as does every lane
    /// where `1/step` is not normal. Zero codes stay on the product, counted without a
    /// branch, because they are common: a board samples its carrier at the carrier's exact
    /// zeros (2 samples in 16 at fs = 16 f0), so an AM drive hands the DAC an exact 0 that
    /// often.
    ///
    /// Why that is exact, for a lane with `c != 0`: with `u = 2^-53`, `p = q (1 + a)(1 + b)`
    /// and the division's `d = q (1 + e)` for `q = x / step` (`|a|, |b|, |e| <= u`; both
    /// normal, as `|p| >= 1/2`), so `|p - d| <= 3.01 u |q| < 2^-20` for `|p| < 2^31`. `p` lies
    /// at least `m` from every half-integer (the nearest are `c +- 1/2`), so `d`, within
    /// 2^-20 of it, rounds to the same `c`. `1 <= |c| <= hi`: inside the end codes (the clamp
    /// keeps it) and not zero (`|c * step| >= step`), so both count nothing. `p - c` is exact
    /// (Sterbenz: `c/2 <= p <= 2c`). For a lane with `c = 0`: `|p| <= 1/2 - m`, so
    /// `|d| < 1/2` (by the same bound, or by an absolute error below 2^-1074 where either is
    /// subnormal), and the division's code is 0 too, with the same sign (both keep the sign
    /// of `x`): both give `+-0 * step`, and both count one zero.
    #[inline(always)]
    pub fn quantize_counting_fast(&self, x: S, clipped: &mut S, zeros: &mut S) -> S {
        match self.quantize_by_product(x) {
            Some((y, zero)) => {
                *zeros += zero;
                y
            }
            None => {
                core::hint::cold_path();
                self.quantize_counting(x, clipped, zeros)
            }
        }
    }

    /// The product path of [`Quantizer::quantize_counting_fast`]: the output, and 1.0 in the
    /// lanes where it is zero, when every lane is clear of the end codes and of a tie (nothing
    /// clipped), else `None`.
    #[inline(always)]
    pub fn quantize_by_product(&self, x: S) -> Option<(S, S)> {
        let p = x * self.inv_step;
        let code = p.round_even();
        // `&`, not `&&`: both tests, then one branch.
        ((p - code).abs().all_le(self.tie_hi) & p.abs().all_le(self.fast_hi)).then(|| {
            let y = code * self.step;
            (y, y.flag_eq(S::splat(0.0)))
        })
    }
}

impl<S: Sample> Stage for Quantizer<S> {
    type Input = S;
    type Output = S;

    #[inline(always)]
    fn tick(&mut self, x: S) -> S {
        self.quantize(x)
    }

    fn reset(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_bit_levels() {
        // 3 bits over [-1, 1): step 0.25, levels -1.0 ..= 0.75.
        let q = Quantizer::<f64>::new(3, 1.0).unwrap();
        assert_eq!(q.step(), 0.25);
        assert_eq!(q.quantize(0.0), 0.0);
        assert_eq!(q.quantize(0.124), 0.0);
        assert_eq!(q.quantize(0.125), 0.25); // tie away from zero
        assert_eq!(q.quantize(-0.125), -0.25);
        assert_eq!(q.quantize(0.9), 0.75);
        assert_eq!(q.quantize(5.0), 0.75);
        assert_eq!(q.quantize(-1.0), -1.0);
        assert_eq!(q.quantize(-7.0), -1.0);
    }
}
