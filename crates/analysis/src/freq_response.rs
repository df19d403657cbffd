//! `gyroemu sweep` as one call: the stepped-sine measurement (`stepped_sine`), a resonance fit
//! of each mode's driven response (`resonance_fit`), and what each fit is checked against:
//! the configured device; the natural frequencies and Q of the coupled plant (the eigenvalues
//! of its state matrix: quadrature coupling moves the modes apart); and the same fit applied
//! to the plant's exact held-drive steady state at the same frequencies, which is what a
//! perfect emulation of this board measures (hold images and coupling included). Beside the
//! one-mode fits, the whole 2 x 2 response identifies the plant's matrices (`matrix_fit`):
//! each mode's own f0 and Q and the quadrature coupling, comparable with `[device]` as set.

use crate::matrix_fit::{fit_matrix, MatrixFit};
use crate::resonance_fit::{fit_resonance, ResonanceFit};
use crate::stepped_sine::{run_stepped_sine, SteppedSine};
use gyroemu_config::Config;
use gyroemu_core::Complex64;
use gyroemu_experiment::{Reporter, SweepError};
use gyroemu_resonator::{continuous_steady_state, Resonator, ResonatorParams};
pub use gyroemu_theory::{coupled_modes, held_response};
use serde::Serialize;

/// One mode's fit and what it is checked against.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ModeCheck {
    /// 1 or 2.
    pub mode: usize,
    /// The fit of the measured driven response (`None`: no resonance found).
    pub fit: Option<ResonanceFit>,
    /// The configured resonance, Hz.
    pub configured_f0_hz: f64,
    /// The configured Q.
    pub configured_q: f64,
    /// The coupled plant's natural frequency of this mode, Hz (its state matrix's eigenvalue
    /// s: |s| / 2 pi; the configured one without quadrature coupling).
    pub coupled_f0_hz: f64,
    /// The coupled plant's Q of this mode, |s| / (2 Re(-s)).
    pub coupled_q: f64,
    /// The fit of the exact held-drive steady state at the swept frequencies: what the
    /// measurement gives when the emulation is exact.
    pub expected: Option<ResonanceFit>,
}

impl ModeCheck {
    /// Fitted f0 minus the configured one, Hz (NaN without a fit).
    pub fn f0_error_hz(&self) -> f64 {
        self.fit
            .map_or(f64::NAN, |f| f.f0_hz - self.configured_f0_hz)
    }

    /// Fitted Q over the configured one, minus 1 (NaN without a fit).
    pub fn q_rel_error(&self) -> f64 {
        self.fit.map_or(f64::NAN, |f| f.q / self.configured_q - 1.0)
    }

    /// The configured half-bandwidth f0/(2Q), Hz.
    pub fn configured_half_bandwidth_hz(&self) -> f64 {
        self.configured_f0_hz / (2.0 * self.configured_q)
    }
}

/// The whole frequency response: the measurement and both modes' fits.
#[derive(Clone, Debug, PartialEq)]
pub struct FrequencyResponse {
    /// The measured responses.
    pub measured: SteppedSine,
    /// Mode 1 and mode 2.
    pub modes: [ModeCheck; 2],
    /// The plant's matrices identified from the whole 2 x 2 response (`None`: too few
    /// usable frequencies).
    pub matrix: Option<MatrixFit>,
}

impl FrequencyResponse {
    /// Fitted f0 of mode 2 minus that of mode 1, and its standard error, Hz.
    pub fn mode_split_hz(&self) -> (f64, f64) {
        match (self.modes[0].fit, self.modes[1].fit) {
            (Some(a), Some(b)) => (b.f0_hz - a.f0_hz, a.f0_sigma_hz.hypot(b.f0_sigma_hz)),
            _ => (f64::NAN, f64::NAN),
        }
    }
}

/// Above this departure of a fitted mass from 1 the 2 x 2 fit is stated with a warning.
pub const MATRIX_MASS_WARNED: f64 = 0.01;

/// Above this departure of a fitted mass from 1 the 2 x 2 fit is not read.
pub const MATRIX_MASS_REFUSED: f64 = 0.1;

