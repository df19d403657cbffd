//! The flicker generator: the designed filter in modal form, run sample by sample on a unit
//! Gaussian sequence the caller draws (so it follows whatever Gaussian generator the board
//! uses), lane-parallel through [`Sample`].

use super::stationary::cholesky_factor;
use super::{FlickerDesign, FlickerParams};
use crate::{Complex64, ParamResult, Response, Sample, Stage};

/// A flicker (1/f) source: `tick(w)` takes one unit-variance white Gaussian per lane and
/// returns the next flicker sample, whose one-sided density is [`FlickerDesign::psd`] (`S1 /
/// f` in band). Every lane runs the scalar recursion on its own input, so lane `l` of an
/// `f64x4` source gives the bits of an `f64` source fed lane `l`'s Gaussians.
#[derive(Clone, Debug)]
pub struct Flicker<S: Sample> {
    design: FlickerDesign,
    a: Vec<S>,
    rho: Vec<S>,
    direct: S,
    /// Modal states `m_k[n] = a_k m_k[n-1] + w[n]`.
    state: Vec<S>,
    /// The state `reset` restores (the start state).
    start: Vec<S>,
}

impl<S: Sample> Flicker<S> {
    /// A source started at rest (every state 0): a linear filter of its input, as the
    /// response checks need. Its output is stationary only after about `1 / (2 pi f_lo)`
    /// seconds; for noise use [`Flicker::stationary`].
    pub fn at_rest(p: &FlickerParams) -> ParamResult<Self> {
        let design = FlickerDesign::new(p)?;
        let n = design.poles();
        Ok(Self {
            a: design.pole_radii().iter().map(|&v| S::splat(v)).collect(),
            rho: design.residues().iter().map(|&v| S::splat(v)).collect(),
            direct: S::splat(design.direct()),
            state: vec![S::default(); n],
            start: vec![S::default(); n],
            design,
        })
    }

    /// A source whose start state is drawn from the stationary law of the filter driven by
    /// unit white noise, so the output is stationary from its first sample. Draws exactly
    /// [`FlickerDesign::poles`] unit Gaussians from `gauss`, in order, before anything else.
    /// `reset` returns to this start.
    pub fn stationary(p: &FlickerParams, mut gauss: impl FnMut() -> S) -> ParamResult<Self> {
        let mut f = Self::at_rest(p)?;
        let n = f.design.poles();
        let l = cholesky_factor(&f.design);
        let xi: Vec<S> = (0..n).map(|_| gauss()).collect();
        for i in 0..n {
            let mut v = S::default();
            for (k, &x) in xi.iter().enumerate().take(i + 1) {
                v += S::splat(l[i * n + k]) * x;
            }
            f.start[i] = v;
        }
        f.state.clone_from(&f.start);
        Ok(f)
    }

    /// One source whose lanes are those of `parts` side by side (part `j` in lanes
    /// `j * U::LANES ..`): sources of one design in a wider lane type, each lane keeping its
    /// state, so it gives the bits the parts give. Why: two sources of four lanes run as one
    /// of eight where the CPU has the wider registers.
    ///
    /// # Panics
    /// If the parts do not fill `S`'s lanes exactly or their designs differ (a caller's bug).
    pub fn from_parts<U: Sample>(parts: &[&Flicker<U>]) -> Self {
        assert_eq!(parts.len() * U::LANES, S::LANES, "the parts fill the lanes");
        let design = parts[0].design.clone();
        assert!(
            parts.iter().all(|p| p.design == design),
            "the parts share one design"
        );
        let join = |v: fn(&Flicker<U>) -> &Vec<U>, k: usize| {
            S::from_fn(|l| v(parts[l / U::LANES])[k].lane(l % U::LANES))
        };
        let n = design.poles();
        Self {
            a: design.pole_radii().iter().map(|&v| S::splat(v)).collect(),
            rho: design.residues().iter().map(|&v| S::splat(v)).collect(),
            direct: S::splat(design.direct()),
            state: (0..n).map(|k| join(|f| &f.state, k)).collect(),
            start: (0..n).map(|k| join(|f| &f.start, k)).collect(),
            design,
        }
    }

    /// The design (exact spectrum, variance, poles).
    pub fn design(&self) -> &FlickerDesign {
        &self.design
    }

