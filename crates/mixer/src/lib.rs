//! Two-stage mixer of the gyroscope readout (THEORY sections 3, 4 and 6).
//!
//! * [`Stage1Mixer`]: complex demodulation by the carrier, `z = 2 y e^{-j(w0 t + phi)}`, to be
//!   low-passed (the low-pass lives in `gyroemu-lpf`). For `y = A cos(w0 t - theta)` the DC of `z`
//!   is `A e^{-j(theta + phi)}`: a lag `theta` shows as a *negative* phase of `z`.
//!   Its I channel is the paper's single real mixer `2 y cos(w0 t + phi)` (DC
//!   `A cos(theta + phi)`), so that reading needs no mixer of its own.
//! * [`Stage2Mixer`]: demodulation of `z` at the modulation rate Omega, giving the C and S terms.
//! * [`TableMixer`]: demodulation of `z` at the harmonics of a rate table's frequency, and
//!   [`phase_fundamental`], the exact phase read-out from them.
//! * [`sideband_estimate`], [`paper_i_channel_psi_rad`], [`phase_lag_rad`]: the read-outs.

mod estimate;
mod iq;
mod stage1;
mod stage2;
mod table;

pub use estimate::{
    paper_i_channel_psi_rad, phase_lag_rad, sideband_estimate, Mode, SidebandEstimate,
};
pub use iq::Iq;
pub use stage1::Stage1Mixer;
pub use stage2::{Stage2Mixer, Stage2Out};
pub use table::{
    phase_fundamental, phase_fundamental_checked, phase_fundamental_fine, table_channel,
    table_reference, NoFundamental, TableMixer, MAX_TABLE_HARMONIC, TABLE_CHANNELS,
    TABLE_HARMONICS,
};

/// Wraps an angle into `(-pi, pi]` (the branch every read-out here uses).
#[inline]
pub fn wrap_pi(x: f64) -> f64 {
    use core::f64::consts::{PI, TAU};
    let mut w = x - TAU * (x / TAU).round();
    // `round` leaves w in [-pi, pi]; move the lower end to the upper one.
    if w <= -PI {
        w += TAU;
    }
    if w > PI {
        w -= TAU;
    }
    w
}

#[cfg(test)]
mod tests {
    use super::wrap_pi;
    use core::f64::consts::{PI, TAU};

    #[test]
    fn wrap_pi_is_half_open_and_preserves_angle() {
        assert_eq!(wrap_pi(PI), PI);
        assert_eq!(wrap_pi(-PI), PI);
        assert_eq!(wrap_pi(3.0 * PI), PI);
        for k in -50..50 {
            let x = 0.37 * k as f64;
            let w = wrap_pi(x);
            assert!(w > -PI && w <= PI);
            let turns = (x - w) / TAU;
            assert!((turns - turns.round()).abs() < 1e-12);
        }
    }

    #[test]
    fn wrap_pi_keeps_the_bits_of_an_angle_already_on_its_branch() {
        // |x| < pi: x / 2 pi rounds to 0, so nothing may be added and taken back (a round
        // trip through x + 2 pi would lose x's low bits).
        for k in 1..2000 {
            let x = PI * (k as f64 / 2000.0).powi(3);
            for x in [x, -x, x * 1e-9, -x * 1e-9] {
                assert_eq!(wrap_pi(x).to_bits(), x.to_bits(), "{x}");
            }
        }
    }

    #[test]
    fn wrap_pi_stays_on_its_branch_next_to_an_odd_multiple_of_pi() {
        // x - 2 pi round(x / 2 pi) can land an ulp or so above pi far from 0: the last branch
        // must take it to the lower end, the same angle.
        let mut upper_end_hit = 0;
        for k in -3000i64..3000 {
            let c = (k as f64 + 0.5) * TAU;
            for d in -40i64..40 {
                let x = f64::from_bits((c.to_bits() as i64 + d) as u64);
                let w = wrap_pi(x);
                assert!(w > -PI && w <= PI, "{x} -> {w}");
                let turns = (x - w) / TAU;
                assert!((turns - turns.round()).abs() < 1e-12, "{x} -> {w}");
                let raw = x - TAU * (x / TAU).round();
                upper_end_hit += usize::from(raw > PI);
            }
        }
        // The case the branch exists for does occur here.
        assert!(upper_end_hit > 0);
    }
}
