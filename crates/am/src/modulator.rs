//! The AM modulator: carrier copies and modulation references in, two drive forces out.

use gyroemu_core::{error, ParamResult, Sample, Stage};

const STAGE: &str = "am_modulator";

/// Which pair of drives the board makes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DrivePattern {
    /// Experiment A: `f1 = F1 cos w0t`, `f2 = F2 sin w0t` (THEORY section 3).
    Coriolis,
    /// Experiment B: `f1 = F0 cos(Omega t) cos w0t`, `f2 = F0 sin(Omega t) cos w0t` (eq. 4).
    Rotating,
}

/// One sample of the modulator's inputs: the carrier `cos w0t` and its phase-shifted copy
/// (`sin w0t` for the nominal 90-degree shifter), and the modulation references
/// `cos Omega t`, `sin Omega t` (ignored by [`DrivePattern::Coriolis`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct AmInput<S> {
    /// In-phase carrier, `cos w0t`.
    pub carrier_i: S,
    /// Phase-shifted carrier, `sin w0t` nominally.
    pub carrier_q: S,
    /// Modulation reference `cos Omega t`.
    pub mod_cos: S,
    /// Modulation reference `sin Omega t`.
    pub mod_sin: S,
}

/// Makes the two drive forces `[f1, f2]` from the carrier and modulation references.
/// Memoryless: each output sample depends only on the same input sample.
#[derive(Clone, Copy, Debug)]
pub struct AmModulator<S> {
    pattern: DrivePattern,
    gain1: S,
    gain2: S,
    /// Every lane of both gains is exactly 1: the products by the gains are skipped
    /// (multiplying by 1 changes no bit), which saves two lane multiplies per sample.
    unit_gains: bool,
}

impl<S: Sample> AmModulator<S> {
    /// `gain1` is F1 (Coriolis) or F0 on mode 1 (rotating); `gain2` is F2 or F0 on mode 2
    /// (unequal values model a drive gain mismatch). Both finite, any sign (0 turns a drive off).
    pub fn new(pattern: DrivePattern, gain1: f64, gain2: f64) -> ParamResult<Self> {
        let g1 = error::finite(STAGE, "gain1", gain1)?;
        let g2 = error::finite(STAGE, "gain2", gain2)?;
        Ok(Self {
            pattern,
            gain1: S::splat(g1),
            gain2: S::splat(g2),
            unit_gains: g1 == 1.0 && g2 == 1.0,
        })
    }

    /// A lane-parallel modulator: lane `i` takes its gains from `lanes[i]`, so four operating
    /// points run through one modulator. All lanes share one pattern (the first modulator's;
    /// others' patterns are ignored). Missing lanes repeat the last given modulator; an empty
    /// slice gives a Coriolis modulator with zero gains.
    pub fn from_lanes(lanes: &[AmModulator<f64>]) -> Self {
        let pick = |i: usize| lanes.get(i.min(lanes.len().saturating_sub(1)));
        let gain1 = S::from_fn(|i| pick(i).map_or(0.0, |m| m.gain1));
        let gain2 = S::from_fn(|i| pick(i).map_or(0.0, |m| m.gain2));
        let unit = |g: S| (0..S::LANES).all(|i| g.lane(i) == 1.0);
        Self {
            pattern: lanes.first().map_or(DrivePattern::Coriolis, |m| m.pattern),
            gain1,
            gain2,
            unit_gains: unit(gain1) && unit(gain2),
        }
    }

    /// The drive pattern.
    pub fn pattern(&self) -> DrivePattern {
        self.pattern
    }

    /// The gains `(gain1, gain2)`.
    pub fn gains(&self) -> (S, S) {
        (self.gain1, self.gain2)
    }
}

impl<S: Sample> Stage for AmModulator<S> {
    type Input = AmInput<S>;
    type Output = [S; 2];

    /// Coriolis: `[gain1 * carrier_i, gain2 * carrier_q]`;
    /// rotating: `[gain1 * mod_cos * carrier_i, gain2 * mod_sin * carrier_i]`.
    #[inline(always)]
    fn tick(&mut self, x: AmInput<S>) -> [S; 2] {
        match (self.pattern, self.unit_gains) {
            (DrivePattern::Coriolis, false) => [self.gain1 * x.carrier_i, self.gain2 * x.carrier_q],
            (DrivePattern::Coriolis, true) => [x.carrier_i, x.carrier_q],
            (DrivePattern::Rotating, false) => [
                self.gain1 * x.mod_cos * x.carrier_i,
                self.gain2 * x.mod_sin * x.carrier_i,
            ],
            (DrivePattern::Rotating, true) => [x.mod_cos * x.carrier_i, x.mod_sin * x.carrier_i],
        }
    }

    fn reset(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms_on_one_sample() {
        let x = AmInput {
            carrier_i: 0.5,
            carrier_q: -0.25,
            mod_cos: 0.75,
            mod_sin: 2.0,
        };
        let mut c = AmModulator::<f64>::new(DrivePattern::Coriolis, 2.0, 4.0).unwrap();
        assert_eq!(c.tick(x), [1.0, -1.0]);
        let mut r = AmModulator::<f64>::new(DrivePattern::Rotating, 2.0, 4.0).unwrap();
        assert_eq!(r.tick(x), [0.75, 4.0]);
        assert!(AmModulator::<f64>::new(DrivePattern::Coriolis, f64::NAN, 1.0).is_err());
        let e = AmModulator::<f64>::new(DrivePattern::Rotating, 1.0, f64::INFINITY).unwrap_err();
        assert_eq!((e.stage, e.param), (STAGE, "gain2"));
    }
}
