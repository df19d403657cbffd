//! How each operating point's converters and rails fared: clipped and exactly-zero samples,
//! counted in the sample loop so a clipped, saturated or dead channel is never read out as
//! if it were clean.

use gyroemu_core::Sample;

/// Counts of one operating point over its whole run (settling included), per mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Health {
    /// Input samples the point ran.
    pub samples: u64,
    /// Drive samples beyond the DAC's end codes.
    pub dac_clipped: [u64; 2],
    /// Drive samples the DAC put out as exactly 0.
    pub dac_zero: [u64; 2],
    /// TIA output samples on a rail.
    pub tia_railed: [u64; 2],
    /// TIA output samples beyond the ADC's end codes.
    pub adc_clipped: [u64; 2],
    /// ADC output samples exactly 0.
    pub adc_zero: [u64; 2],
}

impl Health {
    /// Any clipping or saturation at all.
    pub fn clipped(&self) -> bool {
        [self.dac_clipped, self.tia_railed, self.adc_clipped]
            .iter()
            .flatten()
            .any(|&n| n > 0)
    }

    /// Adds another run's counts (a sum over the points of a sweep).
    pub fn add(&mut self, o: &Health) {
        self.samples += o.samples;
        for k in 0..2 {
            self.dac_clipped[k] += o.dac_clipped[k];
            self.dac_zero[k] += o.dac_zero[k];
            self.tia_railed[k] += o.tia_railed[k];
            self.adc_clipped[k] += o.adc_clipped[k];
            self.adc_zero[k] += o.adc_zero[k];
        }
    }
}

/// Slots of [`Counters`]: two modes each.
pub(crate) const DAC_CLIP: usize = 0;
pub(crate) const DAC_ZERO: usize = 2;
pub(crate) const TIA_RAIL: usize = 4;
pub(crate) const ADC_CLIP: usize = 6;
pub(crate) const ADC_ZERO: usize = 8;

/// Lane-parallel counts of one decimation block (whole numbers below 2^53, exact in f64).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Counters<S>(pub(crate) [S; 10]);

impl<S: Sample> Counters<S> {
    /// Adds `block`'s counts in the lanes where `active` is 1 (0 elsewhere): a lane's running
    /// totals, exact while below 2^53, drained once at the end instead of every block.
    #[inline(always)]
    pub(crate) fn add_where(&mut self, block: &Self, active: S) {
        for (t, b) in self.0.iter_mut().zip(&block.0) {
            *t += *b * active;
        }
    }

    /// Adds lane `lane` of every count to `h`.
    pub(crate) fn drain_into(&self, lane: usize, h: &mut Health) {
        let c = |i: usize| self.0[i].lane(lane) as u64;
        for k in 0..2 {
            h.dac_clipped[k] += c(DAC_CLIP + k);
            h.dac_zero[k] += c(DAC_ZERO + k);
            h.tia_railed[k] += c(TIA_RAIL + k);
            h.adc_clipped[k] += c(ADC_CLIP + k);
            h.adc_zero[k] += c(ADC_ZERO + k);
        }
    }
}
