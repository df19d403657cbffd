//! Rate-table sweeps that differ only in their table frequency and averaging time (the
//! bandwidth sweep: one point per frequency), run in shared lane groups, each lane on its own
//! table. Run one by one, each would be a group of one point; packed, nine frequencies take
//! two groups. Every point keeps the bits of its own sweep; asked to split
//! ([`PreparedTables::new`]), long points run as segments side by side (`split::cut_to_fill`),
//! each settling anew, within what that settling leaves of a whole run's average.

use crate::mutex::lock;
use crate::readout::SweepResult;
use crate::split::{combine, cut_each, cut_to_fill, segment_length_on, splittable};
use crate::sweep::{finish_sweep, group_samples, SweepError};
use gyroemu_board::{group_sizes, BoardParams, GroupBoard, LaneResult, RunOptions, Shape};
use gyroemu_config::Config;
use gyroemu_mixer::MAX_TABLE_HARMONIC;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::Mutex;

/// A finished lane: its sweep, its point's index there, its segment's start and window, and
/// its result.
type Finished = (usize, usize, u64, gyroemu_lpf::Window, LaneResult);

/// A group's finished lanes, or why it failed.
type GroupOutcome = Result<Vec<Finished>, SweepError>;

/// One point of one of the sweeps.
#[derive(Clone)]
struct Job {
    /// The sweep (index in the caller's configs) and the point's index in its rates.
    sweep: usize,
    index: usize,
    /// The point, with its segment's window when split.
    point: gyroemu_board::Point,
    /// Where the segment starts on the point's averaging axis, decimated samples (0 whole).
    start_block: u64,
    table_hz: f64,
    /// The table harmonics its own board would demodulate.
    harmonics: usize,
}

/// What the sweeps of one lane group must share: the board but for the table's frequency and
/// harmonics, and the settling.
fn board_key(cfg: &Config) -> (BoardParams, u64) {
    let p = cfg.board_params();
    let key = BoardParams {
        shape: Shape::RateTable { freq_hz: 0.0 },
        table_harmonics: 0,
        ..p
    };
    (key, cfg.n_settle_out())
}

/// Runs each of `cfgs` (validated rate-table configs) as [`crate::run_sweep`] would, without
/// progress or dumps, and returns their results in order: the same bits, in fewer lane
/// groups. Configs whose boards differ beyond the table (or whose settling differs) run in
/// groups of their own. `group_threads` as in [`crate::SweepOptions`].
pub fn run_table_sweeps(
    cfgs: &[Config],
    group_threads: Option<usize>,
) -> Result<Vec<SweepResult>, SweepError> {
    let tables = PreparedTables::new(cfgs, group_threads, false)?;
    tables.run_all();
    tables.finish()
}

/// The lane results of [`run_table_sweeps`], per config by point index: those of
/// [`crate::run_sweep_with`] on each config alone, bit for bit.
#[cfg(test)]
fn run_table_lanes(
    cfgs: &[Config],
    group_threads: Option<usize>,
) -> Result<Vec<BTreeMap<usize, LaneResult>>, SweepError> {
    let tables = PreparedTables::new(cfgs, group_threads, false)?;
    tables.run_all();
    tables.lanes()
}

/// The table sweeps of [`run_table_sweeps`] with their lane groups planned and boards built,
/// to run in any order on any threads ([`crate::queue`]).
pub struct PreparedTables<'c> {
    cfgs: &'c [Config],
    /// Each group's board (until its run takes it), its points and its settling.
    groups: Vec<(Mutex<Option<GroupBoard>>, Vec<Job>, u64)>,
    outcomes: Vec<Mutex<Option<GroupOutcome>>>,
    /// The lanes (segments) each point runs as, by (sweep, index).
    segments: BTreeMap<(usize, usize), usize>,
}

