//! The drive DAC: optional quantisation. Its zero-order hold is realised by the plant.

use crate::Quantizer;
use gyroemu_core::{error, ParamResult, Sample, Stage};

const STAGE: &str = "dac";

/// The drive DAC. Per sample it only quantises (if configured): memoryless, impulse response
/// `[1]`. The zero-order hold itself is realised exactly by the plant, whose discretisation
/// assumes the force is held constant over each sample period; its response is
/// `gyroemu_resonator::hold_response`.
#[derive(Clone, Copy, Debug)]
pub struct Dac<S> {
    fs_hz: f64,
    quant: Option<Quantizer<S>>,
}

impl<S: Sample> Dac<S> {
    /// A DAC at `fs_hz` (finite, > 0), with `quant = Some((bits, full_scale))` to quantise
    /// (see [`Quantizer::new`]) or `None` for an ideal converter.
    pub fn new(fs_hz: f64, quant: Option<(u32, f64)>) -> ParamResult<Self> {
        let fs_hz = error::positive(STAGE, "fs_hz", fs_hz)?;
        let quant = match quant {
            Some((bits, full_scale)) => Some(Quantizer::new(bits, full_scale)?),
            None => None,
        };
        Ok(Self { fs_hz, quant })
    }

    /// The sample rate in Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// The quantiser, if any.
    pub fn quantizer(&self) -> Option<&Quantizer<S>> {
        self.quant.as_ref()
    }
}

impl<S: Sample> Stage for Dac<S> {
    type Input = S;
    type Output = S;

    #[inline(always)]
    fn tick(&mut self, x: S) -> S {
        match &self.quant {
            Some(q) => q.quantize(x),
            None => x,
        }
    }

    fn reset(&mut self) {}
}
