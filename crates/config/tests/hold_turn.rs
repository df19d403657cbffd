//! The hold rule of a Coriolis run compares phases within a whole turn: a Coriolis phase is
//! not known only modulo 180 degrees as psi is. At 1e9 deg/s on a split, weakly driven
//! device the held board reads mode 1 at -89.97 deg where the continuous theory gives
//! +90.00: a half-turn fold called that 32 mdeg, warned, and let the run print an error of
//! -179 968 mdeg against its theory column.

use gyroemu_config::parse_config;

#[test]
fn a_hold_error_of_a_half_turn_is_refused_not_folded_away() {
    let c = parse_config(
        "[device]\nf0_hz = 15000.0\nq = 2000.0\nangular_gain = 1.0\nmode2_f0_offset_hz = 2.0\n\
         [drive]\nf1 = 1.0\nf2 = 0.3\n\
         [board]\nfs_hz = 240000.0\ntia_gain_ohm = 1e6\ntia_pole_hz = 60000.0\n\
         [experiment]\nkind = \"coriolis\"\nrates_dps = [1e7, 1e9]\naverage_s = 0.05\n",
    )
    .unwrap();
    // The exact phases the rule compares: they differ by about a half turn.
    let dev = c.driven_device();
    let omega = 1e9f64.to_radians();
    let (held, exact) = (
        dev.held_coriolis_phase_rad(omega),
        dev.coriolis_phase_rad(omega),
    );
    let d = (held[0] - exact[0]).to_degrees().abs();
    assert!((d - 180.0).abs() < 1.0, "held {held:?}, exact {exact:?}");
    let e = c.validate().unwrap_err().to_string();
    assert!(
        e.contains("board.fs_hz") && e.contains("zero-order hold"),
        "{e}"
    );
}