/// The classes of `cfgs` that can share a lane group (the board but for the table, and the
/// settling), each with its points, cut into segments with `split` ([`split_jobs`]).
#[allow(clippy::type_complexity)]
fn plan_classes(
    cfgs: &[Config],
    split: bool,
) -> Result<Vec<((BoardParams, u64), Vec<Job>)>, SweepError> {
    let mut classes: Vec<((BoardParams, u64), Vec<Job>)> = Vec::new();
    for (sweep, cfg) in cfgs.iter().enumerate() {
        let p = cfg.board_params();
        let Shape::RateTable { freq_hz } = p.shape else {
            return Err(SweepError::Param(gyroemu_core::ParamError::new(
                "experiment",
                "rate_table",
                "constant",
                "a table sweep takes rate-table configs only",
            )));
        };
        let key = board_key(cfg);
        let jobs = match classes.iter_mut().find(|(k, _)| *k == key) {
            Some((_, jobs)) => jobs,
            None => {
                classes.push((key, Vec::new()));
                &mut classes.last_mut().expect("just pushed").1
            }
        };
        for (index, &r) in cfg.emulated_rates_dps().iter().enumerate() {
            jobs.push(Job {
                sweep,
                index,
                point: cfg.plan_point(r),
                start_block: 0,
                table_hz: freq_hz,
                harmonics: p.table_harmonics,
            });
        }
    }
    if split {
        for ((_, n_settle), jobs) in &mut classes {
            *jobs = split_jobs(cfgs, jobs, *n_settle);
        }
    }
    Ok(classes)
}

/// The work of `cfgs`' table sweeps ([`crate::sweep_work`] of each, the points as each would
/// run alone: what their results report), with the longest lane (`longest_samples`) their
/// lane groups run, cut into segments with `split` as [`PreparedTables::new`] cuts them.
pub fn tables_work(cfgs: &[Config], split: bool) -> Result<crate::Work, SweepError> {
    let mut work = cfgs
        .iter()
        .map(crate::sweep_work)
        .reduce(|a, b| a.plus(b))
        .unwrap_or_default();
    // `longest_s` stays the longest point's signal; its lane may be a segment of it.
    work.longest_samples = plan_classes(cfgs, split)?
        .iter()
        .flat_map(|((_, n_settle), jobs)| {
            jobs.iter().map(move |j| {
                (n_settle + j.point.window.samples()) * cfgs[j.sweep].decimation() as u64
            })
        })
        .max()
        .unwrap_or(0);
    Ok(work)
}

impl<'c> PreparedTables<'c> {
    /// Plans the lane groups of `cfgs` and builds every board (so a bad parameter fails
    /// before any sample is computed). With `split`, the points of configs that can run as
    /// segments (`split::splittable`, boxcar windows) are cut where that fills lane groups
    /// (`split::cut_to_fill`); the cut depends on the configs alone.
    pub fn new(
        cfgs: &'c [Config],
        group_threads: Option<usize>,
        split: bool,
    ) -> Result<Self, SweepError> {
        let classes = plan_classes(cfgs, split)?;
        let mut segments: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for j in classes.iter().flat_map(|(_, jobs)| jobs) {
            *segments.entry((j.sweep, j.index)).or_default() += 1;
        }
        let threads = group_threads.unwrap_or_else(rayon::current_num_threads);
        let m_of = |j: &Job| cfgs[j.sweep].decimation() as u64;
        let mut groups = Vec::new();
        for ((key, n_settle), jobs) in &classes {
            let mut order: Vec<&Job> = jobs.iter().collect();
            // Longest window first, so a group's lanes end together (as in a sweep).
            order.sort_by_key(|j| core::cmp::Reverse(j.point.window.samples()));
            let mut rest = &order[..];
            let runs: Vec<u64> = order
                .iter()
                .map(|j| n_settle + j.point.window.samples())
                .collect();
            for size in group_sizes(key, &runs, threads) {
                let (g, r) = rest.split_at(size);
                rest = r;
                // The board demodulates the most harmonics any of its lanes needs; a lane's
                // harmonics do not depend on how many others are demodulated beside them.
                let p = BoardParams {
                    shape: Shape::RateTable {
                        freq_hz: g[0].table_hz,
                    },
                    table_harmonics: g.iter().map(|j| j.harmonics).max().unwrap_or(1),
                    ..*key
                };
                let rates: Vec<f64> = g.iter().map(|j| j.point.rate_rad_s).collect();
                let table_hz: Vec<f64> = g.iter().map(|j| j.table_hz).collect();
                // Each point draws the stream of its index in its own sweep.
                let streams: Vec<u64> = g.iter().map(|j| j.index as u64).collect();
                let starts: Vec<u64> = g.iter().map(|j| j.start_block * m_of(j)).collect();
                let board =
                    GroupBoard::with_table_hz_starts(&p, &rates, &table_hz, &streams, &starts)?;
                let jobs = g.iter().map(|&j| j.clone()).collect();
                groups.push((Mutex::new(Some(board)), jobs, *n_settle));
            }
        }
        Ok(Self {
            cfgs,
            outcomes: groups.iter().map(|_| Mutex::new(None)).collect(),
            groups,
            segments,
        })
    }

