//! Carrier PLL (gyroemu issue 14 point 1): locks the drive NCO onto the resonance of one mode
//! from its demodulated output, so the drive follows a drifting `f0` through a loop with a
//! stated bandwidth and damping instead of sitting on `f0` for free.
//!
//! # The loop
//!
//! The NCO drives the mode at phase `theta(t)`, `theta' = w_c` (the carrier), and stage 1
//! demodulates the response with the same carrier: `z = LPF{2 y e^{-j theta}}` (mixer and
//! low-pass crates). For the mode `q'' + (w0/Q) q' + w0^2 q = F cos theta`, write the velocity
//! as `v = Re{a(t) e^{j theta(t)}}`; near resonance the slowly varying envelope obeys
//!
//! ```text
//! a' = -(1/tau + j dw) a + F/2,     tau = 2 Q / w0 = Q / (pi f0),   dw = w_c - w0
//! ```
//!
//! (the image at `-2 theta` dropped: relative size `O(1/Q)`). At steady state
//! `a = (F tau / 2) / (1 + j tau dw)`: the velocity lags the force by `atan(tau dw)`
//! (THEORY.md section 3 has the same first-order envelope for the Coriolis phase). Stage 1
//! returns `a` times the chain's gain at the carrier, so `arg z = arg a + phi_chain`, where
//! `phi_chain` (the DAC hold's `-pi f_c Ts`, the TIA's inversion and pole, ...) is what the
//! caller passes as `phase_offset_rad`. The detector reads
//! `e = arg(z e^{-j phase_offset}) = arg a = phi`, and with `a = |a| e^{j phi}`:
//!
//! ```text
//! phi' = -dw - (F / (2 |a|)) sin phi          -> near lock:   phi' = -dw - phi / tau
//! e(s) = -tau / (1 + s tau) dw(s)             (a lag for a carrier above resonance)
//! ```
//!
//! The loop filter sets the carrier: `w_c = w_nom + Kp e + Ki int e`. With
//! `dw = w_c - w0` the closed loop is second order,
//!
//! ```text
//! s^2 + ((1 + tau Kp) / tau) s + Ki = 0   ->   Ki = wn^2,   Kp = 2 zeta wn - 1/tau
//! ```
//!
//! for a natural frequency `wn` and damping `zeta`. `Kp >= 0` needs `2 zeta wn tau >= 1`:
//! slower or less damped loops than the envelope itself cannot be had with a PI on the
//! frequency, and are refused. The carrier's response to a step `D` of the resonance is
//! `H(s) = (Kp s + wn^2) / (s^2 + 2 zeta wn s + wn^2)`, for `zeta < 1`
//!
//! ```text
//! w_c(t) - w_c(0) = D [1 - e^{-zeta wn t} (cos wd t + ((1/tau - zeta wn) / wd) sin wd t)],
//! wd = wn sqrt(1 - zeta^2)
//! ```
//!
//! # The sampled loop, designed exactly
//!
//! The PLL runs once per decimated output (period `T`), and its frequency is held for the
//! next update. Over one update the phase equation integrates exactly:
//!
//! ```text
//! e[k+1] = alpha e[k] - g dw[k],    alpha = e^{-T/tau},   g = tau (1 - alpha)
//! u[k]   = Kp e[k] + I[k],          I[k]  = I[k-1] + Ki T e[k],     w_c[k] = w_nom + u[k]
//! ```
//!
//! so the sampled loop is exactly second order too, with characteristic polynomial
//! `z^2 + (g (Kp + Ki T) - 1 - alpha) z + (alpha - g Kp)`. [`LoopDesign`] chooses `Kp` and
//! `Ki T` to put its roots at `p = e^{s T}` of the continuous poles
//! `s = -zeta wn +- j wn sqrt(1 - zeta^2)`: `Kp = (alpha - p1 p2) / g`,
//! `Ki T = (1 - p1)(1 - p2) / g`. As `T -> 0` these tend to the continuous `Kp` and `wn^2 T`,
//! and `Kp >= 0` still exactly when `2 zeta wn tau >= 1`. The loop filter's response (the
//! stage's [`gyroemu_core::Response`], phase error to Hz) is
//! `(Kp + Ki T / (1 - e^{-j w T})) / 2 pi`.
//!
//! What the design leaves out, and the rules that keep it small: the demodulation low-pass
//! (its DC group delay `d` lags the loop by `wn d` at the natural frequency: refused above
//! [`MAX_LOWPASS_LAG_RAD`]); the one input sample between the sample of `z` and the new
//! frequency (`natural_hz` at most [`MAX_NATURAL_PER_UPDATE`] x the update rate); the image
//! term (`O(1/Q)`); and, far from lock, the detector's and the envelope's nonlinearity.
//!
//! # Acquisition
//!
//! Driven from rest at a fixed detuning, `a(t) / a_ss = 1 - e^{-(1/tau + j dw) t}` keeps a
//! positive real part and `arg a_ss = -atan(tau dw)` is inside `+-pi/2`, so `arg a` stays
//! inside `+-pi` and the detector does not wrap; quasi-statically `e = -atan(tau dw)` has
//! the sign of `-dw` at any detuning, so the loop pulls in from any detuning inside the
//! frequency limits, more slowly far out (the detector's gain falls as
//! `1 / (1 + (tau dw)^2)`). tests/closed_loop.rs measures lock from up to 20 half-bandwidths
//! `f0 / (2 Q)` on a chain of the real stages.
//!
//! # Lock
//!
//! [`Pll::is_locked`]: `|e|` below `lock_threshold_rad` on each of the last `lock_updates`
//! ticks, with a signal and off the frequency limits. An input at or below `min_amplitude`
//! (or not finite) carries no phase: the PLL holds its frequency and drops lock.
//!
//! # Drive amplitude (AGC)
//!
//! [`Agc`] closes a second loop around the same envelope: a PI on `ln(setpoint / |z|)`
//! setting the drive gain. In logs the amplitude follows the gain through the same lag
//! `1 / (1 + s tau)` (gain 1 instead of the phase's `tau`), so its gains are the PLL's times
//! `tau` (`Kp = 2 zeta wn tau - 1`, `Ki = wn^2 tau`) and the amplitude's response to a step of
//! the setpoint is the carrier's to a step of the resonance.
//!
//! # Determinism
//!
//! The gains and the offset rotation are computed once, when a stage is built (std `exp`,
//! `expm1`, `sin`, `cos`; `detmath` for the rotation). Per update the PLL calls std `atan2`
//! once, the AGC std `ln` and `exp` once each: the only libm calls on the signal path besides
//! the rate-table unwrap (docs/architecture.md section 6).
#![warn(missing_docs)]

mod agc;
mod agc_params;
pub mod design;
mod params;
mod pi;
mod pll;

pub use agc::Agc;
pub use agc_params::{AgcParams, AGC_STAGE};
pub use design::LoopDesign;
pub use params::{PllParams, MAX_LOWPASS_LAG_RAD, MAX_NATURAL_PER_UPDATE};
pub use pll::Pll;

/// The stage name in this crate's parameter errors.
pub const STAGE: &str = "pll";
