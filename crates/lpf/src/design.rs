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
/// how many sections are used, and their coefficients. A design that f64 cannot realise
/// (a cutoff so close to 0 or to fs/2 that a pole rounds onto the unit circle, or the
/// numerator to zero) is refused, naming the parameter that caused it.
pub(crate) fn sections(
    design: LowPassDesign,
    fs_hz: f64,
) -> ParamResult<(bool, usize, [Coefs; MAX_ORDER])> {
    let (one_pole, n, out) = raw_sections(design, fs_hz)?;
    let (param, value) = match design {
        LowPassDesign::Butterworth { cutoff_hz, .. } => ("cutoff_hz", cutoff_hz),
        LowPassDesign::LockIn { tau_s, .. } => ("tau_s", tau_s),
    };
    // A biquad's stability sums are rounded (to a few eps); require them to exceed that,
    // so a pole that only rounding keeps inside is refused too. The lock-in one-pole has
    // its pole at 1 - k exactly, inside for any k in (0, 1].
    let margin = if one_pole { 0.0 } else { 8.0 * f64::EPSILON };
    for c in &out[..n] {
        realisable(c, margin).map_err(|why| {
            ParamError::new(
                STAGE,
                param,
                value,
                format!(
                    "{why} at fs_hz = {fs_hz:?} (too close to 0 or to fs/2 for double precision)"
                ),
            )
        })?;
    }
    Ok((one_pole, n, out))
}

/// Largest pole radius of `1 + a1 z^-1 + a2 z^-2` (both roots of `z^2 + a1 z + a2`).
pub(crate) fn pole_radius(a1: f64, a2: f64) -> f64 {
    let disc = a1 * a1 - 4.0 * a2;
    if disc < 0.0 {
        // Complex pair: |z|^2 = a2.
        a2.sqrt()
    } else {
        let r = disc.sqrt();
        (0.5 * (-a1 + r)).abs().max((0.5 * (-a1 - r)).abs())
    }
}

/// Checks one built section: finite coefficients, poles strictly inside the unit circle
/// (the stability triangle `|a2| < 1`, `1 + a1 + a2 > 0`, `1 - a1 + a2 > 0`, evaluated on
/// the coefficients as stored, each by more than `margin`) and a unit DC gain within 1 %
/// (a numerator rounded to zero or a pole at `z = 1` fails this).
fn realisable(c: &Coefs, margin: f64) -> Result<(), String> {
    let all = [c.b0, c.b1, c.b2, c.a1, c.a2];
    if !all.iter().all(|v| v.is_finite()) {
        return Err(format!("the section coefficients are not finite ({all:?})"));
    }
    let a_at_1 = c.a_sum();
    let a_at_minus_1 = 1.0 - c.a1 + c.a2;
    if !(1.0 - c.a2.abs() > margin && a_at_1 > margin && a_at_minus_1 > margin) {
        return Err(format!(
            "a pole is not safely inside the unit circle in double precision (|pole| = {}, stability sums 1 +- a1 + a2 = {a_at_1:e}, {a_at_minus_1:e} must exceed the rounding {margin:e})",
            pole_radius(c.a1, c.a2)
        ));
    }
    let dc = c.dc_gain();
    if !(dc.is_finite() && (dc - 1.0).abs() <= 0.01) {
        return Err(format!("a section's DC gain rounds to {dc} instead of 1"));
    }
    Ok(())
}