/// Fits both modes of a measured response and sets the checks beside them.
pub fn frequency_response_from(cfg: &Config, mut measured: SteppedSine) -> FrequencyResponse {
    let params = cfg.resonator_params();
    let coupled = coupled_modes(&params);
    let freqs: Vec<f64> = measured.points.iter().map(|p| p.freq_hz).collect();
    let plant = Resonator::<f64>::new(&params, 0.0).ok();
    let configured = cfg.mode_resonances_hz();
    // The modes whose coupling warning already says their sigmas describe the fit alone.
    let mut mixed = [false; 2];
    let modes = core::array::from_fn(|m| {
        let h: Vec<Complex64> = measured.points.iter().map(|p| p.response[m][m]).collect();
        let expected = plant.as_ref().and_then(|pl| {
            let h: Vec<Complex64> = freqs.iter().map(|&f| held_response(pl, f, m)[m]).collect();
            fit_resonance(&freqs, &h)
        });
        let (f0, b) = configured[m];
        let cont = fit_resonance(&freqs, &continuous(&params, &freqs, m));
        if let Some(cont) = &cont {
            // Without coupling a driven response is one mode's, exactly the model; with it,
            // the neighbour's residue pulls the fit off both coupled modes (on a matched
            // device each response is half of each, and the fit read a split of 0 for 0.034
            // Hz, at 400 sigma).
            let (cf, cq) = coupled[m];
            let cb = cf / (2.0 * cq);
            let (df, dq) = ((cont.f0_hz - cf) / cb, cont.q / cq - 1.0);
            if !(df.abs() <= COUPLING_BIAS_WARNED && dq.abs() <= COUPLING_BIAS_WARNED) {
                mixed[m] = true;
                measured.warnings.push(format!(
                    "mode {}: quadrature coupling mixes both modes into its driven response, so a one-mode fit reads no mode of the device: even a perfect emulation fits f0 {:+.3e} half-bandwidths and Q {:+.3e} (relative) off the coupled plant's mode ({cf} Hz, Q {cq:.1}); this fit's f0, Q, sigmas and the mode split describe the fit, not the device: read coupled_f0_hz and matrix_fit",
                    m + 1,
                    df,
                    dq
                ));
            }
        }
        if let (Some(held), Some(cont)) = (&expected, cont) {
            let (df, dq) = ((held.f0_hz - cont.f0_hz) / b, held.q / cont.q - 1.0);
            if df.abs() > HOLD_BIAS_WARNED || dq.abs() > HOLD_BIAS_WARNED {
                measured.warnings.push(format!(
                    "mode {}: the DAC's zero-order hold biases its fit: a perfect emulation reads f0 {:+.3e} half-bandwidths and Q {:+.3e} (relative) from the continuous-drive plant's response at these frequencies (expected_f0_hz, expected_q); raise fs_hz to shrink it",
                    m + 1,
                    df,
                    dq
                ));
            }
        }
        let why = match fit_resonance(&freqs, &h) {
            None => Err("no resonance is found in the data (a fitted f0^2 or damping that is not positive, or fewer than three finite points)".to_string()),
            Some(fit) => unsupported(&fit).map_or(Ok(fit), Err),
        };
        if let Some(caveat) = why.as_ref().ok().and_then(|f| unresolved(f, &freqs)) {
            measured.warnings.push(format!("mode {}: {caveat}", m + 1));
        }
        let fit = why
            .map_err(|why| {
                measured.warnings.push(format!(
                    "mode {}: the resonance fit is not read (null): {why}",
                    m + 1
                ))
            })
            .ok();
        ModeCheck {
            mode: m + 1,
            fit,
            configured_f0_hz: f0,
            configured_q: f0 / (2.0 * b),
            coupled_f0_hz: coupled[m].0,
            coupled_q: coupled[m].1,
            expected,
        }
    });
    for w in beyond_sigma(&modes, mixed) {
        measured.warnings.push(w);
    }
    let responses: Vec<_> = measured.points.iter().map(|p| p.response).collect();
    // Dividing out the chain leaves unit masses; a fit whose masses depart from 1 describes
    // noise (or hold images) more than the plant: a 2x2 fit read mass 0.28, Q 605 against
    // 2000 and a coupling of -1.4e6 against 0 with no warning and no sigma.
    let matrix = fit_matrix(&freqs, &responses).and_then(|fit| {
        let off = fit.mass.iter().map(|m| (m - 1.0).abs()).fold(0.0, f64::max);
        if off.is_nan() || off > MATRIX_MASS_REFUSED {
            measured.warnings.push(format!(
                "matrix_fit is not read (null): its masses {:?} depart from the 1 that dividing out the chain leaves by more than {} %, so noise or the hold's images dominate the 2 x 2 identification",
                fit.mass,
                MATRIX_MASS_REFUSED * 100.0
            ));
            return None;
        }
        if off > MATRIX_MASS_WARNED {
            measured.warnings.push(format!(
                "matrix_fit: its masses {:?} depart from 1 by up to {:.1} %: its f0, Q and coupling are no better than that",
                fit.mass,
                off * 100.0
            ));
        }
        if let Some(w) = plant.as_ref().and_then(|pl| matrix_hold_bias(cfg, pl, &freqs)) {
            measured.warnings.push(w);
        }
        Some(fit)
    });
    FrequencyResponse {
        measured,
        modes,
        matrix,
    }
}

