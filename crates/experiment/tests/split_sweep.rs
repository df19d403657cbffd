//! Split sweeps (`SweepOptions::split`) and the one queue `reproduce` runs its sweeps from: a
//! split sweep reads the phases of the whole one (within what re-settling leaves), gives the
//! same bits however its lanes are grouped, records the same dump; sweeps whose groups run
//! from one queue give each sweep the bits it has alone; the queue takes the costliest first.

use gyroemu_board::{LaneResult, DUMP_NODES};
use gyroemu_config::{presets::preset, Config};
use gyroemu_core::Complex64;
use gyroemu_experiment::prepared::PreparedSweep;
use gyroemu_experiment::queue::{run_longest_first, sweep_items, table_items, Item};
use gyroemu_experiment::table_sweep::PreparedTables;
use gyroemu_experiment::{
    finish_sweep, run_sweep_with, run_table_sweeps, DumpPlan, SweepOptions, SweepRun,
};
use gyroemu_lpf::Window;
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

/// `|a - b| / |a|` over the sideband averages C and S of both modes.
fn rel(a: &LaneResult, b: &LaneResult) -> f64 {
    let v = |r: &LaneResult| [r.c[0], r.c[1], r.s[0], r.s[1]];
    let norm = |z: &mut dyn Iterator<Item = Complex64>| z.map(|x| x.norm_sqr()).sum::<f64>().sqrt();
    norm(&mut v(a).iter().zip(v(b)).map(|(x, y)| x - y)) / norm(&mut v(a).into_iter())
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

/// A split sweep of `cfg` against its whole sweep: sideband averages within `1e-12` relative
/// and phases within `1e-10` deg. At Q = 200 the default settling (16 time constants plus 40
/// of the low-pass: 0.1 s) leaves e^-23.5 = 6e-11 of the mechanical transient, which decays
/// in tau = 4.2 ms of a 7.5 s segment: a share of 3.5e-14 of the average. The rest is the
/// rounding of differently cut compensated sums. Segments four decimated samples off their
/// place on the time axis move the average by 5e-5, segments without the time axis by 8e-3.
fn reads_the_whole_ones_phases(cfg: &Config) {
    reads_the_whole_ones_phases_within(cfg, 1e-12);
}

/// [`reads_the_whole_ones_phases`] with the sideband averages within `rel_tol` relative.
fn reads_the_whole_ones_phases_within(cfg: &Config, rel_tol: f64) {
    let whole = sweep(cfg, SweepOptions::default());
    let parts = sweep(cfg, split(1));
    // Four segments of each point ran, each settling anew: more work than the whole sweep.
    assert!(
        parts.point_samples > whole.point_samples,
        "{} {}",
        parts.point_samples,
        whole.point_samples
    );
    for (i, w) in &whole.lanes {
        let p = parts.lanes[i];
        let d = rel(w, &p);
        assert!(d < rel_tol, "point {i}: {d:e}");
        // Every sample a segment ran is counted (each settles anew).
        assert!(p.health.samples > w.health.samples);
    }
    let (rw, rp) = (
        finish_sweep(cfg, &whole.lanes).unwrap(),
        finish_sweep(cfg, &parts.lanes).unwrap(),
    );
    for (a, b) in rw.points.iter().zip(&rp.points) {
        for k in 0..2 {
            let d = (a.phase_deg[k] - b.phase_deg[k]).abs();
            assert!(d < 1e-10, "{} deg/s mode {k}: {d:e} deg", a.rate_dps);
        }
    }
}

#[test]
fn a_split_sweep_reads_the_phases_of_the_whole_one() {
    reads_the_whole_ones_phases(&rotating());
}

#[test]
fn segments_that_cannot_share_a_group_read_the_whole_ones_phases_too() {
    // A carrier of 15 000.1 Hz at 240 kHz repeats its phase word only after 2^61 samples:
    // segments then share groups only with those that start with them.
    let mut cfg = rotating();
    cfg.drive.carrier_hz = Some(15_000.1);
    cfg.validate().unwrap();
    let rates = cfg.emulated_rates_dps();
    let (lanes, packing) = gyroemu_experiment::split::lanes_of(
        &cfg,
        &[0, 1],
        &|i| cfg.plan_point(rates[i]),
        true,
        None,
    );
    assert_eq!(packing, gyroemu_experiment::split::Packing::SameStart);
    assert_eq!(lanes.len(), 8);
    reads_the_whole_ones_phases(&cfg);
}

/// [`rotating`] with three rates and 3 s of averaging (30 settling times): too short for
/// segments of 64 settling times, so it is cut to fill its idle lanes instead. Cut into
/// segments of about 0.75 s that fill groups of four (eleven lanes in three groups, against
/// one group of four at 3.1 s per lane whole), it would leave five lanes of a group of eight
/// idle; cut by the binary digits of three (2 + 1), the two longest points run in quarters
/// and the shortest in eighths: sixteen lanes in two full groups of eight.
fn rotating_three() -> Config {
    let mut c = rotating();
    c.experiment.rates_dps = vec![100.0, 140.0, 175.0];
    c.experiment.average_s = 3.0;
    c.validate().unwrap();
    c
}

#[test]
fn a_sweep_split_to_fill_its_idle_lanes_reads_the_phases_of_the_whole_one() {
    // The share of the start transient (6e-11 of the response, tau = 4.2 ms) in a 0.375 s
    // segment's average is 6.7e-13, twice a 0.75 s segment's; with the rounding of a point's
    // average cut into eight sums, 1.5e-12 was measured: within 3e-12 of a whole sweep's
    // sideband averages (and its phases within 1e-10 deg, as every split sweep).
    let cfg = rotating_three();
    let rates = cfg.emulated_rates_dps();
    let (lanes, _) = gyroemu_experiment::split::lanes_of(
        &cfg,
        &[0, 1, 2],
        &|i| cfg.plan_point(rates[i]),
        true,
        None,
    );
    assert_eq!(lanes.len(), 16);
    let mut per_point: Vec<usize> = (0..3)
        .map(|i| lanes.iter().filter(|l| l.point == i).count())
        .collect();
    per_point.sort();
    assert_eq!(per_point, [4, 4, 8]);
    reads_the_whole_ones_phases_within(&cfg, 3e-12);
    // And its bits do not depend on how its lanes are grouped.
    let one = sweep(&cfg, split(1));
    assert_eq!(one.lanes, sweep(&cfg, split(3)).lanes);
}

#[test]
fn a_sweep_cut_to_fill_groups_of_eight_reads_the_phases_of_the_whole_one() {
    // Six rates of 3 s (whole modulation periods: windows of 1.8 to 2.9 s): two segments
    // each fill groups of four (twelve lanes, of up to 1.44 s), and the four points with the
    // longest segments take a third to fill groups of eight: sixteen lanes of 0.75 to 1.03 s,
    // each point cut evenly.
    let mut cfg = rotating_three();
    cfg.experiment.rates_dps = vec![75.0, 100.0, 125.0, 140.0, 160.0, 175.0];
    cfg.validate().unwrap();
    let rates = cfg.emulated_rates_dps();
    let todo: Vec<usize> = (0..rates.len()).collect();
    let (lanes, _) =
        gyroemu_experiment::split::lanes_of(&cfg, &todo, &|i| cfg.plan_point(rates[i]), true, None);
    assert_eq!(lanes.len(), 16);
    let segments = |i: usize| lanes.iter().filter(|l| l.point == i).count();
    assert_eq!((0..6).filter(|&i| segments(i) == 3).count(), 4);
    reads_the_whole_ones_phases(&cfg);
    let one = sweep(&cfg, split(1));
    assert_eq!(one.lanes, sweep(&cfg, split(2)).lanes);
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

/// A dump of the 175 deg/s point from 0.5 s, within its first segment.
fn dump_of_175() -> DumpPlan {
    DumpPlan {
        rate_dps: 175.0,
        start_s: 0.5,
        duration_s: 0.002,
        decimated_duration_s: 1.0,
        nodes: DUMP_NODES.map(String::from).to_vec(),
    }
}

#[test]
fn a_split_sweep_records_the_dump_of_the_whole_one() {
    let cfg = rotating();
    let dump = dump_of_175();
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
    let t = PreparedTables::new(&table_cfgs, Some(1), false).unwrap();
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

/// Runs `f` on a pool of one thread, where the queue's order is the order items run in.
fn on_one_thread<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn the_queue_takes_the_costliest_item_first() {
    let order = Mutex::new(Vec::new());
    on_one_thread(|| {
        let costs = [1.0, 5.0, 3.0, 5.0, 0.0];
        let items: Vec<(f64, Item)> = costs
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                let order = &order;
                let item: Item = Box::new(move || order.lock().unwrap().push(i));
                (c, item)
            })
            .collect();
        run_longest_first(items);
    });
    // Decreasing cost, ties in the given order.
    assert_eq!(order.into_inner().unwrap(), [1, 3, 2, 0, 4]);
}

#[test]
fn a_sweep_is_finished_once_right_after_its_last_group_and_its_dump_written_once() {
    let cfg = rotating();
    let dir = tempfile::tempdir().unwrap();
    let hooks = Mutex::new(0);
    let hook = |_: &[std::path::PathBuf]| -> Result<Vec<std::path::PathBuf>, String> {
        *hooks.lock().unwrap() += 1;
        Ok(Vec::new())
    };
    let opts = SweepOptions {
        dump: Some(dump_of_175()),
        on_dump_early: Some(&hook),
        ..split(4)
    };
    let prepared = PreparedSweep::new(&cfg, &|_, _| {}, Some(dir.path()), opts).unwrap();
    assert!(prepared.groups() >= 2, "{} groups", prepared.groups());
    let events = Mutex::new(Vec::new());
    let then = || {
        let run = prepared.finish().unwrap();
        events.lock().unwrap().push(("finished", Some(run)));
    };
    on_one_thread(|| {
        let mut items = sweep_items(&prepared, 1.0, Some(&then));
        // Other work in the queue: before the sweep's groups (costlier) and after (cheaper).
        for (c, name) in [(1e12, "first"), (0.0, "last")] {
            let events = &events;
            let item: Item = Box::new(move || events.lock().unwrap().push((name, None)));
            items.push((c, item));
        }
        run_longest_first(items);
    });
    let events = events.into_inner().unwrap();
    let names: Vec<&str> = events.iter().map(|e| e.0).collect();
    // Once, right after the sweep's last group (before the cheaper item), and only then:
    // every point is whole, with its bits.
    assert_eq!(names, ["first", "finished", "last"]);
    let run = events[1].1.as_ref().unwrap();
    assert_eq!(run.lanes, sweep(&cfg, split(1)).lanes);
    // The dump was written once, by the group that recorded it, before the sweep finished.
    assert_eq!(*hooks.lock().unwrap(), 1);
    assert!(!run.dump_files.is_empty());
}

/// The rate-table preset at Q = 2000 (default settling 0.71 s, tau = 42 ms), one 100 deg/s
/// point on a 0.5 Hz table over 8 s (four periods), settling `extra_tau` mechanical time
/// constants beyond the default.
fn long_table(extra_tau: f64) -> Config {
    let mut c = preset("m2tfg-ratetable").unwrap();
    c.device.q = 2000.0;
    c.device.q_mode2 = None;
    c.experiment.settle_s = None;
    c.experiment.table_freq_hz = Some(0.5);
    c.experiment.rates_dps = vec![100.0];
    c.experiment.average_s = 8.0;
    c.validate().unwrap();
    let tau = 2000.0 / (std::f64::consts::PI * c.device.f0_hz);
    c.experiment.settle_s = Some(c.default_settle_s() + extra_tau * tau);
    c.validate().unwrap();
    c
}

/// `|a - b| / |a|` over both modes' table harmonics.
fn rel_table(a: &LaneResult, b: &LaneResult) -> f64 {
    let v = |r: &LaneResult| r.table_z.iter().flatten().copied().collect::<Vec<_>>();
    let norm = |z: &mut dyn Iterator<Item = Complex64>| z.map(|x| x.norm_sqr()).sum::<f64>().sqrt();
    let (va, vb) = (v(a), v(b));
    norm(&mut va.iter().zip(&vb).map(|(x, y)| x - y)) / norm(&mut va.iter().copied())
}

/// A table sweep's lanes and results, its long points split or whole.
fn tables_of(
    cfgs: &[Config],
    split: bool,
) -> (Vec<LaneResult>, Vec<gyroemu_experiment::SweepResult>) {
    let t = PreparedTables::new(cfgs, Some(1), split).unwrap();
    for g in 0..t.groups() {
        t.run_group(g);
    }
    let (r, lanes) = t.finish_with_lanes().unwrap();
    (lanes.iter().map(|l| l[&0]).collect(), r)
}

#[test]
fn a_rate_tables_long_point_split_reads_the_whole_ones_harmonics() {
    // Whole, the point is one lane of 8.71 s; cut in eight even segments of 1 s (each
    // settling 0.71 s anew, its table at its start's phase), one full group of eight.
    let cfg = long_table(0.0);
    let rates = cfg.emulated_rates_dps();
    let Window::Boxcar { n, frac } = cfg.plan_point(rates[0]).window else {
        panic!("boxcar")
    };
    let segment = |len| gyroemu_experiment::split::segment_length(&cfg, len);
    let lens = gyroemu_experiment::split::cut_to_fill(&[(n, frac)], cfg.n_settle_out(), &segment)
        .expect("cut");
    assert_eq!(n.div_ceil(lens[0]), 8);
    let (whole, rw) = tables_of(std::slice::from_ref(&cfg), false);
    let (parts, rp) = tables_of(std::slice::from_ref(&cfg), true);
    // What is left is the start transient of each segment: e^-16 of the drive's response
    // after the default settling, decaying within tau = 42 ms of a 1 s segment.
    let d = rel_table(&whole[0], &parts[0]);
    assert!(d > 0.0 && d < 1e-8, "{d:e}");
    let (a, b) = (&rw[0].points[0], &rp[0].points[0]);
    for k in 0..2 {
        let lag = (a.table_lag_deg.unwrap()[k] - b.table_lag_deg.unwrap()[k]).abs();
        // The phase read is about 0.07 rad of the carrier's response: its relative error
        // is the harmonics' over that (measured: 1.4e-7 and 1.5e-6 deg).
        assert!(lag < 3e-6, "mode {k}: the lag moved {lag:e} deg");
        let phase = (a.phase_deg[k] - b.phase_deg[k]).abs();
        assert!(phase < 3e-7, "mode {k}: the phase moved {phase:e} deg");
    }
    // It is the plant's start transient: three time constants more settling divide it by
    // e^3 (measured: 20.090 against 20.086).
    let longer = long_table(3.0);
    let (w3, _) = tables_of(std::slice::from_ref(&longer), false);
    let (p3, _) = tables_of(std::slice::from_ref(&longer), true);
    let d3 = rel_table(&w3[0], &p3[0]);
    let fold = d / d3 / 3f64.exp();
    assert!((fold - 1.0).abs() < 0.05, "{d:e} then {d3:e}");
}

#[test]
fn a_split_table_sweeps_bits_do_not_depend_on_its_threads_and_a_part_run_point_is_missing() {
    // The long point in eight segments beside a short one of another table frequency (a
    // 2 Hz table over 2 s, whole), in any grouping.
    let mut short = long_table(0.0);
    short.experiment.table_freq_hz = Some(2.0);
    short.experiment.average_s = 2.0;
    short.validate().unwrap();
    let cfgs = [long_table(0.0), short];
    let run = |threads: Option<usize>| {
        let t = PreparedTables::new(&cfgs, threads, true).unwrap();
        for g in 0..t.groups() {
            t.run_group(g);
        }
        t.finish_with_lanes().unwrap().1
    };
    let one = run(Some(1));
    for threads in [Some(2), Some(3), None] {
        assert_eq!(run(threads), one, "{threads:?}");
    }
    // A split point some of whose segments did not run is missing, never read from part of
    // its window: the long point alone, its eight segments in two groups of four on two
    // threads, the second not run.
    let cfgs = [long_table(0.0)];
    let t = PreparedTables::new(&cfgs, Some(2), true).unwrap();
    assert_eq!(t.groups(), 2);
    t.run_group(0);
    match t.finish() {
        Err(gyroemu_experiment::SweepError::Missing(points)) => assert_eq!(points, [0]),
        other => panic!("{other:?}"),
    }
}