fn raw_sections(
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
                // Its b1 is b0 bit for bit; the cascade runs the numerator as 1 + z^-1 and
                // applies b0 once, so record exactly that.
                out[k] = Coefs::biquad(c.b0, c.b0, 0.0, c.a1, 0.0);
                k += 1;
            }
            // Pole pairs at angle psi_m = pi (N - 2m + 1) / (2N) from the negative real axis,
            // Q_m = 1 / (2 cos psi_m); lowest Q first.
            for m in (1..=n / 2).rev() {
                let psi = core::f64::consts::PI * (n - 2 * m + 1) as f64 / (2 * n) as f64;
                let q = 1.0 / (2.0 * psi.cos());
                let c = Coefficients::from_params(Type::LowPass, fs_h, fc_h, q).map_err(map)?;
                // Its b1 is 2 b0 and b2 is b0 bit for bit ((1 - cos w)/2 and 1 - cos w scaled
                // by the same 1/a0); the cascade runs the numerator as (1 + z^-1)^2 and
                // applies b0 once, so record exactly that.
                out[k] = Coefs::biquad(c.b0, 2.0 * c.b0, c.b0, c.a1, c.a2);
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

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    /// Both poles of `z^2 + a1 z + a2` by the complex quadratic formula (independent of
    /// `pole_radius`, which branches on the discriminant's sign).
    fn poles(a1: f64, a2: f64) -> [Complex64; 2] {
        let d = Complex64::new(a1 * a1 - 4.0 * a2, 0.0).sqrt();
        [(-a1 + d) * 0.5, (-a1 - d) * 0.5]
    }

    #[test]
    fn realisable_refuses_each_rule_it_states_on_hand_made_sections() {
        let margin = 1e-15;
        // A stable low-pass section with unit DC gain passes: poles 0.5 +- 0.3j.
        let (a1, a2) = (-1.0, 0.34);
        let g = 1.0 + a1 + a2;
        assert!(realisable(&Coefs::biquad(g, 0.0, 0.0, a1, a2), margin).is_ok());
        // Complex poles outside the unit circle that the two sums alone would let through
        // (1 +- a1 + a2 > 0): only |a2| < 1 refuses them (|z| = sqrt(1.5)).
        let (a1, a2) = (0.0, 1.5);
        assert!(poles(a1, a2).iter().all(|p| p.norm() > 1.0));
        let c = Coefs::biquad(1.0 + a1 + a2, 0.0, 0.0, a1, a2);
        assert!(realisable(&c, margin).unwrap_err().contains("unit circle"));
        // A pole at z = 1 (1 + a1 + a2 = 0) and one at z = -1 (1 - a1 + a2 = 0).
        for (a1, a2) in [(-1.5, 0.5), (1.5, 0.5)] {
            let c = Coefs::biquad(1.0, 0.0, 0.0, a1, a2);
            assert!(realisable(&c, margin).unwrap_err().contains("unit circle"));
        }
        // Stable but with a DC gain of 2, or 1.02: refused; 1.005 passes (within 1 %).
        let (a1, a2) = (-1.0, 0.34);
        let g = 1.0 + a1 + a2;
        for (k, ok) in [(2.0, false), (1.02, false), (1.005, true)] {
            let r = realisable(&Coefs::biquad(k * g, 0.0, 0.0, a1, a2), margin);
            assert_eq!(r.is_ok(), ok, "DC gain {k}: {r:?}");
        }
        // Not finite.
        let c = Coefs::biquad(f64::NAN, 0.0, 0.0, a1, a2);
        assert!(realisable(&c, margin).unwrap_err().contains("not finite"));
    }

    #[test]
    fn every_accepted_section_has_its_poles_inside_the_unit_circle() {
        let fs = 1.0e6;
        let mut checked = 0;
        for order in 1..=MAX_ORDER {
            let mut designs = vec![];
            for e in -18..=0 {
                let fc = 0.5 * fs * 10f64.powi(e);
                designs.push(LowPassDesign::Butterworth {
                    order,
                    cutoff_hz: fc * 0.999,
                });
                // Towards Nyquist: fs/2 (1 - 10^e).
                designs.push(LowPassDesign::Butterworth {
                    order,
                    cutoff_hz: 0.5 * fs * (1.0 - 10f64.powi(e.min(-1))),
                });
                designs.push(LowPassDesign::LockIn {
                    order,
                    tau_s: 10f64.powi(e + 6),
                });
            }
            for d in designs {
                if let Ok((_, n, c)) = sections(d, fs) {
                    for s in &c[..n] {
                        for p in poles(s.a1, s.a2) {
                            assert!(p.norm() < 1.0, "{d:?}: pole {p}");
                        }
                        assert!(s.b0.is_finite() && s.b1.is_finite() && s.b2.is_finite());
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 300, "{checked}");
    }

    #[test]
    fn cutoffs_f64_cannot_realise_are_refused_naming_the_cutoff() {
        let fs = 1.0e6;
        // cos(2 pi fc/fs) rounds to 1 (fc/fs < 1e-9): a pole at z = 1, numerator 0.
        // tan(pi fc/fs) below eps/2: the first-order pole rounds to 1.
        // fc within 1e-9 fs of Nyquist: 1 + cos rounds to (nearly) 0, a pole at z = -1.
        for (order, fc) in [
            (2, 1e-4),
            (4, 1e-6),
            (1, 1e-12),
            (3, 1e-12),
            (2, 0.5 * fs * (1.0 - 1e-12)),
            (8, 0.5 * fs * (1.0 - 1e-11)),
            (5, 0.5 * fs * (1.0 - 1e-9)),
        ] {
            let d = LowPassDesign::Butterworth {
                order,
                cutoff_hz: fc,
            };
            let e = sections(d, fs).expect_err(&format!("order {order} fc {fc}"));
            assert_eq!((e.stage, e.param), ("lpf", "cutoff_hz"), "{e}");
            assert_eq!(e.value, fc.to_string());
            assert!(e.rule.contains("fs_hz = 1000000"), "{e}");
        }
        // Healthy narrow and wide designs stay accepted.
        for fc in [1.0, 10.0, 0.49 * fs, 0.5 * fs * (1.0 - 1e-6)] {
            for order in 1..=MAX_ORDER {
                let d = LowPassDesign::Butterworth {
                    order,
                    cutoff_hz: fc,
                };
                assert!(sections(d, fs).is_ok(), "order {order} fc {fc}");
            }
        }
    }

    #[test]
    fn pole_radius_matches_the_quadratic_formula() {
        for (a1, a2) in [
            (-1.9, 0.95),
            (-1.5, 0.5),
            (0.3, -0.2),
            (1.99, 0.99),
            (-2.0, 1.0),
        ] {
            let truth = poles(a1, a2).iter().map(|p| p.norm()).fold(0.0, f64::max);
            assert!((pole_radius(a1, a2) - truth).abs() < 1e-12, "{a1} {a2}");
        }
    }
}
