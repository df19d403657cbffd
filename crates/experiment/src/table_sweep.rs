//! Rate-table sweeps that differ only in their table frequency and averaging time (the
//! bandwidth sweep: one point per frequency), run in shared lane groups, each lane on its own
//! table. Run one by one, each would be a group of one point; packed, nine frequencies take
//! two groups. Every point keeps the bits of its own sweep; asked to split
//! ([`PreparedTables::new`]), long points run as segments side by side, each settling anew,
//! within what that settling leaves of a whole run's average, and lanes whose points have
//! ended take the next (`refill_plan`, `Board::run_refilled`: the same bits as alone), so the
//! nine frequencies run in one group of eight.

use crate::mutex::lock;
use crate::readout::SweepResult;
use crate::refill_plan::{cut_to_refill, pack_refilled, refill_grain, RefilledGroup};
use crate::split::{
    combine, cut_each, cut_to_fill, lane_samples_in, saves_enough, segment_length_on, splittable,
};
use crate::sweep::{finish_sweep, SweepError};
use gyroemu_board::{
    group_sizes, max_lanes_for, BoardParams, GroupBoard, LaneResult, Refill, RefillError,
    RunOptions, Shape,
};
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

/// A point (or segment) as a lane of a planned group runs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlannedPoint {
    /// Its sweep (index in the configs) and its index in that sweep's rates.
    pub sweep: usize,
    pub index: usize,
    /// Where the segment starts on the point's averaging axis, decimated samples (0 whole).
    pub start_block: u64,
    /// Its window's decimated samples.
    pub window_samples: u64,
    /// The block its lane starts it at (0 but for a refilled lane's later points).
    pub at_block: u64,
}

/// One lane group: its board (until its run takes it), per lane its points in order with the
/// block each starts at (one at 0 but in refilled lanes, `refill_plan`), and the settling.
struct Group {
    board: Mutex<Option<GroupBoard>>,
    lanes: Vec<Vec<(Job, u64)>>,
    n_settle: u64,
}

impl Group {
    /// The input samples the group runs: to its longest lane's end.
    fn samples(&self, m: u64) -> u64 {
        let end = |l: &Vec<(Job, u64)>| l.last().map_or(0, |(j, at)| at + j.blocks(self.n_settle));
        self.lanes.iter().map(end).max().unwrap_or(0) * m
    }
}

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

impl Job {
    /// The decimation blocks a lane runs for this point: the settling, then its window.
    fn blocks(&self, n_settle: u64) -> u64 {
        n_settle + self.point.window.samples()
    }
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
    groups: Vec<Group>,
    outcomes: Vec<Mutex<Option<GroupOutcome>>>,
    /// The lanes (segments) each point runs as, by (sweep, index).
    segments: BTreeMap<(usize, usize), usize>,
}

/// A class of configs that can share lane groups (the board but for the table, and the
/// settling), its points (or their segments), and, where its lanes are refilled, their
/// packing: groups, lanes, each lane's points (indices into the class's) with their start
/// blocks.
type Class = ((BoardParams, u64), Vec<Job>, Option<Vec<RefilledGroup>>);

/// The classes of `cfgs` that can share a lane group, each with its points, cut into segments
/// with `split` ([`split_jobs`]) and, where that runs fewer lane-samples, packed into
/// refilled lanes.
fn plan_classes(cfgs: &[Config], split: bool) -> Result<Vec<Class>, SweepError> {
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
    Ok(classes
        .into_iter()
        .map(|((key, n_settle), jobs)| {
            if !split {
                return ((key, n_settle), jobs, None);
            }
            let (jobs, refilled) = split_jobs(cfgs, &jobs, n_settle);
            ((key, n_settle), jobs, refilled)
        })
        .collect())
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
    // A refilled lane runs its points back to back: its end is what a group waits for.
    work.longest_samples = plan_classes(cfgs, split)?
        .iter()
        .flat_map(|((_, n_settle), jobs, refilled)| {
            let m = jobs
                .first()
                .map_or(1, |j| cfgs[j.sweep].decimation() as u64);
            let alone = jobs.iter().map(move |j| j.blocks(*n_settle) * m);
            let lanes = refilled.iter().flatten().flatten().map(move |l| {
                l.iter()
                    .map(|&(j, at)| at + jobs[j].blocks(*n_settle))
                    .max()
                    .unwrap_or(0)
                    * m
            });
            alone.chain(lanes).collect::<Vec<_>>()
        })
        .max()
        .unwrap_or(0);
    Ok(work)
}

