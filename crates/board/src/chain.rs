//! The responses of the board's own linear stages, built by the same code the board runs, so
//! that the read-out compensates exactly the chain that produced the data.

use crate::params::{build_dac, build_lowpass, build_tia, BoardParams};
use gyroemu_am::Dac;
use gyroemu_core::{Complex64, ParamResult, Response};
use gyroemu_lpf::LowPass;
use gyroemu_tia::Tia;

/// The linear stages between the drive and the stage-2 read-out, as built.
#[derive(Clone, Debug)]
pub struct ChainResponse {
    dac: Dac<f64>,
    tia: Tia<f64>,
    lowpass: LowPass<f64>,
    carrier_hz: f64,
    fs_hz: f64,
    decimation: usize,
}

impl ChainResponse {
    /// The responses of the board `p` describes.
    pub fn new(p: &BoardParams) -> ParamResult<Self> {
        Ok(Self {
            dac: build_dac(p)?,
            tia: build_tia(p)?,
            lowpass: build_lowpass(p)?,
            carrier_hz: p.carrier_hz,
            fs_hz: p.fs_hz(),
            decimation: p.decimation,
        })
    }

    /// The DAC's zero-order hold at `f_hz` (its quantiser is not linear and is left out).
    pub fn dac_hold(&self, f_hz: f64) -> Complex64 {
        self.dac.response(f_hz)
    }

    /// The TIA at `f_hz`.
    pub fn tia(&self, f_hz: f64) -> Complex64 {
        self.tia.response(f_hz)
    }

    /// The stage-1 low-pass at baseband `f_hz`, at the input rate (the decimated output is the
    /// filter's output at input sample kM + M - 1, so no delay is added by decimation).
    pub fn lowpass(&self, f_hz: f64) -> Complex64 {
        self.lowpass.response(f_hz)
    }

    /// The carrier frequency, Hz.
    pub fn carrier_hz(&self) -> f64 {
        self.carrier_hz
    }

    /// Sample rate and decimation of the chain.
    pub fn rates(&self) -> (f64, usize) {
        (self.fs_hz, self.decimation)
    }

    /// The phase the chain adds to the rotating estimate psi at modulation frequency `fm_hz`
    /// (signed like Omega), split into its terms, radians: the TIA and the DAC hold act on the
    /// two sidebands at carrier -+ fm, `(arg H(fc - fm) - arg H(fc + fm))/2`; the stage-1
    /// low-pass delays the envelope (`-arg L(fm)`) but not the Omega references, which are
    /// taken at the decimated instants.
    pub fn rotating_terms(&self, fm_hz: f64) -> RotatingTerms {
        let f = fm_hz.abs();
        let sgn = fm_hz.signum();
        let fc = self.carrier_hz;
        let term = |h: &dyn Fn(f64) -> Complex64| 0.5 * (h(fc - f).arg() - h(fc + f).arg());
        RotatingTerms {
            tia_rad: sgn * term(&|x| self.tia(x)),
            dac_hold_rad: sgn * term(&|x| self.dac_hold(x)),
            lowpass_rad: -sgn * self.lowpass(f).arg(),
        }
    }
}

/// The chain terms of a rotating run at one modulation frequency, radians (added to psi).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotatingTerms {
    /// The TIA's term.
    pub tia_rad: f64,
    /// The DAC hold's term (about Omega Ts / 2).
    pub dac_hold_rad: f64,
    /// The stage-1 low-pass's term.
    pub lowpass_rad: f64,
}

impl RotatingTerms {
    /// Their sum.
    pub fn total_rad(&self) -> f64 {
        self.tia_rad + self.dac_hold_rad + self.lowpass_rad
    }
}
