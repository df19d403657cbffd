//! The board's plant shapes: the decoupled step gives the full step's results bit for bit.

use super::*;
use crate::presets::preset;
use crate::sweep::plan_point;
use gyroemu_core::f64x4;

/// Runs `cfg` at `rates_dps` through the full and the decoupled plant step.
fn both_shapes<const K: u8>(cfg: &Config, rates_dps: &[f64]) -> [Vec<LaneResult>; 2] {
    let points: Vec<Point> = rates_dps.iter().map(|&r| plan_point(cfg, r)).collect();
    let rad: Vec<f64> = points.iter().map(|p| p.rate_rad_s).collect();
    let board = Board::<f64x4>::new(cfg, &rad).unwrap();
    assert!(board.plant_decoupled(), "the shortcut must apply");
    let extras = RunExtras::default();
    let n_settle = 20;
    let full = board
        .clone()
        .run_kind::<K, false, false>(n_settle, &points, None, &extras, &|_| {})
        .unwrap();
    let dec = board
        .clone()
        .run_kind::<K, false, true>(n_settle, &points, None, &extras, &|_| {})
        .unwrap();
    [full.lanes, dec.lanes]
}

#[test]
fn decoupled_plant_runs_equal_full_plant_runs_bit_for_bit() {
    let mut rot = preset("m2tfg-rotating").unwrap();
    rot.experiment.average_s = 0.2;
    let [full, dec] = both_shapes::<ROTATING>(&rot, &[25.0, 100.0, 175.0]);
    assert_eq!(full, dec);
    assert!(full.iter().all(|l| l.c[0].norm() > 0.0));
    // A Coriolis run whose every lane is at rest is decoupled too.
    let mut cor = preset("m2tfg-coriolis").unwrap();
    cor.experiment.average_s = 0.05;
    let [full, dec] = both_shapes::<CORIOLIS>(&cor, &[0.0]);
    assert_eq!(full, dec);
    // Any rotation, or a quadrature coupling, keeps the full step.
    let coupled = Board::<f64x4>::new(&cor, &[0.0, 1e-3]).unwrap();
    assert!(!coupled.plant_decoupled());
    rot.device.quadrature_coupling_rad2_s2 = 10.0;
    assert!(!Board::<f64x4>::new(&rot, &[1.0]).unwrap().plant_decoupled());
}