impl<'c> PreparedTables<'c> {
    /// Plans the lane groups of `cfgs` and builds every board (so a bad parameter fails
    /// before any sample is computed). With `split`, the points of configs that can run as
    /// segments (`split::splittable`, boxcar windows) are cut where that fills lane groups,
    /// their lanes refilled where that runs fewer lane-samples (`split_jobs`); the cut
    /// depends on the configs alone, the packing of refilled lanes on the lane width (not on
    /// `group_threads`: it runs the fewest lane-samples, as `reproduce`'s queue wants).
    pub fn new(
        cfgs: &'c [Config],
        group_threads: Option<usize>,
        split: bool,
    ) -> Result<Self, SweepError> {
        let classes = plan_classes(cfgs, split)?;
        let mut segments: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for j in classes.iter().flat_map(|(_, jobs, _)| jobs) {
            *segments.entry((j.sweep, j.index)).or_default() += 1;
        }
        let threads = group_threads.unwrap_or_else(rayon::current_num_threads);
        let mut groups = Vec::new();
        for ((key, n_settle), jobs, refilled) in &classes {
            if let Some(plan) = refilled {
                for lanes in plan {
                    let lanes: Vec<Vec<(Job, u64)>> = lanes
                        .iter()
                        .map(|l| l.iter().map(|&(j, at)| (jobs[j].clone(), at)).collect())
                        .collect();
                    groups.push(build_group(cfgs, key, *n_settle, lanes)?);
                }
                continue;
            }
            let mut order: Vec<&Job> = jobs.iter().collect();
            // Longest window first, so a group's lanes end together (as in a sweep).
            order.sort_by_key(|j| core::cmp::Reverse(j.point.window.samples()));
            let mut rest = &order[..];
            let runs: Vec<u64> = order.iter().map(|j| j.blocks(*n_settle)).collect();
            for size in group_sizes(key, &runs, threads) {
                let (g, r) = rest.split_at(size);
                rest = r;
                let lanes = g.iter().map(|&j| vec![(j.clone(), 0)]).collect();
                groups.push(build_group(cfgs, key, *n_settle, lanes)?);
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

    /// Group `g`'s lanes: per lane, the points it runs in order.
    pub fn group_lanes(&self, g: usize) -> Vec<Vec<PlannedPoint>> {
        self.groups[g]
            .lanes
            .iter()
            .map(|l| {
                l.iter()
                    .map(|(j, at)| PlannedPoint {
                        sweep: j.sweep,
                        index: j.index,
                        start_block: j.start_block,
                        window_samples: j.point.window.samples(),
                        at_block: *at,
                    })
                    .collect()
            })
            .collect()
    }

    /// The input samples group `g` runs.
    pub fn group_samples(&self, g: usize) -> u64 {
        let group = &self.groups[g];
        let m = self.cfgs[group.lanes[0][0].0.sweep].decimation() as u64;
        group.samples(m)
    }

    /// Runs group `g` (once) on this thread.
    pub fn run_group(&self, g: usize) {
        let group = &self.groups[g];
        let Some(mut board) = lock(&group.board).take() else {
            return;
        };
        let firsts: Vec<&Job> = group.lanes.iter().map(|l| &l[0].0).collect();
        let points: Vec<_> = firsts.iter().map(|j| j.point).collect();
        let m = self.cfgs[firsts[0].sweep].decimation() as u64;
        let mut refills: Vec<Refill> = group
            .lanes
            .iter()
            .enumerate()
            .flat_map(|(lane, l)| {
                l[1..].iter().map(move |(j, at)| Refill {
                    lane,
                    at_block: *at,
                    point: j.point,
                    start: j.start_block * m,
                    table_hz: Some(j.table_hz),
                })
            })
            .collect();
        refills.sort_by_key(|r| (r.at_block, r.lane));
        let run = if refills.is_empty() {
            board
                .run(group.n_settle, &points, RunOptions::default(), &|_| {})
                .map_err(SweepError::from)
        } else {
            board
                .run_refilled(group.n_settle, &points, &refills, &|_| {})
                .map_err(|e| match e {
                    RefillError::Refused(e) => SweepError::from(e),
                    RefillError::NonFinite(f) => SweepError::from(f),
                })
        };
        let done = run.and_then(|out| {
            let mut finished = Vec::new();
            for (lane, l) in group.lanes.iter().enumerate() {
                // The lane's points in order: those before its last, then its last; a lane
                // that ran other than its plan would credit a point with another's result.
                let before = out.refilled.get(lane).map_or(&[][..], |r| &r[..]);
                if before.len() + 1 != l.len() {
                    return Err(SweepError::Param(gyroemu_core::ParamError::new(
                        "experiment",
                        "refills",
                        before.len(),
                        format!(
                            "lane {lane} was to run {} points before its last",
                            l.len() - 1
                        ),
                    )));
                }
                let results = before.iter().copied().chain([out.lanes[lane]]);
                for ((j, _), mut res) in l.iter().zip(results) {
                    // Harmonics beyond the point's own are zero in its own sweep.
                    for md in 0..2 {
                        for (i, h) in res.table_z[md].iter_mut().enumerate() {
                            if i.abs_diff(MAX_TABLE_HARMONIC) > j.harmonics {
                                *h = Default::default();
                            }
                        }
                    }
                    finished.push((j.sweep, j.index, j.start_block, j.point.window, res));
                }
            }
            Ok(finished)
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

/// The board of a group of `lanes` (per lane its points in order, each with its start block)
/// of the class `key` (the board but for the table) settling `n_settle`: each lane built for
/// its first point. It demodulates the most harmonics any of its points needs (a point's
/// harmonics do not depend on how many others are demodulated beside them).
fn build_group(
    cfgs: &[Config],
    key: &BoardParams,
    n_settle: u64,
    lanes: Vec<Vec<(Job, u64)>>,
) -> Result<Group, SweepError> {
    let firsts: Vec<&Job> = lanes.iter().map(|l| &l[0].0).collect();
    let m = cfgs[firsts[0].sweep].decimation() as u64;
    let p = BoardParams {
        shape: Shape::RateTable {
            freq_hz: firsts[0].table_hz,
        },
        table_harmonics: lanes
            .iter()
            .flatten()
            .map(|(j, _)| j.harmonics)
            .max()
            .unwrap_or(1),
        ..*key
    };
    let rates: Vec<f64> = firsts.iter().map(|j| j.point.rate_rad_s).collect();
    let table_hz: Vec<f64> = firsts.iter().map(|j| j.table_hz).collect();
    // Each point draws the stream of its index in its own sweep.
    let streams: Vec<u64> = firsts.iter().map(|j| j.index as u64).collect();
    let starts: Vec<u64> = firsts.iter().map(|j| j.start_block * m).collect();
    let board = GroupBoard::with_table_hz_starts(&p, &rates, &table_hz, &streams, &starts)?;
    Ok(Group {
        board: Mutex::new(Some(board)),
        lanes,
        n_settle,
    })
}

/// A class's points (`jobs`, of one board and settling `n_settle`) as the segments of their
/// cut when every config they come from can run segments and every window is a boxcar (else
/// as they are). Where the carrier allows refills (`refill_plan::refill_grain`), the cut for
/// refilled lanes (`refill_plan::cut_to_refill`) with its packing into this machine's lane
/// groups, if it runs at least 1/[`crate::split::MIN_IDLE_SAVING`] fewer lane-samples in
/// groups of eight than the cut without refill and no more than 1/`MIN_IDLE_SAVING` more in
/// groups of four (`split::saves_enough`; the same cut on every machine); else the cut that fills groups (`split::cut_to_fill`), if
/// one pays off. The bandwidth sweep's nine points (settling 12.25 s) run refilled: its 40 s
/// point in halves, the rest whole, two lanes running two 4 s points back to back, in one
/// group of eight lanes of 32.5 s (624 296 lane-samples counted in eights, 16 % fewer than
/// `cut_to_fill`'s 13 lanes in groups of 22.25 and 16.25 s, 739 408).
fn split_jobs(
    cfgs: &[Config],
    jobs: &[Job],
    n_settle: u64,
) -> (Vec<Job>, Option<Vec<RefilledGroup>>) {
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
        return (jobs.to_vec(), None);
    };
    // The carrier, sample rate and decimation are the class's: any of its configs rounds
    // (its board parameters built once: a rate table's take steady-state solves).
    let p = cfgs[first.sweep].board_params();
    let segment = |len| segment_length_on(&p, len);
    let todo: Vec<usize> = (0..jobs.len()).collect();
    let segments = |lens: &[u64]| -> Vec<Job> {
        cut_each(&todo, &windows, lens)
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
    };
    let fill = cut_to_fill(&windows, n_settle, &segment);
    // Refills keep the bits only of a board without converters or rails (`run_refilled`
    // refuses others; noise is not splittable already).
    if let Some(grain) = refill_grain(&p).filter(|_| !p.imperfect()) {
        let plain = fill
            .clone()
            .unwrap_or_else(|| windows.iter().map(|w| w.0.max(1)).collect());
        let plain = cut_each(&todo, &windows, &plain);
        let before = [8, 4].map(|width| lane_samples_in(&plain, n_settle, width));
        let (lens, in_eights) = cut_to_refill(&windows, n_settle, grain, &segment);
        let cut = segments(&lens);
        let runs: Vec<u64> = cut.iter().map(|j| j.blocks(n_settle)).collect();
        let in_fours = pack_refilled(&runs, 4, grain).1;
        if saves_enough(before, [in_eights, in_fours]) {
            let groups = pack_refilled(&runs, max_lanes_for(&p), grain).0;
            return (cut, Some(groups));
        }
    }
    match fill {
        Some(lens) => (segments(&lens), None),
        None => (jobs.to_vec(), None),
    }
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
