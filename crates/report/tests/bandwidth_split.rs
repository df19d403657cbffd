//! `reproduce`'s bandwidth sweep runs its two longest points as segments side by side
//! (`split::cut_to_fill`): its gains and lags against the same sweep run whole, every point
//! within what the segments' settling leaves, below the hold error a config is warned at.

use gyroemu_analysis::bandwidth::{bandwidth_configs, bandwidth_points, BandwidthPoint};
use gyroemu_config::{presets::preset, WARN_HOLD_ERROR_MDEG};
use gyroemu_experiment::table_sweep::PreparedTables;

fn sweep(split: bool) -> Vec<BandwidthPoint> {
    let base = preset("m2tfg-ratetable").unwrap();
    let cfgs = bandwidth_configs(&base).unwrap();
    let t = PreparedTables::new(&cfgs, Some(1), split).unwrap();
    for g in 0..t.groups() {
        t.run_group(g);
    }
    bandwidth_points(&base, &t.finish().unwrap())
}

#[test]
fn the_split_bandwidth_sweep_reads_the_whole_ones_gains_and_lags() {
    let whole = sweep(false);
    // The 40 s point in four segments, the 20 s one in two, each settling 12.25 s anew.
    let split = sweep(true);
    let mut moved = 0;
    for (w, s) in whole.iter().zip(&split) {
        assert_eq!(w.table_freq_hz, s.table_freq_hz);
        for k in 0..2 {
            // Measured: at most 3.7e-3 mdeg (the 0.05 Hz point's lag), 5.3e-8 of a gain.
            let lag_mdeg = (w.lag_deg[k] - s.lag_deg[k]).abs() * 1e3;
            assert!(
                lag_mdeg < WARN_HOLD_ERROR_MDEG,
                "{} Hz: the lag moved {lag_mdeg:e} mdeg",
                w.table_freq_hz
            );
            let gain = (w.gain_deg_per_dps[k] / s.gain_deg_per_dps[k] - 1.0).abs();
            assert!(gain < 1e-6, "{} Hz: gain {gain:e}", w.table_freq_hz);
            moved += usize::from(lag_mdeg > 0.0);
        }
    }
    // Only the split points' (0.05 and 0.1 Hz, both modes) read otherwise.
    assert_eq!(moved, 4);
}
