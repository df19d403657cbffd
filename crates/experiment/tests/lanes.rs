//! The board in f64x4 lanes gives each lane the result the scalar board gives for that
//! operating point alone (bit for bit: the arithmetic is lane-wise, and `Sample::mul_add` is
//! fused or not alike for f64 and f64x4).

use gyroemu_core::f64x4;
use gyroemu_experiment::board::Board;
use gyroemu_experiment::presets::preset;
use gyroemu_experiment::sweep::plan_point;

fn check(name: &str, average_s: f64) {
    let mut cfg = preset(name).unwrap();
    cfg.experiment.average_s = average_s;
    cfg.experiment.settle_s = Some(0.05);
    let rates = [25.0, 100.0, 175.0];
    let points: Vec<_> = rates.iter().map(|&r| plan_point(&cfg, r)).collect();
    let n_settle = (0.05 * cfg.fs_out_hz()).ceil() as u64;
    let rad: Vec<f64> = points.iter().map(|p| p.rate_rad_s).collect();
    let lanes = Board::<f64x4>::new(&cfg, &rad)
        .unwrap()
        .run(n_settle, &points, None, &|_| {});
    for (i, p) in points.iter().enumerate() {
        let scalar =
            Board::<f64>::new(&cfg, &[p.rate_rad_s])
                .unwrap()
                .run(n_settle, &[*p], None, &|_| {});
        assert_eq!(lanes[i], scalar[0], "{name}: lane {i}");
    }
}

#[test]
fn coriolis_lanes_equal_scalar() {
    check("m2tfg-coriolis", 0.2);
}

#[test]
fn rotating_lanes_equal_scalar() {
    check("m2tfg-rotating", 1.1);
}

#[test]
fn rate_table_lanes_equal_scalar() {
    check("m2tfg-ratetable", 0.5);
}
