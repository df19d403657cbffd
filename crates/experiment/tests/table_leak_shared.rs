//! The read-out computes a rate-table window's leak once per window and shares it among the
//! points with that window: each point still reads with its own window's leak, whatever
//! windows its neighbours have.

use gyroemu_board::{LaneResult, Point};
use gyroemu_config::presets::preset;
use gyroemu_experiment::{post_process, run_sweep_with, SweepOptions};
use gyroemu_lpf::Window;

#[test]
fn each_point_reads_with_its_own_windows_leak() {
    let mut cfg = preset("m2tfg-ratetable").unwrap();
    cfg.experiment.rates_dps = vec![25.0, 75.0, 125.0, 175.0];
    cfg.experiment.average_s = 1.0;
    let run = run_sweep_with(&cfg, &|_, _| {}, None, SweepOptions::default()).unwrap();
    let rates = cfg.emulated_rates_dps();
    let lanes: Vec<LaneResult> = (0..rates.len()).map(|i| run.lanes[&i]).collect();
    let planned: Vec<Point> = rates.iter().map(|&r| cfg.plan_point(r)).collect();
    // The same points over one sample less: another window, with another leak.
    let shorter: Vec<Point> = planned
        .iter()
        .map(|p| match p.window {
            Window::Boxcar { n, frac } => Point {
                window: Window::Boxcar { n: n - 1, frac },
                ..*p
            },
            Window::Hann { .. } => panic!("the preset averages with a boxcar"),
        })
        .collect();
    let mixed: Vec<Point> = (0..rates.len())
        .map(|i| if i % 2 == 0 { planned[i] } else { shorter[i] })
        .collect();
    let read = |points: &[Point]| post_process(&cfg, &rates, points, &lanes).unwrap().points;
    let (all_planned, all_shorter, all_mixed) = (read(&planned), read(&shorter), read(&mixed));
    assert_eq!(all_mixed.len(), rates.len());
    for (i, r) in all_mixed.iter().enumerate() {
        let own = if i % 2 == 0 {
            &all_planned[i]
        } else {
            &all_shorter[i]
        };
        assert_eq!(r, own, "point {i}");
        // The two windows read differently, so a leak taken from the other window would show.
        assert_ne!(
            all_planned[i].phase_deg, all_shorter[i].phase_deg,
            "point {i}"
        );
    }
}
