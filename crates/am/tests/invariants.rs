//! How the lane-parallel modulator takes its gains, and ties in every lane of the quantiser
//! (block processing, reset and lanes bit for bit are checked by the shared harness in
//! tests/contract.rs).

use gyroemu_am::{AmModulator, DrivePattern, Quantizer};
use gyroemu_core::{f64x4, Sample};

#[test]
fn from_lanes_repeats_the_last_modulator_and_none_gives_zero_gains() {
    let one = [AmModulator::<f64>::new(DrivePattern::Rotating, 2.0, 3.0).unwrap()];
    let m = AmModulator::<f64x4>::from_lanes(&one);
    assert_eq!(m.pattern(), DrivePattern::Rotating);
    let (g1, g2) = m.gains();
    assert_eq!((g1.to_array(), g2.to_array()), ([2.0; 4], [3.0; 4]));
    let (g1, _) = AmModulator::<f64x4>::from_lanes(&[]).gains();
    assert_eq!(g1.to_array(), [0.0; 4]);
}

#[test]
fn quantizer_ties_round_away_from_zero_in_every_lane() {
    let q4 = Quantizer::<f64x4>::new(12, 1.3).unwrap();
    let q1 = Quantizer::<f64>::new(12, 1.3).unwrap();
    let step = q1.step();
    let ties = f64x4::from_fn(|i| [0.5, -0.5, 2.5, -2.5][i] * step);
    let y = q4.quantize(ties);
    for i in 0..4 {
        assert_eq!(y.lane(i), q1.quantize(ties.lane(i)));
        // Away from zero: |code| is the tie's magnitude rounded up.
        let code = ties.lane(i) / step;
        assert_eq!(y.lane(i) / step, code.signum() * (code.abs() + 0.5));
    }
}