/// Above this many of its sigmas between what a perfect emulation fits and the coupled
/// plant's mode, a fit's sigma is stated not to cover its bias (if the bias also passes
/// [`BIAS_FLOOR`]).
pub const SIGMA_BIAS_WARNED: f64 = 2.0;

/// Below this bias (in half-bandwidths for f0 and the split, relative for Q) the sigma rule
/// is silent: a noiseless fit's sigma (from its residuals) never covers the hold's own bias,
/// about 1e-5 half-bandwidths at 16 samples per period, which no use of a sweep resolves.
pub const BIAS_FLOOR: f64 = 1e-4;

/// The fits whose method bias (the fit of the exact held steady state against the coupled
/// plant's mode: the hold and the coupling, below the 1 % rules) exceeds both
/// [`SIGMA_BIAS_WARNED`] of their own sigmas and [`BIAS_FLOOR`], and the same for the mode
/// split: their `value +- sigma` would read as the device's to a confidence the method does
/// not have (the sweep preset printed a split 0.501434 +- 3.8e-5 Hz where the coupled modes
/// are 0.501132 Hz apart, 8 sigma, and Q 35958 +- 3.4 for 35992, 10 sigma, unwarned). A mode
/// already warned of coupling is left out: that warning says its sigmas describe the fit.
fn beyond_sigma(modes: &[ModeCheck; 2], mixed: [bool; 2]) -> Vec<String> {
    let mut out = Vec::new();
    let k = SIGMA_BIAS_WARNED;
    let beyond = |bias: f64, sigma: f64, scale: f64| {
        bias.abs() > k * sigma && bias.abs() > BIAS_FLOOR * scale
    };
    let mut biases = [None; 2];
    for (m, c) in modes.iter().enumerate() {
        let (Some(fit), Some(exp)) = (c.fit, c.expected) else {
            continue;
        };
        let hb = c.coupled_f0_hz / (2.0 * c.coupled_q);
        let (bf, bq) = (exp.f0_hz - c.coupled_f0_hz, exp.q - c.coupled_q);
        biases[m] = Some((bf, fit.f0_sigma_hz, hb));
        if mixed[m] || !(beyond(bf, fit.f0_sigma_hz, hb) || beyond(bq, fit.q_sigma, c.coupled_q)) {
            continue;
        }
        out.push(format!(
            "mode {}: its f0 sigma ({:.1e} Hz) and Q sigma ({:.2e}) do not cover the method's bias: even a perfect emulation fits f0 {:+.3e} Hz ({:+.1} sigma, {:+.1e} half-bandwidths) and Q {:+.3e} ({:+.1} sigma, {:+.1e} relative) from the coupled plant's mode ({} Hz, Q {:.1}), through the DAC's hold and the quadrature coupling; read f0_minus_coupled_hz beside the sigma",
            m + 1,
            fit.f0_sigma_hz,
            fit.q_sigma,
            bf,
            bf / fit.f0_sigma_hz,
            bf / hb,
            bq,
            bq / fit.q_sigma,
            bq / c.coupled_q,
            c.coupled_f0_hz,
            c.coupled_q
        ));
    }
    if let ([Some((b1, s1, h1)), Some((b2, s2, h2))], [false, false]) = (biases, mixed) {
        let (bias, sigma) = (b2 - b1, s1.hypot(s2));
        if beyond(bias, sigma, h1.min(h2)) {
            out.push(format!(
                "the mode split's sigma ({sigma:.1e} Hz) does not cover the method's bias: even a perfect emulation reads it {bias:+.3e} Hz ({:+.1} sigma) from the coupled modes' split ({} Hz); read coupled_mode_split_hz beside it",
                bias / sigma,
                modes[1].coupled_f0_hz - modes[0].coupled_f0_hz
            ));
        }
    }
    out
}

