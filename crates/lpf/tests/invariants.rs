//! LowPass invariants: homogeneity by powers of two (block processing, reset, lanes and the
//! bank's channels are checked by the shared harness in tests/contract.rs).

mod common;

use gyroemu_core::Stage;
use gyroemu_lpf::{LowPass, LowPassDesign};

proptest::proptest! {
    /// Linearity by an exact power of two holds bit for bit in any cascade of linear sections.
    #[test]
    fn homogeneous_by_powers_of_two(order in 1usize..=8, fc in 1.0f64..4.9e4, lockin in proptest::bool::ANY) {
        let design = if lockin {
            LowPassDesign::LockIn { order, tau_s: 1.0 / fc }
        } else {
            LowPassDesign::Butterworth { order, cutoff_hz: fc }
        };
        let mut a = LowPass::<f64>::new(design, 1e5).unwrap();
        let mut b = LowPass::<f64>::new(design, 1e5).unwrap();
        for v in common::noise(300, 2.0, 5) {
            proptest::prop_assert_eq!((a.tick(v) * 8.0).to_bits(), b.tick(v * 8.0).to_bits());
        }
    }
}