    /// The lane groups to run.
    pub fn groups(&self) -> usize {
        self.groups.len()
    }

    /// The input samples group `g` runs.
    pub fn group_samples(&self, g: usize) -> u64 {
        let (_, jobs, _) = &self.groups[g];
        let points: Vec<_> = jobs.iter().map(|j| j.point).collect();
        group_samples(&self.cfgs[jobs[0].sweep], &points)
    }

    /// Runs group `g` (once) on this thread.
    pub fn run_group(&self, g: usize) {
        let (board, jobs, n_settle) = &self.groups[g];
        let Some(mut board) = lock(board).take() else {
            return;
        };
        let points: Vec<_> = jobs.iter().map(|j| j.point).collect();
        let done = board
            .run(*n_settle, &points, RunOptions::default(), &|_| {})
            .map_err(SweepError::from)
            .map(|out| {
                jobs.iter()
                    .zip(out.lanes)
                    .map(|(j, mut lane)| {
                        // Harmonics beyond the point's own are zero in its own sweep.
                        for md in 0..2 {
                            for (i, h) in lane.table_z[md].iter_mut().enumerate() {
                                if i.abs_diff(MAX_TABLE_HARMONIC) > j.harmonics {
                                    *h = Default::default();
                                }
                            }
                        }
                        (j.sweep, j.index, j.start_block, j.point.window, lane)
                    })
                    .collect()
            });
        *lock(&self.outcomes[g]) = Some(done);
    }

    /// Runs every group, in parallel.
    fn run_all(&self) {
        (0..self.groups())
            .into_par_iter()
            .with_max_len(1)
            .for_each(|g| self.run_group(g));
    }

    /// Each config's lane results by point index, once every group has run (taken: once): a
    /// split point's from its segments in their order on its axis (`split::combine`).
    fn lanes(&self) -> Result<Vec<BTreeMap<usize, LaneResult>>, SweepError> {
        type Segments = Vec<(u64, gyroemu_lpf::Window, LaneResult)>;
        let mut parts: Vec<BTreeMap<usize, Segments>> = vec![BTreeMap::new(); self.cfgs.len()];
        for o in &self.outcomes {
            let done = lock(o).take();
            for (sweep, index, start, window, lane) in done.unwrap_or_else(|| Ok(Vec::new()))? {
                parts[sweep]
                    .entry(index)
                    .or_default()
                    .push((start, window, lane));
            }
        }
        Ok(parts
            .into_iter()
            .enumerate()
            .map(|(sweep, points)| {
                points
                    .into_iter()
                    // A point some of whose segments did not run is left out (then missing,
                    // as a whole point that did not run), never read from part of its window.
                    .filter(|(index, segs)| {
                        self.segments.get(&(sweep, *index)) == Some(&segs.len())
                    })
                    .map(|(index, mut segs)| {
                        segs.sort_by_key(|s| s.0);
                        let segs: Vec<_> = segs.into_iter().map(|(_, w, l)| (w, l)).collect();
                        (index, combine(&segs))
                    })
                    .collect()
            })
            .collect())
    }

    /// Each config's result, in order, once every group has run: what
    /// [`run_table_sweeps`] returns. Called once.
    pub fn finish(&self) -> Result<Vec<SweepResult>, SweepError> {
        self.finish_with_lanes().map(|(results, _)| results)
    }

    /// [`PreparedTables::finish`], with each config's lane results by point index (a split
    /// point's combined from its segments) beside. Called once.
    #[allow(clippy::type_complexity)]
    pub fn finish_with_lanes(
        &self,
    ) -> Result<(Vec<SweepResult>, Vec<BTreeMap<usize, LaneResult>>), SweepError> {
        let lanes = self.lanes()?;
        let results = self
            .cfgs
            .iter()
            .zip(&lanes)
            .map(|(cfg, l)| finish_sweep(cfg, l))
            .collect::<Result<_, _>>()?;
        Ok((results, lanes))
    }
}

