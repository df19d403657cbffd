//! Validation refuses a chain whose signals would overflow; a library user who runs it anyway
//! meets the second line of defence: a value that overflows inside the chain stops the run and
//! names the stage and the sample.
//! A matched mode driven at resonance from rest has the velocity envelope
//! v(t) = F Q / w0 (1 - exp(-t / tau)), tau = 2 Q / w0; the TIA output envelope is
//! v * t_a * R * |H(f0)|. The stage-1 mixer doubles it (2 y cos w0t), so the first value to
//! overflow is the mixer's once 2 y passes f64::MAX, or the TIA's once y does: the reported
//! time must lie between those two instants.

use gyroemu::config::presets::preset;
use gyroemu::experiment::{run_sweep, SweepError};
use std::f64::consts::PI;

#[test]
fn overflow_names_the_stage_and_the_sample() {
    let mut c = preset("m2tfg-coriolis").unwrap();
    let (f, t_a) = (1e295, 1e10);
    c.device.transduction_a_s_per_m = t_a;
    c.drive.f1 = f;
    c.drive.f2 = Some(f);
    c.experiment.average_s = 0.1;
    let refused = c.validate().expect_err("the drive is far beyond 1e100");
    assert_eq!(refused.key.as_deref(), Some("drive.f1"), "{refused}");
    let d = &c.device;
    let w0 = 2.0 * PI * d.f0_hz;
    let tau = 2.0 * d.q / w0;
    let pole = c.board.tia_pole_hz.unwrap();
    let gain = c.board.tia_gain_ohm / (1.0 + (d.f0_hz / pole).powi(2)).sqrt();
    // Solve y_env(t) = level for t (in units that cannot overflow: divide by f64::MAX first).
    let y_full = (f / f64::MAX) * d.q / w0 * t_a * gain;
    let t_at = |level: f64| -tau * (1.0 - level / y_full).ln();
    let (t_lo, t_hi) = (t_at(0.5), t_at(1.0));
    match run_sweep(&c, &|_, _| {}, None) {
        Err(SweepError::NonFinite(e)) => {
            assert!(["mixer (stage 1)", "tia/adc"].contains(&e.stage), "{e}");
            // 5 % margin for the TIA pole's settling and the hold's sinc.
            assert!(
                e.time_s > 0.95 * t_lo && e.time_s < 1.05 * t_hi,
                "{e}: expected between {t_lo} and {t_hi} s"
            );
            assert_eq!(e.sample as f64 / c.fs_hz(), e.time_s);
            assert!(e
                .to_string()
                .contains(&format!("input sample {}", e.sample)));
        }
        other => panic!("expected a non-finite error, got {other:?}"),
    }
}
