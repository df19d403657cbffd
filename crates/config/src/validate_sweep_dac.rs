//! The DAC's rounding of a stepped-sine sweep's drive. `gyroemu sweep` divides each response
//! by the nominal drive, and it drives one mode at a time, so the rounding's change of the
//! drive's fundamental is not cancelled by a second drive rounded alike (as in a Coriolis
//! phase): every Bode point and the fitted gain move with it.

use crate::config::Config;
use gyroemu_core::Complex64;

/// Above this change of a drive's fundamental (relative; 0.0087 dB, 0.057 deg) the sweep's
/// DAC rounding is stated.
pub const WARN_SWEEP_DAC_REL: f64 = 1e-3;

/// Samples summed per swept frequency (fewer for long sweeps, to bound the work to about
/// 4e6 samples): enough to see a pattern of a few thousand samples and the rounding's
/// average gain where the pattern never repeats.
const SPAN: usize = 4096;

impl Config {
    /// Warns, per drive, when the DAC's rounding changes the drive's fundamental by more
    /// than [`WARN_SWEEP_DAC_REL`] at some swept frequency: a carrier of few samples per
    /// period repeats its rounding every period and never averages it out (7.3 %, 0.61 dB,
    /// at 4 bits and 16 samples per period; the sweep read it as the plant's, unwarned).
    /// The change is the error's fundamental over the drive's amplitude, summed over the
    /// swept carrier as the NCO realises it, the quantiser's arithmetic (mid-tread, ties away
    /// from zero, clipped to [-FS, FS - step]).
    pub(crate) fn validate_sweep_dac(&self, warnings: &mut Vec<String>) {
        use core::f64::consts::TAU;
        let Some(bits) = self.board.dac_bits else {
            return;
        };
        let half = (1u64 << (bits - 1)) as f64;
        let lsb = self.board.dac_full_scale / half;
        let fs = self.fs_hz();
        let freqs = self.sweep_frequencies_hz();
        let span = (4_000_000 / freqs.len().max(1)).clamp(256, SPAN);
        let shift = (90.0 + self.board.phase_shifter_error_deg).to_radians();
        for (k, (a, phase0)) in [(self.drive.f1, 0.0), (self.f2(), -shift)]
            .into_iter()
            .enumerate()
        {
            if !(a > 0.0 && a.is_finite()) {
                continue;
            }
            // The worst relative change over the swept frequencies, and where.
            let mut worst = (0.0, Complex64::new(1.0, 0.0), f64::NAN);
            for &f in &freqs {
                let Ok(nco) = gyroemu_nco::Nco::new(f, fs, 0.0) else {
                    continue;
                };
                let w = TAU * nco.f_hz() / fs;
                let err: Complex64 = (0..span)
                    .map(|n| {
                        let th = w * n as f64 + phase0;
                        let x = a * th.cos();
                        let q = (x / lsb).round().clamp(-half, half - 1.0) * lsb;
                        Complex64::from_polar(q - x, -th)
                    })
                    .sum();
                let gain = 1.0 + err * (2.0 / (span as f64 * a));
                let rel = (gain - 1.0).norm();
                if rel > worst.0 {
                    worst = (rel, gain, nco.f_hz());
                }
            }
            let (rel, gain, at) = worst;
            if rel > WARN_SWEEP_DAC_REL {
                warnings.push(format!(
                    "the DAC's rounding (board.dac_bits = {bits}, step {lsb:e} against drive.f{} = {a:e}) changes that drive's fundamental by up to {rel:.2e} (at {at} Hz: {:+.3} dB, {:+.3} deg): the sweep divides by the nominal drive, so its Bode points and fitted gain carry that change; raise board.dac_bits or the drive",
                    k + 1,
                    20.0 * gain.norm().log10(),
                    gain.arg().to_degrees()
                ));
            }
        }
    }
}