/// A class's points (`jobs`, of one board and settling `n_settle`) as the segments of their
/// cut (`split::cut_to_fill`) when every config they come from can run segments and every
/// window is a boxcar; else as they are.
fn split_jobs(cfgs: &[Config], jobs: &[Job], n_settle: u64) -> Vec<Job> {
    let windows: Option<Vec<(u64, f64)>> = jobs
        .iter()
        .map(|j| match j.point.window {
            gyroemu_lpf::Window::Boxcar { n, frac } if splittable(&cfgs[j.sweep]) => {
                Some((n, frac))
            }
            _ => None,
        })
        .collect();
    let (Some(windows), Some(first)) = (windows, jobs.first()) else {
        return jobs.to_vec();
    };
    // The carrier, sample rate and decimation are the class's: any of its configs rounds
    // (its board parameters built once: a rate table's take steady-state solves).
    let p = cfgs[first.sweep].board_params();
    let Some(lens) = cut_to_fill(&windows, n_settle, &|len| segment_length_on(&p, len)) else {
        return jobs.to_vec();
    };
    let todo: Vec<usize> = (0..jobs.len()).collect();
    cut_each(&todo, &windows, &lens)
        .into_iter()
        .map(|lane| Job {
            point: gyroemu_board::Point {
                window: lane.window,
                ..jobs[lane.point].point
            },
            start_block: lane.start_block,
            ..jobs[lane.point].clone()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run_sweep;

    /// The rate-table preset, short, at table frequency `f` with rate amplitudes `rates`.
    fn cfg(f: f64, average_s: f64, rates: &[f64]) -> Config {
        let mut c = gyroemu_config::presets::preset("m2tfg-ratetable").unwrap();
        c.experiment.table_freq_hz = Some(f);
        c.experiment.average_s = average_s;
        c.experiment.settle_s = Some(0.02);
        c.experiment.rates_dps = rates.to_vec();
        c.validate().unwrap();
        c
    }

    fn noisy(mut c: Config, seed: u64) -> Config {
        c.noise = Some(gyroemu_config::NoiseConfig {
            seed,
            tia_current_noise_a_per_rthz: 5e-13,
            ..Default::default()
        });
        c.validate().unwrap();
        c
    }

    #[test]
    fn packed_sweeps_give_each_sweep_its_own_bits() {
        let mut other_drive = cfg(3.0, 0.34, &[50.0]);
        other_drive.drive.f1 *= 1.5;
        let cfgs = vec![
            cfg(2.0, 0.5, &[5.0]),
            cfg(7.0, 0.3, &[5.0]),
            cfg(0.5, 2.0, &[5.0, 900.0]),
            noisy(cfg(2.5, 0.4, &[100.0]), 3),
            noisy(cfg(4.0, 0.25, &[100.0, 20.0]), 3),
            other_drive,
            cfg(11.0, 0.3, &[5.0]),
        ];
        // The packing is exercised: lanes of one group need different harmonics.
        let h: Vec<usize> = cfgs.iter().map(|c| c.table_harmonics()).collect();
        assert!(h[0] != h[2] || h[1] != h[2], "harmonics {h:?}");
        // Lane by lane: the harmonics beyond a point's own are zero as in its own sweep.
        let lanes = run_table_lanes(&cfgs, Some(1)).unwrap();
        for (i, (c, l)) in cfgs.iter().zip(&lanes).enumerate() {
            let alone = crate::run_sweep_with(c, &|_, _| {}, None, Default::default()).unwrap();
            assert_eq!(*l, alone.lanes, "sweep {i}");
        }
        for threads in [Some(1), Some(2), None] {
            let packed = run_table_sweeps(&cfgs, threads).unwrap();
            assert_eq!(packed.len(), cfgs.len());
            for (i, (c, p)) in cfgs.iter().zip(&packed).enumerate() {
                let alone = run_sweep(c, &|_, _| {}, None).unwrap();
                // Through Debug: a one-rate sweep's line fit is NaN, which `==` never equals
                // (Debug prints each float's shortest exact form).
                assert_eq!(
                    format!("{p:?}"),
                    format!("{alone:?}"),
                    "sweep {i} ({threads:?} threads)"
                );
            }
        }
    }

    #[test]
    fn a_constant_rate_config_is_refused() {
        let mut c = cfg(2.0, 0.5, &[5.0]);
        c.experiment.rate_table = gyroemu_config::RateTable::Constant;
        c.experiment.table_freq_hz = None;
        let e = run_table_sweeps(&[c], None).err().unwrap().to_string();
        assert!(e.contains("rate-table configs only"), "{e}");
    }
}
