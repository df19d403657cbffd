//! Split sweeps (`SweepOptions::split`) and the one queue `reproduce` runs its sweeps from: a
//! split sweep reads the phases of the whole one (within what re-settling leaves), gives the
//! same bits however its lanes are grouped, records the same dump; sweeps whose groups run
//! from one queue give each sweep the bits it has alone; the queue takes the costliest first.

use gyroemu_board::DUMP_NODES;
use gyroemu_config::{presets::preset, Config};
use gyroemu_experiment::prepared::PreparedSweep;
use gyroemu_experiment::queue::{run_longest_first, sweep_items, table_items, Item};
use gyroemu_experiment::table_sweep::PreparedTables;
use gyroemu_experiment::{
    finish_sweep, run_sweep_with, run_table_sweeps, DumpPlan, SweepOptions, SweepRun,
};
use std::sync::Mutex;

/// The rotating preset at Q = 200 (settling 0.1 s), two rates, 30 s of averaging: each point
/// splits into four segments of 7.5 s (64 settling times at least), whose eight lanes fill
/// one group of eight.
fn rotating() -> Config {
    let mut c = preset("m2tfg-rotating").unwrap();
    c.device.q = 200.0;
    // The preset's settling was resolved for its Q of 2000: back to the default, 16 tau.
    c.experiment.settle_s = None;
    c.experiment.rates_dps = vec![100.0, 175.0];
    c.experiment.average_s = 30.0;
    c.validate().unwrap();
    c
}

fn sweep(cfg: &Config, opts: SweepOptions) -> SweepRun {
    run_sweep_with(cfg, &|_, _| {}, None, opts).unwrap()
}

fn split(group_threads: usize) -> SweepOptions<'static> {
    SweepOptions {
        split: true,
        group_threads: Some(group_threads),
        ..Default::default()
    }
}

#[test]
fn a_split_sweep_reads_the_phases_of_the_whole_one() {
    let cfg = rotating();
    let whole = sweep(&cfg, SweepOptions::default());
    let parts = sweep(&cfg, split(1));
    // Four segments of each point ran, each settling anew: more work than the whole sweep.
    assert!(
        parts.point_samples > whole.point_samples,
        "{} {}",
        parts.point_samples,
        whole.point_samples
    );
    for (i, w) in &whole.lanes {
        let p = parts.lanes[i];
        for k in 0..2 {
            // Each segment settles 16 time constants: e^-16 = 1.1e-7 of the response is left
            // at its start, and it decays in tau = 4.2 ms of the 7.5 s segment, so its share
            // of the average is about 1.1e-7 tau / 7.5 s = 6e-11 (a segment without the
            // point's time axis is off by 8e-3).
            for (a, b) in [(w.c[k], p.c[k]), (w.s[k], p.s[k])] {
                let rel = (a - b).norm() / a.norm();
                assert!(rel < 1e-9, "point {i} mode {k}: {rel:e}");
            }
        }
        // Every sample a segment ran is counted (each settles anew).
        assert!(p.health.samples > w.health.samples);
    }
    let (rw, rp) = (
        finish_sweep(&cfg, &whole.lanes).unwrap(),
        finish_sweep(&cfg, &parts.lanes).unwrap(),
    );
    for (a, b) in rw.points.iter().zip(&rp.points) {
        for k in 0..2 {
            // 6e-11 rad is 3.4e-9 deg.
            let d = (a.phase_deg[k] - b.phase_deg[k]).abs();
            assert!(d < 1e-7, "{} deg/s mode {k}: {d:e} deg", a.rate_dps);
        }
    }
}

#[test]
fn a_split_sweeps_bits_do_not_depend_on_how_its_lanes_are_grouped() {
    let cfg = rotating();
    let one = sweep(&cfg, split(1));
    for threads in [2, 3, 8] {
        let other = sweep(&cfg, split(threads));
        assert_eq!(one.lanes, other.lanes, "{threads} threads");
    }
}

