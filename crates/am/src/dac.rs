//! The drive DAC: optional quantisation plus the zero-order hold's frequency response.

use crate::Quantizer;
use gyroemu_core::{detmath, error, ParamResult, Response, Sample, Stage};
use num_complex::Complex64;

const STAGE: &str = "dac";

/// The drive DAC. Per sample it only quantises (if configured); the zero-order hold itself is
/// realised exactly by the plant, whose discretisation assumes the force is held constant
/// over each sample period (ZOH). [`Response`] reports that hold, `sinc(f Ts) e^{-j pi f Ts}`
/// (`sinc(x) = sin(pi x)/(pi x)`), and the latency is half a sample, so readout chain terms
/// (about `Omega Ts / 2` in the rotating phase, THEORY section 6) can be compensated.
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

    #[inline]
    fn tick(&mut self, x: S) -> S {
        match &self.quant {
            Some(q) => q.quantize(x),
            None => x,
        }
    }

    fn reset(&mut self) {}

    /// The hold delays by half a sample.
    fn latency_samples(&self) -> f64 {
        0.5
    }
}

impl<S: Sample> Response for Dac<S> {
    /// The zero-order hold, `sinc(f Ts) e^{-j pi f Ts}` (quantisation is not linear and is
    /// not included).
    fn response(&self, f_hz: f64) -> Complex64 {
        let x = f_hz / self.fs_hz; // f Ts
                                   // sin(pi x) and e^{-j pi x} from half a turn of x, reduced exactly in turns.
        let (s, c) = detmath::sin_cos_turns(0.5 * x);
        let sinc = if x == 0.0 {
            1.0
        } else {
            s / (core::f64::consts::PI * x)
        };
        Complex64::new(sinc * c, -sinc * s)
    }
}
