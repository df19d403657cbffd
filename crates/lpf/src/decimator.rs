//! Low-pass decimation by an integer factor.

use crate::lowpass::{u_of, LowPass};
use crate::{LowPassDesign, STAGE};
use gyroemu_core::error::positive;
use gyroemu_core::{Complex64, ParamError, ParamResult, Response, Sample, Stage};

/// How a [`Decimator`] forms each output sample from M inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DecimateMode {
    /// Low-pass every input, keep every M-th filter output.
    Filter(LowPassDesign),
    /// Integrate and dump: the mean of each block of M inputs (a boxcar, nulls at k fs/M).
    IntegrateDump,
    /// Low-pass every input, then output the mean of each block of M filter outputs.
    FilterThenDump(LowPassDesign),
}

/// Decimation by `factor` M with a low-pass and/or an integrate-and-dump.
///
/// Output phase: output k is produced on input index `k M + (M - 1)` (counting from 0 after
/// `new`/`reset`), i.e. on the last input of block k. It is the filter output at that input
/// sample (`Filter`), the mean of inputs `kM ..= kM + M - 1` (`IntegrateDump`), or the mean
/// of the filter outputs at those inputs (`FilterThenDump`). The dump sum is a plain sum,
/// restarted every block (error at most `M eps` of the block's sum of magnitudes).
#[derive(Clone, Debug)]
pub struct Decimator<S> {
    lp: Option<LowPass<S>>,
    dump: bool,
    m: usize,
    inv_m: S,
    phase: usize,
    acc: S,
    fs_in_hz: f64,
}

impl<S: Sample> Decimator<S> {
    /// Builds a decimator for input rate `fs_in_hz`; `factor` must be >= 1.
    pub fn new(mode: DecimateMode, factor: usize, fs_in_hz: f64) -> ParamResult<Self> {
        let fs = positive(STAGE, "fs_in_hz", fs_in_hz)?;
        if factor == 0 {
            return Err(ParamError::new(STAGE, "factor", factor, "must be >= 1"));
        }
        let (lp, dump) = match mode {
            DecimateMode::Filter(d) => (Some(LowPass::new(d, fs)?), false),
            DecimateMode::IntegrateDump => (None, true),
            DecimateMode::FilterThenDump(d) => (Some(LowPass::new(d, fs)?), true),
        };
        Ok(Self {
            lp,
            dump,
            m: factor,
            inv_m: S::splat(1.0 / factor as f64),
            phase: 0,
            acc: S::default(),
            fs_in_hz: fs,
        })
    }

    /// The decimation factor M.
    pub fn factor(&self) -> usize {
        self.m
    }

    /// Output sample rate `fs_in / M` in Hz.
    pub fn fs_out_hz(&self) -> f64 {
        self.fs_in_hz / self.m as f64
    }

    /// Number of outputs the next `n_in` inputs will produce.
    pub fn outputs_for(&self, n_in: usize) -> usize {
        (self.phase + n_in) / self.m
    }

    /// Consumes one input; returns an output on inputs `k M + M - 1`.
    #[inline]
    pub fn tick(&mut self, x: S) -> Option<S> {
        let y = match &mut self.lp {
            Some(lp) => lp.tick(x),
            None => x,
        };
        if self.dump {
            self.acc += y;
        }
        self.phase += 1;
        if self.phase < self.m {
            return None;
        }
        self.phase = 0;
        if self.dump {
            // Mean of the block. Multiplying by 1/M (not dividing) keeps M = 2^k exact and
            // is the same operation in every lane.
            let mean = self.acc * self.inv_m;
            self.acc = S::default();
            Some(mean)
        } else {
            Some(y)
        }
    }

    /// Processes a block, writing only the produced outputs; returns how many were written.
    /// No allocation. `output` must hold at least [`Decimator::outputs_for`]`(input.len())`
    /// samples (a programming error otherwise: panics before touching any state).
    pub fn process_block(&mut self, input: &[S], output: &mut [S]) -> usize {
        assert!(
            output.len() >= self.outputs_for(input.len()),
            "Decimator::process_block: output holds {} samples, {} needed",
            output.len(),
            self.outputs_for(input.len())
        );
        let mut k = 0;
        for &x in input {
            if let Some(y) = self.tick(x) {
                output[k] = y;
                k += 1;
            }
        }
        k
    }

    /// Back to the freshly built state (filter state, dump sum and output phase).
    pub fn reset(&mut self) {
        if let Some(lp) = &mut self.lp {
            lp.reset();
        }
        self.phase = 0;
        self.acc = S::default();
    }
}

impl<S: Sample> Stage for Decimator<S> {
    type Input = S;
    type Output = Option<S>;

    #[inline]
    fn tick(&mut self, x: S) -> Option<S> {
        Decimator::tick(self, x)
    }

    fn reset(&mut self) {
        Decimator::reset(self)
    }

    /// DC group delay in *input* samples, before the output instant: the filter's, plus
    /// `(M - 1)/2` for the dump's moving average.
    fn latency_samples(&self) -> f64 {
        let f = self.lp.as_ref().map_or(0.0, |lp| lp.latency_samples());
        let d = if self.dump {
            0.5 * (self.m as f64 - 1.0)
        } else {
            0.0
        };
        f + d
    }
}

impl<S: Sample> Response for Decimator<S> {
    /// Response of the linear part at the *input* rate (`f_hz` relative to `fs_in`), with
    /// the time origin at the output instant (input index `kM + M - 1`): an input
    /// `cos(2 pi f n/fs_in)` gives output k = `Re(H(f) exp(j 2 pi f (kM + M - 1)/fs_in))`
    /// plus whatever aliases in. The dump contributes `(1/M) sum_{i<M} exp(-j 2 pi f i/fs_in)`.
    fn response(&self, f_hz: f64) -> Complex64 {
        let f = self
            .lp
            .as_ref()
            .map_or(Complex64::new(1.0, 0.0), |lp| lp.response(f_hz));
        if !self.dump || self.m == 1 {
            return f;
        }
        // (1/M) (1 - z^-M) / (1 - z^-1) with z^-1 = 1 + u, written as ratios of accurate
        // differences; at (aliased) DC it is 1.
        let turns = f_hz / self.fs_in_hz;
        let u1 = u_of(turns);
        let um = u_of(turns * self.m as f64);
        let ma = if u1.norm() == 0.0 {
            Complex64::new(1.0, 0.0)
        } else {
            um / (u1 * self.m as f64)
        };
        f * ma
    }
}
