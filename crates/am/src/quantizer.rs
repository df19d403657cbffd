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
}

impl<S: Sample> Quantizer<S> {
    /// `bits` in `2..=32`, `full_scale` finite and > 0 (in the signal's unit).
    pub fn new(bits: u32, full_scale: f64) -> ParamResult<Self> {
        if !(2..=32).contains(&bits) {
            return Err(ParamError::new(STAGE, "bits", bits, "must be in 2..=32"));
        }
        let fs = error::positive(STAGE, "full_scale", full_scale)?;
        let half_codes = (1u64 << (bits - 1)) as f64;
        let step = fs / half_codes; // exact: division by a power of two
        Ok(Self {
            bits,
            step_f64: step,
            step: S::splat(step),
            code_lo: S::splat(-half_codes),
            code_hi: S::splat(half_codes - 1.0),
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
