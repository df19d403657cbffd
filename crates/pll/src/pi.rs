//! The PI loop filter both loops share: `u[k] = Kp e[k] + I[k]`, `I[k] = I[k-1] + Ki T e[k]`,
//! with the output limited and the integrator held while a limit is pushed (no wind-up).

use gyroemu_core::detmath::sin_cos_turns;
use gyroemu_core::Complex64;

/// The PI filter's gains and integrator.
#[derive(Clone, Debug)]
pub(crate) struct Pi {
    kp: f64,
    ki_t: f64,
    integ: f64,
}

impl Pi {
    pub(crate) fn new(kp: f64, ki_t: f64) -> Self {
        Self {
            kp,
            ki_t,
            integ: 0.0,
        }
    }

    /// One update on error `e`: the output `map(Kp e + I)` clamped to `[lo, hi]`, and whether
    /// it was clamped. `map` must be increasing, and the gains are >= 0, so a positive error
    /// raises the output: while the output sits on `hi` with `e > 0` (or on `lo` with
    /// `e < 0`) the integrator is held, so it leaves the limit as soon as the error turns.
    #[inline]
    pub(crate) fn tick(
        &mut self,
        e: f64,
        lo: f64,
        hi: f64,
        map: impl Fn(f64) -> f64,
    ) -> (f64, bool) {
        let integ = self.integ + self.ki_t * e;
        let y = map(self.kp * e + integ);
        let (out, pushing_out) = if y > hi {
            (hi, e > 0.0)
        } else if y < lo {
            (lo, e < 0.0)
        } else {
            (y, false)
        };
        if !pushing_out {
            self.integ = integ;
        }
        (out, out != y)
    }

    /// The integrator, in the units of `Kp e`.
    pub(crate) fn integrator(&self) -> f64 {
        self.integ
    }

    pub(crate) fn reset(&mut self) {
        self.integ = 0.0;
    }

    /// `Kp + Ki T / (1 - e^{-j 2 pi x})` at `x` = frequency / update rate; infinite at
    /// integer `x` (the integrator's pole).
    pub(crate) fn response(&self, x: f64) -> Complex64 {
        // The response has period 1 in x; reduce to |x| <= 1/2 first, so an integer x is
        // exactly 0.
        let x = x - x.round();
        if x == 0.0 {
            return Complex64::new(f64::INFINITY, 0.0);
        }
        // 1 - e^{-jw} = 2 sin^2(w/2) + j sin w, accurate near DC.
        let (sh, ch) = sin_cos_turns(0.5 * x);
        let one_minus = Complex64::new(2.0 * sh * sh, 2.0 * sh * ch);
        Complex64::new(self.kp, 0.0) + Complex64::new(self.ki_t, 0.0) / one_minus
    }
}