/// The DAC hold's bias on the 2 x 2 fit, when it passes [`HOLD_BIAS_WARNED`]: the fit of the
/// exact held steady state (what a perfect emulation reads) against the configured plant, per
/// mode in half-bandwidths (f0) and relative (Q), and the coupling as the split it makes
/// (`dk / (2 w0)`) in mode 1's half-bandwidths. The one-mode fits state theirs; the matrix fit
/// had read mode 1's f0 0.083 half-bandwidths off beside a Q-of-8 mode 2, with masses within
/// 0.1 % and no warning.
fn matrix_hold_bias(cfg: &Config, pl: &Resonator<f64>, freqs: &[f64]) -> Option<String> {
    let held: Vec<[[Complex64; 2]; 2]> = freqs
        .iter()
        .map(|&f| [held_response(pl, f, 0), held_response(pl, f, 1)])
        .collect();
    let fit = fit_matrix(freqs, &held)?;
    let configured = cfg.mode_resonances_hz();
    let df = [0, 1].map(|m| (fit.f0_hz[m] - configured[m].0) / configured[m].1);
    let dq = [0, 1].map(|m| fit.q[m] / (configured[m].0 / (2.0 * configured[m].1)) - 1.0);
    let (f0, b) = configured[0];
    let w0 = core::f64::consts::TAU * f0;
    let dk = (fit.coupling_rad2_s2 - cfg.device.quadrature_coupling_rad2_s2)
        / (2.0 * w0 * core::f64::consts::TAU * b);
    let worst = df
        .iter()
        .chain(&dq)
        .chain(std::iter::once(&dk))
        .fold(0.0f64, |a, x| a.max(x.abs()));
    (worst > HOLD_BIAS_WARNED).then(|| {
        format!(
            "matrix_fit: the DAC's zero-order hold biases it: a perfect emulation reads mode 1's f0 {:+.3e} half-bandwidths and Q {:+.3e} (relative), mode 2's f0 {:+.3e} and Q {:+.3e}, and a coupling whose split is {:+.3e} of mode 1's half-bandwidths off the configured plant's; raise fs_hz to shrink it (as (f0/fs)^2)",
            df[0], dq[0], df[1], dq[1], dk
        )
    })
}

/// Above this shift (in half-bandwidths for f0, relative for Q) between the fits of the held
/// and the continuous-drive responses, the hold's bias is stated.
pub const HOLD_BIAS_WARNED: f64 = 1e-2;

/// Above this departure (in half-bandwidths for f0, relative for Q) of the one-mode fit of
/// the continuous-drive response from the coupled plant's mode, the coupling's bias is
/// stated.
pub const COUPLING_BIAS_WARNED: f64 = 1e-2;

/// Mode `m`'s velocity per force on mode `m` under a continuous drive at each of `f_hz` (the
/// plant at rest, no hold), for the hold's bias: `held_response` without the hold.
fn continuous(p: &ResonatorParams, f_hz: &[f64], m: usize) -> Vec<Complex64> {
    let mut force = [Complex64::new(0.0, 0.0); 2];
    force[m] = Complex64::new(1.0, 0.0);
    f_hz.iter()
        .map(|&f| continuous_steady_state(p, 0.0, f, force)[2 + m])
        .collect()
}

/// Why a fit is not the resonance the data show, if it is not: its gain far from the 1 the
/// board's division by the chain leaves (a noisy fit ran away to Q = 7e20 with gain -0.17
/// and an f0 sigma of 0.4 Hz, 39 sigma off).
fn unsupported(fit: &ResonanceFit) -> Option<String> {
    let gain = Complex64::new(fit.gain_re, fit.gain_im).norm();
    (!(0.5..=2.0).contains(&gain)).then(|| {
        format!(
            "its gain is {gain:.3} where dividing out the chain leaves about 1: the model does not describe the data (noise or a response outside the mode model)"
        )
    })
}

/// The caveat of a fit narrower than the frequency step at its f0: no swept point resolves
/// it, so its f0 and Q rest on the skirts (exact without noise, fragile with it).
fn unresolved(fit: &ResonanceFit, freqs: &[f64]) -> Option<String> {
    let (f0, bw) = (fit.f0_hz, fit.f0_hz / (2.0 * fit.q));
    let step = freqs
        .windows(2)
        .filter(|w| w[0] <= f0 && f0 <= w[1])
        .map(|w| w[1] - w[0])
        .fold(0.0, f64::max);
    (bw < step).then(|| {
        format!(
            "its half-bandwidth ({bw:.3e} Hz, Q {:.3e}) is shorter than the frequency step at its f0 ({step:.3e} Hz at {f0} Hz): no swept point resolves it, so its f0 and Q rest on the skirts; raise sweep.points or narrow the span",
            fit.q
        )
    })
}

/// Runs `gyroemu sweep` on `cfg` (validated with `validate_sweep`): the measurement as one
/// reported task, then the fits.
pub fn run_frequency_response(
    cfg: &Config,
    reporter: &dyn Reporter,
) -> Result<FrequencyResponse, SweepError> {
    let task = reporter.task("stepped-sine sweep");
    let measured = run_stepped_sine(cfg, &|d, t| task.update(d, t))?;
    task.finish(Some(measured.point_samples));
    Ok(frequency_response_from(cfg, measured))
}
