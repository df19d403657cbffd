//! The responses of the board's own linear stages, built by the same code the board runs, so
//! that the read-out compensates exactly the chain that produced the data.

use crate::board::{modulation_hz, table_nco};
use crate::params::{build_lowpass, build_tia, BoardParams};
use crate::point::Point;
use gyroemu_core::{Complex64, ParamResult, Response};
use gyroemu_lpf::{KahanSum, LowPass};
use gyroemu_mixer::table_reference;
use gyroemu_nco::{phasor_of_word, Nco};
use gyroemu_resonator::hold_response;
use gyroemu_tia::Tia;

/// The linear stages between the drive and the stage-2 read-out, as built.
#[derive(Clone, Debug)]
pub struct ChainResponse {
    tia: Tia<f64>,
    lowpass: LowPass<f64>,
    carrier_hz: f64,
    fs_hz: f64,
    decimation: usize,
    /// The table frequency as the board's table oscillator realises it, Hz (0: no table).
    table_hz: f64,
}

impl ChainResponse {
    /// The responses of the board `p` describes.
    pub fn new(p: &BoardParams) -> ParamResult<Self> {
        Ok(Self {
            tia: build_tia(p)?,
            lowpass: build_lowpass(p)?,
            carrier_hz: p.carrier_hz,
            fs_hz: p.fs_hz(),
            decimation: p.decimation,
            table_hz: table_nco(p)?.f_hz(),
        })
    }