#[test]
fn a_split_sweep_records_the_dump_of_the_whole_one() {
    let cfg = rotating();
    let dump = DumpPlan {
        rate_dps: 175.0,
        start_s: 0.5,
        duration_s: 0.002,
        decimated_duration_s: 1.0,
        nodes: DUMP_NODES.map(String::from).to_vec(),
    };
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let with_dump = |o: SweepOptions<'static>| SweepOptions {
        dump: Some(dump.clone()),
        ..o
    };
    let whole = run_sweep_with(
        &cfg,
        &|_, _| {},
        Some(a.path()),
        with_dump(Default::default()),
    );
    let parts = run_sweep_with(&cfg, &|_, _| {}, Some(b.path()), with_dump(split(1)));
    let (whole, parts) = (whole.unwrap(), parts.unwrap());
    assert!(
        parts.point_samples > whole.point_samples,
        "the sweep was split"
    );
    assert_eq!(whole.dump_files.len(), parts.dump_files.len());
    assert!(!whole.dump_files.is_empty());
    for (x, y) in whole.dump_files.iter().zip(&parts.dump_files) {
        assert_eq!(x.file_name(), y.file_name());
        assert_eq!(
            std::fs::read(x).unwrap(),
            std::fs::read(y).unwrap(),
            "{x:?}"
        );
    }
}

/// Two short rate-table configs for the queue.
fn tables() -> Vec<Config> {
    [(2.0, 0.5), (5.0, 0.4)]
        .iter()
        .map(|&(f, avg)| {
            let mut c = preset("m2tfg-ratetable").unwrap();
            c.experiment.table_freq_hz = Some(f);
            c.experiment.average_s = avg;
            c.experiment.settle_s = Some(0.02);
            c.experiment.rates_dps = vec![5.0, 50.0];
            c.validate().unwrap();
            c
        })
        .collect()
}

#[test]
fn sweeps_run_from_one_queue_give_each_sweep_its_own_bits() {
    let mut coriolis = preset("m2tfg-coriolis").unwrap();
    coriolis.experiment.average_s = 0.2;
    coriolis.experiment.settle_s = Some(0.02);
    let rot = rotating();
    let table_cfgs = tables();
    let a = PreparedSweep::new(&rot, &|_, _| {}, None, split(1)).unwrap();
    let b = PreparedSweep::new(&coriolis, &|_, _| {}, None, Default::default()).unwrap();
    let t = PreparedTables::new(&table_cfgs, Some(1)).unwrap();
    let mut items = sweep_items(&a, 1.0, None);
    items.extend(sweep_items(&b, 1.0, None));
    items.extend(table_items(&t, 1.35, None));
    run_longest_first(items);
    assert_eq!(a.finish().unwrap().lanes, sweep(&rot, split(1)).lanes);
    assert_eq!(
        b.finish().unwrap().lanes,
        sweep(&coriolis, Default::default()).lanes
    );
    // Through Debug: a table sweep's fits may be NaN, which `==` never equals.
    assert_eq!(
        format!("{:?}", t.finish().unwrap()),
        format!("{:?}", run_table_sweeps(&table_cfgs, Some(1)).unwrap())
    );
}

#[test]
fn the_queue_takes_the_costliest_item_first_and_runs_what_items_spawn() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let order = Mutex::new(Vec::new());
    pool.install(|| {
        let costs = [1.0, 5.0, 3.0, 5.0, 0.0];
        let items: Vec<(f64, Item)> = costs
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                let order = &order;
                let item: Item = Box::new(move |s| {
                    order.lock().unwrap().push(i);
                    // A task spawned by the item runs before the queue ends.
                    s.spawn(move |_| order.lock().unwrap().push(10 + i));
                });
                (c, item)
            })
            .collect();
        run_longest_first(items);
    });
    let order = order.into_inner().unwrap();
    let items: Vec<usize> = order.iter().copied().filter(|&i| i < 10).collect();
    // Decreasing cost, ties in the given order.
    assert_eq!(items, [1, 3, 2, 0, 4]);
    let mut spawned: Vec<usize> = order.iter().copied().filter(|&i| i >= 10).collect();
    spawned.sort_unstable();
    assert_eq!(spawned, [10, 11, 12, 13, 14]);
}

#[test]
fn a_sweep_is_finished_once_right_after_its_last_group() {
    let cfg = rotating();
    let prepared = PreparedSweep::new(&cfg, &|_, _| {}, None, split(3)).unwrap();
    assert!(prepared.groups() >= 2, "{} groups", prepared.groups());
    let runs = Mutex::new(Vec::new());
    let then = || runs.lock().unwrap().push(prepared.finish().unwrap());
    let mut items = sweep_items(&prepared, 1.0, Some(&then));
    // Other work in the queue, before and after the sweep's groups.
    for c in [1e12, 0.0] {
        let item: Item = Box::new(|_| {});
        items.push((c, item));
    }
    run_longest_first(items);
    let runs = runs.into_inner().unwrap();
    // Once, and only when every group had run: both points are whole.
    assert_eq!(runs.len(), 1);
    assert_eq!(runs[0].lanes, sweep(&cfg, split(1)).lanes);
}
