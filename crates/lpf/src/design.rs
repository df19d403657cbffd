//! Filter designs and their section coefficients.

use crate::section::Coefs;
use crate::STAGE;
use biquad::{Coefficients, Hertz, Type};
use gyroemu_core::error::{below_nyquist, positive};
use gyroemu_core::{ParamError, ParamResult};

/// Largest supported order (the cascade holds at most this many sections).
pub const MAX_ORDER: usize = 8;

/// What low-pass to build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LowPassDesign {
    /// Bilinear-transform Butterworth of `order` 1..=8 with the cutoff prewarped, so that
    /// `|H(f)| = 1 / sqrt(1 + (tan(pi f/fs) / tan(pi fc/fs))^(2N))` exactly (-3 dB at `fc`).
    Butterworth {
        /// Filter order N (1..=8).
        order: usize,
        /// -3 dB frequency in Hz, `0 < fc < fs/2`.
        cutoff_hz: f64,
    },
    /// A lock-in amplifier's output filter: `order` identical RC one-poles (6N dB/octave),
    /// each `y += (1 - a)(x - y)` with `a = exp(-Ts/tau)` (exact for a held input).
    LockIn {
        /// Number of cascaded RC stages N (1..=8).
        order: usize,
        /// Time constant of each RC stage in s.
        tau_s: f64,
    },
}

/// Section coefficients of a design (validated): whether the sections are lock-in one-poles,
/// how many sections are used, and their coefficients.
pub(crate) fn sections(
    design: LowPassDesign,
    fs_hz: f64,
) -> ParamResult<(bool, usize, [Coefs; MAX_ORDER])> {
    let fs = positive(STAGE, "fs_hz", fs_hz)?;
    let mut out = [Coefs::default(); MAX_ORDER];
    let check_order = |order: usize| {
        if (1..=MAX_ORDER).contains(&order) {
            Ok(order)
        } else {
            Err(ParamError::new(STAGE, "order", order, "must be in 1..=8"))
        }
    };
    match design {
        LowPassDesign::Butterworth { order, cutoff_hz } => {
            let n = check_order(order)?;
            let fc = below_nyquist(STAGE, "cutoff_hz", cutoff_hz, fs)?;
            let map = |e: biquad::Errors| {
                ParamError::new(
                    STAGE,
                    "cutoff_hz",
                    fc,
                    format!("biquad design failed: {e:?}"),
                )
            };
            let fs_h = Hertz::<f64>::from_hz(fs).map_err(map)?;
            let fc_h = Hertz::<f64>::from_hz(fc).map_err(map)?;
            let mut k = 0;
            if n % 2 == 1 {
                // biquad's SinglePoleLowPass is t(1 + z^-1) / ((1 + t) + (t - 1) z^-1) with
                // t = tan(pi fc/fs): exactly the prewarped bilinear first-order section.
                let c = Coefficients::from_params(Type::SinglePoleLowPass, fs_h, fc_h, 1.0)
                    .map_err(map)?;
                out[k] = Coefs::biquad(c.b0, c.b1, 0.0, c.a1, 0.0);
                k += 1;
            }
            // Pole pairs at angle psi_m = pi (N - 2m + 1) / (2N) from the negative real axis,
            // Q_m = 1 / (2 cos psi_m); lowest Q first.
            for m in (1..=n / 2).rev() {
                let psi = core::f64::consts::PI * (n - 2 * m + 1) as f64 / (2 * n) as f64;
                let q = 1.0 / (2.0 * psi.cos());
                let c = Coefficients::from_params(Type::LowPass, fs_h, fc_h, q).map_err(map)?;
                out[k] = Coefs::biquad(c.b0, c.b1, c.b2, c.a1, c.a2);
                k += 1;
            }
            Ok((false, k, out))
        }
        LowPassDesign::LockIn { order, tau_s } => {
            let n = check_order(order)?;
            let tau = positive(STAGE, "tau_s", tau_s)?;
            let a = (-1.0 / (fs * tau)).exp();
            let k = 1.0 - a;
            if k <= 0.0 {
                return Err(ParamError::new(
                    STAGE,
                    "tau_s",
                    tau,
                    "too long for fs_hz: 1 - exp(-Ts/tau) rounds to 0",
                ));
            }
            // The realised recursion y += k (x - y) has its pole at 1 - k exactly in real
            // arithmetic; record k (not `a`) so the response is the one built.
            out[..n].fill(Coefs::one_pole(k));
            Ok((true, n, out))
        }
    }
}