    /// The DAC's zero-order hold at `f_hz`, which the plant realises (the DAC's quantiser is
    /// not linear and is left out).
    pub fn dac_hold(&self, f_hz: f64) -> Complex64 {
        hold_response(f_hz, self.fs_hz)
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

    /// The stage-2 window leak of a rotating point: `W = sum_j w_j e^{j 2 Omega t_j} / sum_j
    /// w_j` over the point's averaging window, with `t_j` the instants of the decimated
    /// samples it averages (input index (n_settle + j) M + M - 1) and `Omega` the modulation
    /// oscillator's exact frequency. Stage 2 averages `2 z cos(Omega t)` and `2 z sin(Omega t)`
    /// over that window; with `z = Z+ e^{j Omega t} + Z- e^{-j Omega t}` its averages are
    /// `(C - jS)/2 = Z+ + conj(W) Z-` and `(C + jS)/2 = Z- + W Z+`, so `W` is exactly what a
    /// window of a not quite whole number of half periods leaks (0 for whole periods of a
    /// continuous average). [`unleak_sidebands`] undoes it.
    pub fn stage2_leak(&self, point: &Point, n_settle: u64) -> ParamResult<Complex64> {
        let nco = Nco::new(
            modulation_hz(crate::params::Shape::Rotating, point.rate_rad_s),
            self.fs_hz,
            0.0,
        )?;
        let step = nco.step_word();
        let m = self.decimation as u64;
        let (mut sum, mut wsum) = (KahanSum::<f64>::new(), KahanSum::<f64>::new());
        let (mut sum_im, samples) = (KahanSum::<f64>::new(), point.window.samples());
        for j in 0..samples {
            let w = point.window.weight(j);
            if w == 0.0 {
                continue;
            }
            let n = (n_settle + j) * m + m - 1;
            // The oscillator's phase word at sample n, doubled: e^{j 2 Omega t_n} exactly as
            // the word arithmetic defines it (wrapping is the 2 pi periodicity).
            let p = phasor_of_word(step.wrapping_mul(n).wrapping_mul(2));
            sum.add(w * p.re);
            sum_im.add(w * p.im);
            wsum.add(w);
        }
        Ok(Complex64::new(sum.value(), sum_im.value()) / wsum.value())
    }

    /// The rate-table window's leak between table harmonics: `K(d) = sum_j w_j e^{j d theta_j}
    /// / sum_j w_j` for `d = -2N ..= 2N` (index `d + 2N`), over the point's averaging window,
    /// with `theta_j` the table phase at each averaged output's instant (input index
    /// `(n_settle + j) M + M - 1`), taken as the board takes it ([`table_reference`]). The
    /// average of `z e^{-j n theta}` is then `A_n = sum_m Z_m K(m - n)` for the harmonics
    /// `Z_m` of `z`; [`unleak_table_harmonics`] solves it.
    pub fn table_leak(&self, point: &Point, n_settle: u64, harmonics: usize) -> Vec<Complex64> {
        let m = self.decimation as u64;
        let nd = 4 * harmonics + 1;
        let mut sum: Vec<[KahanSum<f64>; 2]> = vec![[KahanSum::new(), KahanSum::new()]; nd];
        let mut wsum = KahanSum::<f64>::new();
        for j in 0..point.window.samples() {
            let w = point.window.weight(j);
            if w == 0.0 {
                continue;
            }
            let n = (n_settle + j) * m + m - 1;
            let e = table_reference(n, self.table_hz, self.fs_hz).conj();
            // e^{j d theta} for d = 0 ..= 2N, the negative ones as conjugates.
            let mut p = Complex64::new(w, 0.0);
            for d in 0..=2 * harmonics {
                for (idx, v) in [(2 * harmonics + d, p), (2 * harmonics - d, p.conj())] {
                    sum[idx][0].add(v.re);
                    sum[idx][1].add(v.im);
                }
                p *= e;
            }
            wsum.add(w);
        }
        let mut k: Vec<Complex64> = sum
            .iter()
            .map(|[re, im]| Complex64::new(re.value(), im.value()) / wsum.value())
            .collect();
        // d = 0 was added twice.
        k[2 * harmonics] *= 0.5;
        k
    }

    /// The table frequency the board realises, Hz (0 outside rate-table runs).
    pub fn table_hz(&self) -> f64 {
        self.table_hz
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

/// The sideband phasors `(Z+, Z-)` of a rotating point from its stage-2 averages `C`, `S` and
/// the window leak `w` of [`ChainResponse::stage2_leak`]: the averages are `B = (C - jS)/2 =
/// Z+ + conj(w) Z-` and `A = (C + jS)/2 = Z- + w Z+`, solved exactly:
/// `Z+ = (B - conj(w) A) / (1 - |w|^2)`, `Z- = (A - w B) / (1 - |w|^2)`. Returned as the
/// `(C, S)` a leak-free window would have given, `C = Z+ + Z-`, `S = j (Z+ - Z-)`, so every
/// estimator reads them unchanged.
pub fn unleak_sidebands(c: Complex64, s: Complex64, w: Complex64) -> (Complex64, Complex64) {
    let j = Complex64::new(0.0, 1.0);
    let b = (c - j * s) * 0.5;
    let a = (c + j * s) * 0.5;
    let det = 1.0 - w.norm_sqr();
    let zp = (b - w.conj() * a) / det;
    let zm = (a - w * b) / det;
    (zp + zm, j * (zp - zm))
}

/// The harmonics `Z_{-N} .. Z_N` of a rate-table point's `z` from its window averages `A_n` of
/// `z e^{-j n theta}` and the window's leak `K` ([`ChainResponse::table_leak`]): solves
/// `A_n = sum_m Z_m K(m - n)` exactly (a window of not quite whole table periods mixes the
/// harmonics a little). NaN if the system is singular.
pub fn unleak_table_harmonics(a: &[Complex64], leak: &[Complex64]) -> Vec<Complex64> {
    let nb = a.len();
    let h = nb / 2;
    let mat = nalgebra::DMatrix::from_fn(nb, nb, |n, m| leak[m + 2 * h - n]);
    let rhs = nalgebra::DVector::from_column_slice(a);
    match mat.lu().solve(&rhs) {
        Some(x) => x.iter().copied().collect(),
        None => vec![Complex64::new(f64::NAN, f64::NAN); nb],
    }
}
