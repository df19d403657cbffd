//! A sweep taken apart for whoever runs it: [`PreparedSweep::new`] plans its lane groups and
//! builds every board (so a bad parameter fails before any sample), [`PreparedSweep::run_group`]
//! runs one group on the calling thread, and [`PreparedSweep::finish`] writes the dump and puts
//! the points together. [`run_sweep_with`] runs one sweep's groups in parallel;
//! [`crate::queue`] runs several sweeps' groups from one queue, the costliest first.

use crate::dump::DumpPlan;
use crate::mutex::lock;
use crate::progress::Progress;
use crate::readout::SweepResult;
use crate::split::{combine, lanes_of, pack, Lane};
use crate::sweep::{
    add_group_progress, finish_sweep, group_samples, write_dump, DumpWritten, SweepError,
    SweepOptions, SweepRun,
};
use gyroemu_board::{group_sizes, GroupBoard, LaneResult, Point, Probe, RunOptions};
use gyroemu_config::Config;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// A group's points, their work, whether all finished, and its probe when it recorded the
/// dump (then the dump is written and the points passed on in [`PreparedSweep::finish`]).
type Finished = (Vec<(Lane, LaneResult)>, u64, bool, Option<Probe>);

/// A group skipped (None: stopped before it started) or run.
type Outcome = Option<Result<Finished, SweepError>>;

/// A sweep's lane groups, boards built, ready to run in any order on any threads.
pub struct PreparedSweep<'a> {
    cfg: &'a Config,
    progress: Progress<'a>,
    dump_dir: Option<&'a Path>,
    opts: SweepOptions<'a>,
    rates: Vec<f64>,
    n_settle: u64,
    groups: Vec<Vec<Lane>>,
    /// Each group's board until its run takes it.
    boards: Vec<Mutex<Option<GroupBoard>>>,
    outcomes: Vec<Mutex<Outcome>>,
    /// Each point's lanes (one, or its segments), to put its result together.
    lanes_per_point: BTreeMap<usize, usize>,
    /// The dumped point's index and its plan.
    dump: Option<(usize, DumpPlan)>,
    total: u64,
    done: AtomicU64,
    /// The points computed before (`SweepOptions::done`), returned with the new ones.
    done_points: Mutex<BTreeMap<usize, LaneResult>>,
    /// Raised by the caller's flag (copied at each progress report) or by a failed group.
    stop: Arc<AtomicBool>,
    /// The dump written early (`on_dump_early`) by [`PreparedSweep::write_early_dump`], which
    /// the recording group's hand-on calls (or a task it spawns).
    early: Mutex<Option<Result<DumpWritten, SweepError>>>,
}

impl<'a> PreparedSweep<'a> {
    /// Plans the lane groups of the points `opts` assigns and that are not done yet (see
    /// [`crate::run_sweep_with`]) and builds their boards.
    pub fn new(
        cfg: &'a Config,
        progress: Progress<'a>,
        dump_dir: Option<&'a Path>,
        mut opts: SweepOptions<'a>,
    ) -> Result<Self, SweepError> {
        let rates = cfg.emulated_rates_dps();
        let mut todo: Vec<usize> = match &opts.only {
            Some(only) => {
                let mut v: Vec<usize> = only.iter().copied().filter(|&i| i < rates.len()).collect();
                v.sort_unstable();
                v.dedup();
                v
            }
            None => (0..rates.len()).collect(),
        };
        todo.retain(|i| !opts.done.contains_key(i));
        let plan = |i: usize| cfg.plan_point(rates[i]);
        todo.sort_by_key(|&i| core::cmp::Reverse(plan(i).window.samples()));
        let threads = opts
            .group_threads
            .unwrap_or_else(rayon::current_num_threads);
        let dump = opts
            .dump
            .clone()
            .or_else(|| DumpPlan::from_config(cfg))
            .map(|d| {
                let idx = rates.iter().position(|&r| r == d.rate_dps).unwrap_or(0);
                (idx, d)
            });
        let whole_run = opts.on_group.is_none()
            && opts.cancel.is_none()
            && opts.only.is_none()
            && opts.done.is_empty();
        let dump_end_s = dump
            .as_ref()
            .map(|(_, d)| d.start_s + d.duration_s.max(d.decimated_duration_s));
        let (lanes, packing) = lanes_of(cfg, &todo, &plan, opts.split && whole_run, dump_end_s);
        let params = cfg.board_params();
        let groups = pack(&lanes, packing, &|set| {
            let runs: Vec<u64> = set
                .iter()
                .map(|l| cfg.n_settle_out() + l.window.samples())
                .collect();
            group_sizes(&params, &runs, threads)
        });
        let mut lanes_per_point: BTreeMap<usize, usize> = BTreeMap::new();
        for l in &lanes {
            *lanes_per_point.entry(l.point).or_default() += 1;
        }
        let stop = Arc::new(AtomicBool::new(false));
        let m = cfg.decimation() as u64;
        let mut boards = Vec::with_capacity(groups.len());
        for g in &groups {
            let r: Vec<f64> = g.iter().map(|l| plan(l.point).rate_rad_s).collect();
            // Each point draws the noise stream of its index in the emulated rates.
            let streams: Vec<u64> = g.iter().map(|l| l.point as u64).collect();
            let starts: Vec<u64> = g.iter().map(|l| l.start_block * m).collect();
            let mut board = GroupBoard::with_starts(&params, &r, &streams, &starts)?;
            board.set_cancel(stop.clone());
            boards.push(Mutex::new(Some(board)));
        }
        let done_points = Mutex::new(std::mem::take(&mut opts.done));
        let mut s = Self {
            cfg,
            done_points,
            progress,
            dump_dir,
            opts,
            rates,
            n_settle: cfg.n_settle_out(),
            outcomes: groups.iter().map(|_| Mutex::new(None)).collect(),
            groups,
            boards,
            lanes_per_point,
            dump,
            total: 0,
            done: AtomicU64::new(0),
            stop,
            early: Mutex::new(None),
        };
        s.total = (0..s.groups.len()).map(|g| s.group_samples(g)).sum();
        Ok(s)
    }