    /// The exact one-sided density of the output at `f_hz`, unit^2/Hz.
    pub fn psd(&self, f_hz: f64) -> f64 {
        self.design.psd(f_hz)
    }
}

impl<S: Sample> Stage for Flicker<S> {
    /// One unit-variance white Gaussian per lane.
    type Input = S;
    type Output = S;

    #[inline(always)]
    fn tick(&mut self, w: S) -> S {
        let mut y = w * self.direct;
        for ((m, &a), &r) in self.state.iter_mut().zip(&self.a).zip(&self.rho) {
            *m = m.mul_add(a, w);
            y = m.mul_add(r, y);
        }
        y
    }

    /// The same bits as `tick` on each sample, computed a few poles at a time over the whole
    /// block. Why: in `tick` each pole's multiply-add waits on the previous one's (the sum
    /// runs through the poles in order), so a sample costs one multiply-add latency per
    /// pole. Here every sample's sum still runs through the poles in that order, but the
    /// samples' sums are independent of each other, so the core overlaps them.
    #[inline(always)]
    fn process(&mut self, input: &[S], output: &mut [S]) {
        let len = input.len().min(output.len());
        let (w, y) = (&input[..len], &mut output[..len]);
        for (y, &x) in y.iter_mut().zip(w) {
            *y = x * self.direct;
        }
        let n = self.a.len();
        let mut k = 0;
        if S::LANES >= 8 {
            while k + 2 * POLES_AT_ONCE <= n {
                k += self.poles::<{ 2 * POLES_AT_ONCE }>(k, w, y);
            }
            // The rest, up to seven poles, in one pass (32 registers hold them): a pass
            // takes at least a multiply-add's latency per sample, so one of five beats two.
            k += match n - k {
                7 => self.poles::<7>(k, w, y),
                6 => self.poles::<6>(k, w, y),
                5 => self.poles::<5>(k, w, y),
                _ => 0,
            };
        }
        while k + POLES_AT_ONCE <= n {
            k += self.poles::<POLES_AT_ONCE>(k, w, y);
        }
        match n - k {
            3 => self.poles::<3>(k, w, y),
            2 => self.poles::<2>(k, w, y),
            1 => self.poles::<1>(k, w, y),
            _ => 0,
        };
    }

    fn reset(&mut self) {
        self.state.clone_from(&self.start);
    }
}

/// Poles [`Flicker::process`] runs together per pass over a block: four keep the states, pole
/// radii and residues in registers and give each sample's chain of four dependent
/// multiply-adds enough independent work beside it. Eight-lane sources (compiled for
/// AVX-512: 32 registers) run twice as many per pass first, so the sums are read and written
/// fewer times (docs/performance.md), and the rest, up to seven, in one pass; four-lane
/// sources the last one to three in one pass. One by one, each pole's state waited a
/// multiply-add's latency per sample: the last three of the bench's TIA source's 19 poles
/// took 12 cycles a sample, the other 16 took 16.
const POLES_AT_ONCE: usize = 4;

impl<S: Sample> Flicker<S> {
    /// Adds poles `k .. k + P` to every sample's sum in `y` (started by `process`), advancing
    /// their states over the block `w`: per sample the multiply-adds of `tick`, in its order.
    /// Returns `P`, the poles done.
    #[inline(always)]
    fn poles<const P: usize>(&mut self, k: usize, w: &[S], y: &mut [S]) -> usize {
        let a: [S; P] = core::array::from_fn(|i| self.a[k + i]);
        let r: [S; P] = core::array::from_fn(|i| self.rho[k + i]);
        let mut m: [S; P] = core::array::from_fn(|i| self.state[k + i]);
        for (y, &x) in y.iter_mut().zip(w) {
            let mut acc = *y;
            for i in 0..P {
                m[i] = m[i].mul_add(a[i], x);
                acc = m[i].mul_add(r[i], acc);
            }
            *y = acc;
        }
        self.state[k..k + P].copy_from_slice(&m);
        P
    }
}

impl<S: Sample> Response for Flicker<S> {
    /// The complex gain from the Gaussian input to the output (the design's).
    fn response(&self, f_hz: f64) -> Complex64 {
        self.design.response(f_hz)
    }
}
