//! The one small interface every stage of the chain shares (after fundsp and rubato):
//! `tick` one sample, `process` a block, `reset`, and where it applies a frequency
//! response and a latency. Everything is static dispatch so the per-sample path inlines.

use num_complex::Complex64;

/// A sample-by-sample processing stage.
pub trait Stage {
    /// What one step consumes (`()` for sources such as the NCO).
    type Input: Copy;
    /// What one step produces.
    type Output: Copy;

    /// Advances the stage by one input sample.
    fn tick(&mut self, x: Self::Input) -> Self::Output;

    /// Processes a block; identical, bit for bit, to calling [`Stage::tick`] on each sample.
    /// Only the common prefix of `input` and `output` is processed.
    #[inline]
    fn process(&mut self, input: &[Self::Input], output: &mut [Self::Output]) {
        for (x, y) in input.iter().zip(output.iter_mut()) {
            *y = self.tick(*x);
        }
    }

    /// Returns the stage to the state it had when it was built.
    fn reset(&mut self);

    /// Group delay at DC, in input samples (0 for memoryless stages).
    fn latency_samples(&self) -> f64 {
        0.0
    }
}

/// The exact complex gain of a linear stage as built (discrete-time, at the stage's sample
/// rate), used to compensate chain terms and to check the stage against theory.
pub trait Response {
    /// Complex gain at `f_hz` (may be negative, or above Nyquist where that means aliasing).
    fn response(&self, f_hz: f64) -> Complex64;
}
