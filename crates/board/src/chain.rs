//! The responses of the board's own linear stages, built by the same code the board runs, so
//! that the read-out compensates exactly the chain that produced the data.

use crate::board::{modulation_hz, table_nco};
use crate::params::{build_lowpass, build_tia, BoardParams};
use crate::point::Point;
use gyroemu_core::{Complex64, ParamResult, Response};
use gyroemu_lpf::{KahanSum, LowPass, Window};
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
        Ok(stage2_leak_blocked(
            nco.step_word(),
            self.decimation as u64,
            n_settle,
            &point.window,
        ))
    }

    /// The rate-table window's leak between table harmonics: `K(d) = sum_j w_j e^{j d theta_j}
    /// / sum_j w_j` for `d = -2N ..= 2N` (index `d + 2N`), over the point's averaging window,
    /// with `theta_j` the table phase at each averaged output's instant (input index
    /// `(n_settle + j) M + M - 1`), taken as the board takes it ([`table_reference`]). The
    /// average of `z e^{-j n theta}` is then `A_n = sum_m Z_m K(m - n)` for the harmonics
    /// `Z_m` of `z`; [`unleak_table_harmonics`] solves it.
    pub fn table_leak(&self, point: &Point, n_settle: u64, harmonics: usize) -> Vec<Complex64> {
        let m = self.decimation as u64;
        let top = 2 * harmonics;
        // K(d) for d = 0 ..= 2N; the weights are real, so K(-d) = conj K(d), whose sums are
        // the same sums negated (rounding to nearest is symmetric): half the work.
        let mut sums = LeakSums::new(top + 1);
        let mut wsum = KahanSum::<f64>::new();
        // Each term's phasor w e^{j d theta} comes from a chain of products in d, one chain
        // per window sample: chains of TABLE_BLOCK samples run side by side (a chain alone
        // waits on each product), then their terms are added in sample order (the same sums
        // in the same order as one sample at a time, so the same bits).
        let mut block = LeakBlock::new(top + 1);
        for j in 0..point.window.samples() {
            let w = point.window.weight(j);
            if w == 0.0 {
                continue;
            }
            let n = (n_settle + j) * m + m - 1;
            block.push(w, table_reference(n, self.table_hz, self.fs_hz).conj());
            wsum.add(w);
            if block.len == TABLE_BLOCK {
                block.add_to(&mut sums);
            }
        }
        block.add_to(&mut sums);
        let k = |d: usize| sums.value(d) / wsum.value();
        (0..=2 * top)
            .map(|i| match i.checked_sub(top) {
                Some(d) => k(d),
                None => k(top - i).conj(),
            })
            .collect()
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

/// Averaged outputs per block of [`stage2_leak_blocked`].
const LEAK_BLOCK: u64 = 64;

/// `sum_j w_j e^{j 2 Omega t_j} / sum_j w_j` for the oscillator of phase step `step` (words
/// of 2^-64 turn per input sample), averaged output `j` at input sample
/// `(n_settle + j) m + m - 1`. Its doubled phase word is an exact progression `w0 + j d`
/// (wrapping is the 2 pi periodicity), so each block of [`LEAK_BLOCK`] outputs is
/// `e^{j(w0 + b d)} sum_i w_{b+i} e^{j i d}`: one exact phasor per block, and in a boxcar's
/// interior the inner sum is the same for every block. Why: the per-output phasor and its
/// compensated sums took 1 % of a `reproduce` (Fig. 9's 7 x 1.2e6 outputs); this is
/// within 1e-13 of [`stage2_leak_reference`] (tested), which moves a read-out phase by about
/// 1e-13 rad times the ratio of the sidebands.
pub(crate) fn stage2_leak_blocked(step: u64, m: u64, n_settle: u64, window: &Window) -> Complex64 {
    let w0 = step.wrapping_mul(n_settle * m + m - 1).wrapping_mul(2);
    let d = step.wrapping_mul(m).wrapping_mul(2);
    let rot: [Complex64; LEAK_BLOCK as usize] =
        core::array::from_fn(|i| phasor_of_word(d.wrapping_mul(i as u64)));
    let whole: Complex64 = rot.iter().sum();
    // Outputs of weight 1 in a boxcar: the blocks wholly inside take `whole`.
    let ones = match *window {
        Window::Boxcar { n, .. } => n,
        Window::Hann { .. } => 0,
    };
    let (mut sum_re, mut sum_im, mut wsum) = (
        KahanSum::<f64>::new(),
        KahanSum::<f64>::new(),
        KahanSum::<f64>::new(),
    );
    let samples = window.samples();
    let mut b0 = 0;
    while b0 < samples {
        let len = LEAK_BLOCK.min(samples - b0);
        let (inner, weights) = if len == LEAK_BLOCK && b0 + LEAK_BLOCK <= ones {
            (whole, LEAK_BLOCK as f64)
        } else {
            (0..len).fold((Complex64::new(0.0, 0.0), 0.0), |(z, ws), i| {
                let w = window.weight(b0 + i);
                (z + rot[i as usize] * w, ws + w)
            })
        };
        let v = phasor_of_word(w0.wrapping_add(d.wrapping_mul(b0))) * inner;
        sum_re.add(v.re);
        sum_im.add(v.im);
        wsum.add(weights);
        b0 += len;
    }
    Complex64::new(sum_re.value(), sum_im.value()) / wsum.value()
}

/// [`stage2_leak_blocked`] by its definition, one exact phasor and compensated sum per
/// averaged output (the reference its tests check it against).
#[cfg(test)]
pub(crate) fn stage2_leak_reference(
    step: u64,
    m: u64,
    n_settle: u64,
    window: &Window,
) -> Complex64 {
    let (mut sum, mut wsum) = (KahanSum::<f64>::new(), KahanSum::<f64>::new());
    let mut sum_im = KahanSum::<f64>::new();
    for j in 0..window.samples() {
        let w = window.weight(j);
        if w == 0.0 {
            continue;
        }
        let n = (n_settle + j) * m + m - 1;
        let p = phasor_of_word(step.wrapping_mul(n).wrapping_mul(2));
        sum.add(w * p.re);
        sum_im.add(w * p.im);
        wsum.add(w);
    }
    Complex64::new(sum.value(), sum_im.value()) / wsum.value()
}

/// Window samples whose leak terms [`ChainResponse::table_leak`] forms side by side.
const TABLE_BLOCK: usize = 8;

/// Compensated sums (as [`KahanSum`] adds them) of the leak's real and imaginary parts, one
/// per harmonic distance, each array contiguous so an add runs over every distance at once.
struct LeakSums {
    re: [Vec<f64>; 2],
    im: [Vec<f64>; 2],
}

impl LeakSums {
    fn new(n: usize) -> Self {
        Self {
            re: [vec![0.0; n], vec![0.0; n]],
            im: [vec![0.0; n], vec![0.0; n]],
        }
    }

    /// [`KahanSum::value`] of distance `d`.
    fn value(&self, d: usize) -> Complex64 {
        Complex64::new(self.re[0][d] + self.re[1][d], self.im[0][d] + self.im[1][d])
    }
}

/// [`KahanSum::add`] of `x[d]` to sum `d` (`[sum, comp]`), for every `d`.
#[inline(always)]
fn kahan_add_each(acc: &mut [Vec<f64>; 2], x: &[f64]) {
    let [sum, comp] = acc;
    for ((s, c), &x) in sum.iter_mut().zip(comp.iter_mut()).zip(x) {
        let t = *s + x;
        let z = t - *s;
        *c += (*s - (t - z)) + (x - z);
        *s = t;
    }
}

/// Up to [`TABLE_BLOCK`] window samples' weights and conjugate table phasors, then their
/// terms `w e^{-j d theta}` for `d = 0 .. n`, sample by sample.
struct LeakBlock {
    w: [f64; TABLE_BLOCK],
    e: [Complex64; TABLE_BLOCK],
    len: usize,
    terms_re: Vec<f64>,
    terms_im: Vec<f64>,
}

impl LeakBlock {
    fn new(n: usize) -> Self {
        Self {
            w: [0.0; TABLE_BLOCK],
            e: [Complex64::new(0.0, 0.0); TABLE_BLOCK],
            len: 0,
            terms_re: vec![0.0; n * TABLE_BLOCK],
            terms_im: vec![0.0; n * TABLE_BLOCK],
        }
    }

    fn push(&mut self, w: f64, e: Complex64) {
        self.w[self.len] = w;
        self.e[self.len] = e;
        self.len += 1;
    }

    /// Adds the block's terms to `sums` in sample order and empties it.
    fn add_to(&mut self, sums: &mut LeakSums) {
        let n = sums.re[0].len();
        // p = w, then p *= e at each distance: `Complex64`'s `*=` (re e.re - im e.im,
        // im e.re + re e.im), one chain per sample, all of them at once (the unused ones
        // run on zeros and are not added).
        let mut re = self.w;
        let mut im = [0.0; TABLE_BLOCK];
        let er: [f64; TABLE_BLOCK] = core::array::from_fn(|k| self.e[k].re);
        let ei: [f64; TABLE_BLOCK] = core::array::from_fn(|k| self.e[k].im);
        for d in 0..n {
            for k in 0..TABLE_BLOCK {
                self.terms_re[k * n + d] = re[k];
                self.terms_im[k * n + d] = im[k];
                let a = re[k];
                re[k] = re[k] * er[k] - im[k] * ei[k];
                im[k] = im[k] * er[k] + a * ei[k];
            }
        }
        for k in 0..self.len {
            kahan_add_each(&mut sums.re, &self.terms_re[k * n..][..n]);
            kahan_add_each(&mut sums.im, &self.terms_im[k * n..][..n]);
        }
        self.len = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A seeded walk over phase steps (any word: the modulation can be near DC or near
    /// Nyquist), decimations, settlings and windows of every shape and edge.
    fn cases() -> Vec<(u64, u64, u64, Window)> {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut out = Vec::new();
        for k in 0..60u64 {
            let step = match k % 3 {
                0 => next(),
                1 => next() >> 20, // slow modulation: a leak near 1
                _ => next() >> 40,
            };
            let m = 1 + next() % 200;
            let n_settle = next() % 5000;
            let n = next() % 3000;
            let window = match k % 4 {
                0 => Window::Boxcar { n, frac: 0.0 },
                1 => Window::Boxcar {
                    n,
                    frac: (next() % 1000) as f64 / 1000.0,
                },
                2 => Window::Boxcar {
                    n: 64 * (n / 64),
                    frac: 0.5,
                },
                _ => Window::Hann { n: n.max(2) },
            };
            out.push((step, m, n_settle, window));
        }
        out
    }

    #[test]
    fn blocked_leak_matches_the_per_output_sum() {
        for (step, m, n_settle, window) in cases() {
            let fast = stage2_leak_blocked(step, m, n_settle, &window);
            let slow = stage2_leak_reference(step, m, n_settle, &window);
            // |W| <= 1; each block adds a few ulp of rounding.
            assert!(
                (fast - slow).norm() < 1e-13,
                "step {step}, m {m}, settle {n_settle}, {window:?}: {fast} vs {slow}"
            );
        }
    }

    #[test]
    fn boxcar_leak_is_the_geometric_sum() {
        // Whole outputs only: W = e^{j phi0} (1 - r^N) / (N (1 - r)), r = e^{j delta}, in
        // closed form with libm's trigonometry (independent of the phase-word tables).
        let tau = core::f64::consts::TAU;
        for (step, m, n_settle, n) in [
            (1u64 << 50, 100u64, 400u64, 1000u64),
            (3u64 << 44, 64, 0, 5000),
            (12_345_678_901_234, 7, 33, 129),
        ] {
            let turns = |w: u64| w as f64 / 18_446_744_073_709_551_616.0;
            let phi0 = tau * turns(step.wrapping_mul(n_settle * m + m - 1).wrapping_mul(2));
            let delta = tau * turns(step.wrapping_mul(m).wrapping_mul(2));
            let e = |a: f64| Complex64::new(a.cos(), a.sin());
            let want = e(phi0) * (Complex64::new(1.0, 0.0) - e(n as f64 * delta))
                / ((Complex64::new(1.0, 0.0) - e(delta)) * n as f64);
            let got = stage2_leak_blocked(step, m, n_settle, &Window::Boxcar { n, frac: 0.0 });
            assert!((got - want).norm() < 1e-11, "{got} vs {want}");
        }
    }
}
