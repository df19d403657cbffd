//! The board in f64x4 lanes gives each lane the result the scalar board gives for that
//! operating point alone (bit for bit: the arithmetic is lane-wise, and `Sample::mul_add` is
//! fused or not alike for f64 and f64x4), with and without noise (each point has its own
//! stream, so its noise does not depend on the lane that runs it).

use gyroemu_core::f64x4;
use gyroemu_experiment::board::Board;
use gyroemu_experiment::config::{Config, NoiseConfig};
use gyroemu_experiment::presets::preset;
use gyroemu_experiment::sweep::plan_point;

fn noisy(mut cfg: Config, seed: u64) -> Config {
    cfg.noise = Some(NoiseConfig {
        seed,
        temperature_k: 300.0,
        effective_mass_kg: Some(1e-9),
        tia_current_noise_a_per_rthz: 1e-13,
        tia_voltage_noise_v_per_rthz: 2e-8,
    });
    cfg.board.adc_bits = Some(14);
    cfg.board.adc_full_scale_v = 0.1;
    cfg
}

fn check_cfg(name: &str, cfg: &Config) {
    let rates = [25.0, 100.0, 175.0];
    let points: Vec<_> = rates.iter().map(|&r| plan_point(cfg, r)).collect();
    let n_settle = (0.05 * cfg.fs_out_hz()).ceil() as u64;
    let rad: Vec<f64> = points.iter().map(|p| p.rate_rad_s).collect();
    let streams = [7, 3, 11];
    let lanes = Board::<f64x4>::with_streams(cfg, &rad, &streams)
        .unwrap()
        .run(n_settle, &points, None, &|_| {})
        .unwrap();
    for (i, p) in points.iter().enumerate() {
        let scalar = Board::<f64>::with_streams(cfg, &[p.rate_rad_s], &[streams[i]])
            .unwrap()
            .run(n_settle, &[*p], None, &|_| {})
            .unwrap();
        assert_eq!(lanes[i], scalar[0], "{name}: lane {i}");
    }
}

fn check(name: &str, average_s: f64) {
    let mut cfg = preset(name).unwrap();
    cfg.experiment.average_s = average_s;
    cfg.experiment.settle_s = Some(0.05);
    check_cfg(name, &cfg);
    check_cfg(name, &noisy(cfg, 42));
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

#[test]
fn same_seed_same_bits_other_seed_other_bits() {
    let mut cfg = preset("m2tfg-coriolis").unwrap();
    cfg.experiment.average_s = 0.1;
    cfg.experiment.settle_s = Some(0.02);
    let p = plan_point(&cfg, 100.0);
    let run = |seed: u64| {
        let c = noisy(cfg.clone(), seed);
        Board::<f64>::new(&c, &[p.rate_rad_s])
            .unwrap()
            .run(48, &[p], None, &|_| {})
            .unwrap()[0]
    };
    assert_eq!(run(1), run(1));
    assert_ne!(run(1), run(2));
}