    /// The lane groups to run.
    pub fn groups(&self) -> usize {
        self.groups.len()
    }

    /// The input samples group `g` runs (its settling and longest window).
    pub fn group_samples(&self, g: usize) -> u64 {
        group_samples(self.cfg, &self.points(g))
    }

    fn points(&self, g: usize) -> Vec<Point> {
        self.groups[g]
            .iter()
            .map(|l| Point {
                rate_rad_s: self.cfg.plan_point(self.rates[l.point]).rate_rad_s,
                window: l.window,
            })
            .collect()
    }

    fn user_cancel(&self) -> bool {
        self.opts
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// Runs group `g` (once) on this thread; `hand_on` receives the dump's probe as soon as
    /// its windows are recorded (see [`SweepOptions::on_dump_early`]), when asked for.
    pub fn run_group(&self, g: usize, hand_on: &(dyn Fn(&Probe) + Sync)) {
        // A group runs once: a second call leaves its outcome as it is.
        let Some(board) = lock(&self.boards[g]).take() else {
            return;
        };
        let outcome = self.run_group_inner(g, board, hand_on);
        if matches!(outcome, Some(Err(_))) {
            self.stop.store(true, Ordering::Relaxed);
        }
        *lock(&self.outcomes[g]) = outcome;
    }

    fn run_group_inner(
        &self,
        g: usize,
        mut board: GroupBoard,
        hand_on: &(dyn Fn(&Probe) + Sync),
    ) -> Outcome {
        if self.user_cancel() {
            self.stop.store(true, Ordering::Relaxed);
        }
        if self.stop.load(Ordering::Relaxed) {
            return None;
        }
        let lanes = &self.groups[g];
        let points = self.points(g);
        // The dump is its point's first segment's (which starts where the point does).
        let mut probe = self.dump.as_ref().and_then(|(idx, plan)| {
            lanes
                .iter()
                .position(|l| l.point == *idx && l.segment == 0)
                .map(|lane| (lane, plan.probe(self.cfg, lane)))
        });
        let last = AtomicU64::new(0);
        let report = |n: u64| {
            add_group_progress(&self.done, &last, n, self.total, self.progress);
            if self.user_cancel() {
                self.stop.store(true, Ordering::Relaxed);
            }
        };
        let early_on = self.opts.on_dump_early.is_some() && self.dump_dir.is_some();
        let run_opts = RunOptions {
            probe: probe.as_mut().map(|(_, p)| p),
            on_probe_recorded: early_on.then_some(hand_on),
            ..Default::default()
        };
        let res = board.run(self.n_settle, &points, run_opts, &report);
        Some((|| {
            let out = res?;
            // A raised flag may have cut the run short: only the lanes whose own window ended
            // before it hold their points' results. The dumped lane waits for a whole run,
            // which writes its dump.
            let whole = out.complete.iter().all(|&c| c);
            let pts: Vec<(Lane, LaneResult)> = lanes
                .iter()
                .copied()
                .zip(out.lanes)
                .zip(&out.complete)
                .enumerate()
                .filter(|(lane, (_, &c))| {
                    whole || (c && probe.as_ref().is_none_or(|(l, _)| l != lane))
                })
                .map(|(_, (p, _))| p)
                .collect();
            // A whole group that recorded the dump hands its probe on.
            let probe = probe
                .filter(|_| whole && self.dump_dir.is_some())
                .map(|(_, p)| p);
            if let (None, Some(f), false) = (&probe, self.opts.on_group, pts.is_empty()) {
                f(&by_point(&pts)).map_err(SweepError::Output)?;
            }
            let work = if whole {
                self.group_samples(g) * lanes.len() as u64
            } else {
                0
            };
            Ok((pts, work, whole, probe))
        })())
    }

    /// Writes the dump recorded by the group that handed its probe on (with `on_dump_early`):
    /// what [`PreparedSweep::run_group`]'s `hand_on` calls, on the group's thread (the queue)
    /// or in a task it spawns ([`run_sweep_with`]).
    pub fn write_early_dump(&self, p: &Probe) {
        if let (Some(then), Some(dir)) = (self.opts.on_dump_early, self.dump_dir) {
            *lock(&self.early) = Some(write_dump(p, dir, Some(then)));
        }
    }

    /// After every group has run (or been skipped): the dump written (unless it was early),
    /// then the points passed on and put together, as [`crate::run_sweep_with`] returns them.
    /// Called once: it takes the groups' outcomes (so it needs only a shared borrow, and a
    /// queue can finish a sweep as soon as its last group has run).
    pub fn finish(&self) -> Result<SweepRun, SweepError> {
        let mut early = lock(&self.early).take();
        let mut run = SweepRun {
            lanes: std::mem::take(&mut *lock(&self.done_points)),
            ..Default::default()
        };
        let mut first_err = None;
        let mut finished: BTreeMap<usize, Vec<(Lane, LaneResult)>> = BTreeMap::new();
        for o in &self.outcomes {
            match lock(o).take() {
                None => run.cancelled = true,
                Some(Err(e)) => {
                    first_err.get_or_insert(e);
                }
                Some(Ok((pts, work, whole, probe))) => {
                    if let (Some(p), Some(dir)) = (probe, self.dump_dir) {
                        // Written early (its task ran within the caller's scope), else now.
                        let written = early
                            .take()
                            .unwrap_or_else(|| write_dump(&p, dir, self.opts.on_dump_early));
                        // The dump first, then its group's points: a failed write leaves them
                        // unsaved, so a rerun records the dump again.
                        let written = written.and_then(|w| match self.opts.on_group {
                            Some(f) => f(&by_point(&pts)).map(|_| w).map_err(SweepError::Output),
                            None => Ok(w),
                        });
                        match written {
                            Ok(w) => run.add_dump(w),
                            Err(e) => {
                                first_err.get_or_insert(e);
                                continue;
                            }
                        }
                    }
                    run.cancelled |= !whole;
                    run.point_samples += work;
                    for (l, lane) in pts {
                        finished.entry(l.point).or_default().push((l, lane));
                    }
                }
            }
        }
        // A point is computed once all its lanes are: a whole point's lane is its result, a
        // split point's segments are put together in their order.
        for (i, mut segments) in finished {
            if segments.len() == self.lanes_per_point[&i] {
                segments.sort_by_key(|(l, _)| l.segment);
                let parts: Vec<_> = segments.iter().map(|(l, r)| (l.window, *r)).collect();
                run.computed.push(i);
                run.lanes.insert(i, combine(&parts));
            }
        }
        // A dump written early for a group a cancel stopped: its files stay, listed.
        match early {
            Some(Ok(w)) => run.add_dump(w),
            Some(Err(e)) => {
                first_err.get_or_insert(e);
            }
            None => {}
        }
        if let Some(e) = first_err {
            return Err(e);
        }
        run.computed.sort_unstable();
        Ok(run)
    }
}

/// Runs the whole sweep and reads it out. `dump_dir` receives the probe's files when the
/// config asks for a dump.
pub fn run_sweep(
    cfg: &Config,
    progress: Progress,
    dump_dir: Option<&Path>,
) -> Result<SweepResult, SweepError> {
    let run = run_sweep_with(cfg, progress, dump_dir, SweepOptions::default())?;
    finish_sweep(cfg, &run.lanes)
}

/// Runs the points of a sweep that `opts` assigns and that are not done yet, in lane groups
/// of four or eight ([`group_sizes`]: cut by the lanes' runs when sized for one thread),
/// groups in parallel; long points split into segments when
/// [`SweepOptions::split`] asks and the sweep can be ([`crate::split`]). A group runs as long
/// as its longest window, so the points are packed by window length (longest first, index
/// order among equals) and a short window does not idle a lane beside a long one. Each point
/// draws the noise stream of its index, and lanes do not interact, so any subset or grouping
/// gives every point the same bits.
pub fn run_sweep_with(
    cfg: &Config,
    progress: Progress,
    dump_dir: Option<&Path>,
    opts: SweepOptions,
) -> Result<SweepRun, SweepError> {
    let sweep = PreparedSweep::new(cfg, progress, dump_dir, opts)?;
    rayon::in_place_scope(|scope| {
        let sweep = &sweep;
        let hand_on = |p: &Probe| {
            let p = p.clone();
            scope.spawn(move |_| sweep.write_early_dump(&p));
        };
        (0..sweep.groups())
            .into_par_iter()
            // A group per task, so a thread freed by other work can take any group not started.
            .with_max_len(1)
            .for_each(|g| sweep.run_group(g, &hand_on));
    });
    sweep.finish()
}

/// A group's finished lanes by point index (lanes of whole points only: a split sweep has no
/// per-group callback).
fn by_point(pts: &[(Lane, LaneResult)]) -> Vec<(usize, LaneResult)> {
    pts.iter().map(|(l, r)| (l.point, *r)).collect()
}
