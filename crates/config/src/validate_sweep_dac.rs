//! The DAC's rounding of a stepped-sine sweep's drive. `gyroemu sweep` divides each response
//! by the nominal drive, and it drives one mode at a time, so the rounding's change of the
//! drive's fundamental is not cancelled by a second drive rounded alike (as in a Coriolis
//! phase): every Bode point and the fitted gain move with it.

use crate::config::Config;
use crate::validate_dac::dac_code;
use gyroemu_core::Complex64;

/// Above this change of a drive's fundamental (relative; 0.0087 dB, 0.057 deg) the sweep's
/// DAC rounding is stated.
pub const WARN_SWEEP_DAC_REL: f64 = 1e-3;

/// Input samples summed over all swept frequencies, per drive (at most; each frequency sums
/// at least [`MIN_SPAN`]): about 0.1 s of validation.
const BUDGET: u64 = 16_000_000;

/// Fewest samples summed at a frequency: a pattern of a few thousand samples repeats in it.
const MIN_SPAN: u64 = 4096;

/// Samples between exact re-sets of the rotated carrier phasor from the NCO's 64-bit word.
const RESYNC: u64 = 1024;

impl Config {
    /// Warns, per drive, when the DAC's rounding changes the drive's fundamental by more
    /// than [`WARN_SWEEP_DAC_REL`] at some swept frequency: a carrier of few samples per
    /// period repeats its rounding every period and never averages it out (7.3 %, 0.61 dB,
    /// at 4 bits and 16 samples per period; the sweep read it as the plant's, unwarned).
    ///
    /// The change is the rounding error's fundamental over the drive's, summed from the start
    /// of the frequency's averaging window (the sweep's boxcar after settling) over as much of
    /// it as [`BUDGET`] allows, at the carrier NCO's phase (re-set from its 64-bit word every
    /// [`RESYNC`] samples) through the board's phase shifter, with the quantiser's arithmetic
    /// ([`dac_code`]). A pattern that repeats is read exactly; one that drifts slowly is
    /// averaged as the window averages it (read over 4096 samples at the window's start
    /// alone, it had warned of 2.95e-3 where the emulation moved by 6e-4). The plant's
    /// filtering of the rounding's components beside the carrier is left out, so the figure
    /// errs high (by up to about 2 against the emulated Bode points, where it is small).
    pub(crate) fn validate_sweep_dac(&self, warnings: &mut Vec<String>) {
        use core::f64::consts::TAU;
        let Some(bits) = self.board.dac_bits else {
            return;
        };
        let half = (1u64 << (bits - 1)) as f64;
        let lsb = self.board.dac_full_scale / half;
        let fs = self.fs_hz();
        let freqs = self.sweep_frequencies_hz();
        // The averaging window in input samples, as much of it as the budget allows.
        let (settle, point) = self.sweep_point();
        let m = self.decimation() as u64;
        let start = settle * m;
        let span = (BUDGET / freqs.len().max(1) as u64)
            .max(MIN_SPAN)
            .min(point.window.samples() * m);
        let Ok(shifter) = gyroemu_board::drive_shifter(&self.board_params()) else {
            return;
        };
        for (k, a) in [self.drive.f1, self.f2()].into_iter().enumerate() {
            if !(a > 0.0 && a.is_finite()) {
                continue;
            }
            // The worst relative change over the swept frequencies, and where.
            let mut worst = (0.0, Complex64::new(1.0, 0.0), f64::NAN);
            for &f in &freqs {
                let Ok(nco) = gyroemu_nco::Nco::new(f, fs, 0.0) else {
                    continue;
                };
                let word = nco.step_word();
                let phasor = |n: u64| {
                    let turn = word.wrapping_mul(n) as f64 / 2f64.powi(64);
                    Complex64::from_polar(1.0, TAU * turn)
                };
                let step = phasor(1);
                let mut err = Complex64::new(0.0, 0.0);
                let mut c = phasor(start);
                for n in start..start + span {
                    if (n - start).is_multiple_of(RESYNC) {
                        c = phasor(n);
                    }
                    // The drive's own phasor: the carrier, or its shifted copy.
                    let p = if k == 0 { c } else { shifter.apply(c) };
                    let x = a * p.re;
                    err += (dac_code(x, lsb, half) * lsb - x) * p.conj();
                    c *= step;
                }
                let gain = 1.0 + err * (2.0 / (span as f64 * a));
                let rel = (gain - 1.0).norm();
                if rel > worst.0 {
                    worst = (rel, gain, nco.f_hz());
                }
            }
            let (rel, gain, at) = worst;
            if rel > WARN_SWEEP_DAC_REL {
                warnings.push(format!(
                    "the DAC's rounding (board.dac_bits = {bits}, step {lsb:e} against drive.f{} = {a:e}) changes that drive's fundamental by up to {rel:.2e} over the averaging window (at {at} Hz: {:+.3} dB, {:+.3} deg): the sweep divides by the nominal drive, so its Bode points and fitted gain carry that change; raise board.dac_bits or the drive",
                    k + 1,
                    20.0 * gain.norm().log10(),
                    gain.arg().to_degrees()
                ));
            }
        }
    }
}
