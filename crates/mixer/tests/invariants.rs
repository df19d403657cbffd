//! Bad parameters are refused (block processing, reset and f64x4 lanes bit for bit are
//! checked by the shared harness in tests/contract.rs).

use gyroemu_core::f64x4;
use gyroemu_mixer::Stage1Mixer;

#[test]
fn non_finite_reference_phase_is_a_param_error() {
    for bad in [f64::NAN, f64::INFINITY, -f64::INFINITY] {
        let e = Stage1Mixer::<f64x4>::new(bad).unwrap_err();
        assert_eq!(e.param, "ref_phase_rad");
        assert!(e.to_string().contains("finite"));
    }
}
