//! `reproduce`'s bandwidth sweep runs its points in refilled lanes (`refill_plan`): its 40 s
//! point as two segments side by side, the others whole, two lanes running two 4 s points
//! back to back, all in one group of eight. Its gains and lags against the same sweep run
//! whole: every whole point the same bits (a refilled lane is its point alone), the split
//! one within what its segments' settling leaves, below the hold error a config is warned at.

use gyroemu_analysis::bandwidth::{bandwidth_configs, bandwidth_points, BandwidthPoint};
use gyroemu_config::{presets::preset, Config, WARN_HOLD_ERROR_MDEG};
use gyroemu_experiment::table_sweep::PreparedTables;

fn cfgs() -> Vec<Config> {
    bandwidth_configs(&preset("m2tfg-ratetable").unwrap()).unwrap()
}

fn sweep(split: bool) -> Vec<BandwidthPoint> {
    let cfgs = cfgs();
    let t = PreparedTables::new(&cfgs, Some(1), split).unwrap();
    for g in 0..t.groups() {
        t.run_group(g);
    }
    bandwidth_points(&preset("m2tfg-ratetable").unwrap(), &t.finish().unwrap())
}

#[test]
fn the_split_bandwidth_sweep_reads_the_whole_ones_gains_and_lags() {
    let whole = sweep(false);
    let split = sweep(true);
    let mut moved = 0;
    for (w, s) in whole.iter().zip(&split) {
        assert_eq!(w.table_freq_hz, s.table_freq_hz);
        if w.table_freq_hz != 0.05 {
            // Whole points, refilled or not: their own bits.
            assert_eq!(w, s, "{} Hz", w.table_freq_hz);
            continue;
        }
        for k in 0..2 {
            // Measured: 1.23e-3 mdeg (the lag), 1.8e-8 of a gain (in four segments: 3.7e-3, 5.3e-8).
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
    // The split point's two modes read otherwise (segments settle anew).
    assert_eq!(moved, 2);
}

#[test]
fn the_bandwidth_sweep_runs_in_one_group_of_refilled_lanes() {
    let cfgs = cfgs();
    let m = cfgs[0].decimation() as u64;
    let n_settle = cfgs[0].n_settle_out();
    let t = PreparedTables::new(&cfgs, Some(1), true).unwrap();
    let width = gyroemu_board::max_lanes_for(&cfgs[0].board_params());
    let lanes: Vec<_> = (0..t.groups()).flat_map(|g| t.group_lanes(g)).collect();
    let mut segments = 0;
    for lane in &lanes {
        let mut end = 0;
        for (k, j) in lane.iter().enumerate() {
            // Back to back: each point after the lane's last has ended, at a block whose
            // input sample is a whole number of 1600 (carrier periods and re-sets).
            let at = j.at_block;
            assert!(
                at >= end && (at * m).is_multiple_of(1600) || k == 0 && at == 0,
                "{lane:?}"
            );
            end = at + n_settle + j.window_samples;
            segments += 1;
        }
    }
    // The 40 s point (sweep 0) as two halves, the other eight whole.
    assert_eq!(segments, 10);
    let halves: Vec<_> = lanes.iter().flatten().filter(|j| j.sweep == 0).collect();
    assert_eq!(halves.len(), 2);
    let four_s = lanes.iter().flatten().filter(|j| j.sweep >= 4);
    assert!(four_s
        .clone()
        .all(|j| j.window_samples == 9601 && j.start_block == 0));
    assert_eq!(four_s.count(), 5);
    // The packing is the machine's (the cut above is every machine's). In eight lanes: one
    // group of 32.5 s, two lanes running two of the 4 s points (sweeps 4 to 8) each, against
    // cut_to_fill's two groups of 22.25 and 16.25 s (9 242 600 group-samples).
    if width == 8 {
        assert_eq!((t.groups(), lanes.len()), (1, 8));
        assert_eq!(lanes.iter().filter(|l| l.len() == 2).count(), 2);
        assert_eq!(t.group_samples(0), 7_803_700);
    }
}

#[test]
fn a_board_with_converters_keeps_its_lanes_unrefilled_and_runs() {
    // Refills keep the bits only without converters or rails (`run_refilled` refuses such a
    // board): with a 16-bit DAC the same sweep plans no refill, and every group runs.
    let cfgs: Vec<Config> = cfgs()
        .into_iter()
        .map(|mut c| {
            c.board.dac_bits = Some(16);
            c.board.dac_full_scale = 1.5;
            c.validate().unwrap();
            c
        })
        .collect();
    let t = PreparedTables::new(&cfgs, Some(1), true).unwrap();
    for g in 0..t.groups() {
        assert!(t.group_lanes(g).iter().all(|l| l.len() == 1), "group {g}");
        t.run_group(g);
    }
    assert_eq!(t.finish().unwrap().len(), 9);
}
