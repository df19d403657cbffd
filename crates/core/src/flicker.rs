//! Seeded flicker (1/f) noise at the sample level: the bias-instability floor white noise
//! cannot make (gyroemu issue 14).
//!
//! One unit white Gaussian sequence `w` drives a linear filter whose exact power spectrum is
//! `S1 / f` between two corners, within a stated ripple ([`RIPPLE_DB`]):
//!
//! * Design ([`FlickerDesign`]): a cascade of first-order pole-zero sections, two per decade,
//!   poles `p_k = f_lo r^k` and zeros `z_k = p_k sqrt(r)` interlaced on a geometric lattice
//!   from `f_lo` (the lowest pole: the spectrum is flat below it) to `f_hi` (the last zero:
//!   flat above it). Each pole or zero pulls the slope of `|H|^2` by -2 or +2 over its own
//!   half-period of the lattice, so on average the slope is -1: the classic rational
//!   approximation of `1/f` (Keshner 1982). The sections are discretised by matched z
//!   (`a_k = exp(-2 pi p_k / fs)`, `c_k = exp(-2 pi z_k / fs)`), and the gain `g` sets the
//!   mean level of `f S(f)` over one lattice period at the band centre to `S1`.
//! * Exact spectrum ([`FlickerDesign::psd`]): for unit-variance white `w`, the one-sided
//!   density of the output is `S(f) = (2/fs) g^2 prod_k |1 - c_k e^{-jw}|^2 /
//!   |1 - a_k e^{-jw}|^2`, `w = 2 pi f / fs`: exact for the sampled filter, no continuous-time
//!   approximation.
//! * Realisation ([`Flicker`]): the same transfer function in modal (partial-fraction) form,
//!   `H(z) = D + sum_k rho_k / (1 - a_k z^-1)`: one one-pole state per pole, all residues
//!   positive, so the output is a positive sum of one-pole-filtered copies of `w` (no
//!   cancellation). Per sample it costs one Gaussian and two multiply-adds per pole, with no
//!   allocation.
//! * Stationary start ([`Flicker::stationary`]): the modal states are drawn from their
//!   stationary law, covariance `C_ij = 1 / (1 - a_i a_j)`, so the sequence is stationary
//!   from its first sample (a filter started at rest would need about `1 / (2 pi f_lo)`
//!   seconds, a sizeable part of the record, to forget its start).
//! * Allan deviation: for `S(f) = h / f` (one-sided, of the quantity whose deviation is
//!   taken) `sigma^2(tau) = 2 ln 2 h` at every tau ([`flicker_adev`]), over the taus whose
//!   `1 / tau` lies well inside `[f_lo, f_hi]`. A bias instability `B` is the one-sided
//!   `h = B^2 / pi` (IEEE Std 952's two-sided `B^2 / (2 pi f)`), whose floor is
//!   `sqrt(2 ln 2 / pi) B = 0.664 B` ([`ADEV_PER_BIAS_INSTABILITY`]).

mod design;
mod generator;
mod params;
mod stationary;

pub use design::{FlickerDesign, POLES_PER_DECADE, RIPPLE_DB};
pub use generator::Flicker;
pub use params::{
    flicker_adev, min_f_lo_hz, psd_at_1hz_from_bias_instability, psd_at_1hz_from_corner,
    FlickerParams, ADEV_PER_BIAS_INSTABILITY,
};
