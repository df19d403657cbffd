//! A sweep over operating points: what it is asked (`SweepOptions`), what it returns
//! (`SweepRun`) and how its lane results are read out (`finish_sweep`). `prepared.rs` runs it:
//! the board sample by sample, four or eight points per SIMD lane group (eight on a CPU with
//! AVX-512), groups in parallel; any subset (a shard, a resumed run) gives every point the
//! bits of a whole run. `readout.rs` turns the averages into phases.

use crate::dump::DumpPlan;
use crate::leaks::Stage2Leaks;
use crate::progress::{Progress, Written};
use crate::readout::{post_process_with, SweepResult};
use gyroemu_board::{LaneResult, NonFinite, Point, Probe, CANONICAL_LANES};
use gyroemu_config::Config;
use gyroemu_core::ParamError;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Why a sweep failed after validation.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// A config derived from the user's (a sweep of an analysis) is refused.
    #[error(transparent)]
    Config(#[from] gyroemu_config::ConfigError),
    /// A stage refused a parameter.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// Writing an output (a dump, a point file) failed.
    #[error("writing the outputs failed: {0}")]
    Output(String),
    /// The chain overflowed.
    #[error(transparent)]
    NonFinite(#[from] NonFinite),
    /// Points without a result (indices in `emulated_rates_dps`).
    #[error("the sweep is missing the results of points {0:?}")]
    Missing(Vec<usize>),
    /// The carrier PLL did not lock (the sweep would run at a carrier still moving): what it
    /// did, and what would help (which depends on who asked for the lock).
    #[error("{cause}; {advice}")]
    NotLocked { cause: String, advice: String },
    /// The cancel flag (Ctrl-C, SIGTERM) stopped the carrier lock before the sweep began.
    #[error("stopped during the carrier lock, before any point ran")]
    Cancelled,
}

/// The file stem of a sweep's signal dump in its output folder (see [`Probe::write`]).
pub const DUMP_STEM: &str = "dump";

/// The index (in `emulated_rates_dps`) of the point the config's `[dump]` records, if any.
pub fn dump_point(cfg: &Config) -> Option<usize> {
    let d = cfg.dump_resolved()?;
    let rate = d.rate_dps.unwrap_or(f64::NAN);
    let rates = cfg.emulated_rates_dps();
    Some(rates.iter().position(|&r| r == rate).unwrap_or(0))
}

/// Called with each finished lane group's points, `(index in emulated_rates_dps, lane
/// result)`, and with the finished points of a group a cancel stopped: from the worker
/// threads, except for the group that records the dump, whose dump is written (while the
/// groups run, with [`SweepOptions::on_dump_early`]) and points passed after every group has
/// run (so the write is timed apart from the emulation, and a group's points are never saved
/// without its dump). An error stops the sweep (groups not started are skipped) and is
/// returned.
pub type OnGroup<'a> = &'a (dyn Fn(&[(usize, LaneResult)]) -> Result<(), String> + Sync);

/// Called with a dump's files once they are written (see [`SweepOptions::on_dump_early`]);
/// returns the files it made from them.
pub type OnDump<'a> = &'a (dyn Fn(&[PathBuf]) -> Result<Vec<PathBuf>, String> + Sync);

/// What [`run_sweep_with`](crate::run_sweep_with) runs and what it does with the points it finishes.
#[derive(Default)]
pub struct SweepOptions<'a> {
    /// Points already computed (by index): not run again (a resumed sweep).
    pub done: BTreeMap<usize, LaneResult>,
    /// The point indices this run is responsible for (a shard); `None`: all.
    pub only: Option<Vec<usize>>,
    /// Raised (Ctrl-C): groups not started are skipped, running ones stop within about
    /// 65 536 samples; of a stopped group, the points whose own window had ended are kept
    /// (and passed to `on_group`), the others are left out.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Receives each finished group (e.g. to write its point files).
    pub on_group: Option<OnGroup<'a>>,
    /// The dump to record instead of the config's `[dump]` (if any); written into the
    /// `dump_dir` given to [`run_sweep_with`](crate::run_sweep_with).
    pub dump: Option<DumpPlan>,
    /// The threads the lane groups are sized for; `None`: the pool's. A caller whose pool
    /// runs other work beside this sweep (reproduce runs every experiment in one pool) gives
    /// 1: each group is then as wide as the CPU runs (most points per CPU-second), and the
    /// other work keeps the remaining threads busy.
    pub group_threads: Option<usize>,
    /// Writes the dump as soon as its windows are recorded, in a task a thread left idle by
    /// the lane groups takes, instead of after every group has run; then calls this in that
    /// task with its files; the files it returns (made from the dump, e.g. its figures) are
    /// listed in `dump_made`. Its group's points are still passed to `on_group`
    /// only after the dump is written. `reproduce` gives it: its longest group then no longer
    /// waits on its dump at the end.
    pub on_dump_early: Option<OnDump<'a>>,
    /// Cuts each long point's window into segments that run as lanes of their own, each
    /// settling anew ([`crate::split`]: the cut depends on the config alone, and only sweeps
    /// that can be split are), so that one long point does not keep a run on one thread. Taken
    /// only by a whole run: with `done`, `only`, `cancel` or `on_group` (point by point
    /// results) the points run whole.
    pub split: bool,
}

/// The points a [`run_sweep_with`](crate::run_sweep_with) call has, and whether it was cancelled.
#[derive(Clone, Debug, Default)]
pub struct SweepRun {
    /// Every point available: the given `done` plus those computed now, by index.
    pub lanes: BTreeMap<usize, LaneResult>,
    /// Indices computed by this call, ascending.
    pub computed: Vec<usize>,
    /// The cancel flag stopped the run before every point it was given finished.
    pub cancelled: bool,
    /// Operating-point samples emulated by the groups that finished.
    pub point_samples: u64,
    /// The dump files written (`dump_fullrate.*`, `dump_decimated.*`), if any.
    pub dump_files: Vec<PathBuf>,
    /// Their total size, bytes.
    pub dump_bytes: u64,
    /// The files `on_dump_early` made from them.
    pub dump_made: Vec<PathBuf>,
    /// What the dump could not write (a WAV copy that would lose samples), for the user.
    pub dump_notes: Vec<String>,
    /// Wall time spent writing them, s (after the emulation, not part of its time, unless
    /// written early).
    pub dump_write_s: f64,
}

impl SweepRun {
    /// Lists a dump written.
    pub(crate) fn add_dump(&mut self, w: DumpWritten) {
        self.dump_bytes += w.bytes;
        self.dump_write_s += w.seconds;
        self.dump_files.extend(w.files);
        self.dump_made.extend(w.made);
        self.dump_notes.extend(w.notes);
    }

    /// The dump written, for a progress line.
    pub fn written(&self) -> Written {
        Written {
            files: self.dump_files.len(),
            bytes: self.dump_bytes,
            seconds: self.dump_write_s,
        }
    }
}

/// Input samples a lane group of `points` runs: settling plus its longest window.
pub fn group_samples(cfg: &Config, points: &[Point]) -> u64 {
    let m = cfg.decimation() as u64;
    (cfg.n_settle_out() + points.iter().map(|p| p.window.samples()).max().unwrap_or(1)) * m
}

/// The canonical lane grouping of a sweep (all points in index order, four per group) and
/// its work: (input samples per lane group summed, operating-point samples). Reported in the
/// results, so they are the same whichever subset, order, shard or lane width actually ran
/// the points.
pub fn canonical_work(cfg: &Config, points: &[Point]) -> (u64, u64) {
    points.chunks(CANONICAL_LANES).fold((0, 0), |(s, ps), g| {
        let n = group_samples(cfg, g);
        (s + n, ps + n * g.len() as u64)
    })
}

/// A lane group reports the input samples it has done (`n`, its own count): adds the increase
/// since its previous report (`last`) to the count shared by all groups (`done`) and reports
/// that against `total`.
pub fn add_group_progress(
    done: &AtomicU64,
    last: &AtomicU64,
    n: u64,
    total: u64,
    progress: Progress,
) {
    let prev = last.swap(n, Ordering::Relaxed);
    let all = done.fetch_add(n - prev, Ordering::Relaxed) + n - prev;
    progress(all, total);
}

/// A dump written, and the files made from it.
pub(crate) struct DumpWritten {
    files: Vec<PathBuf>,
    made: Vec<PathBuf>,
    notes: Vec<String>,
    bytes: u64,
    seconds: f64,
}

/// Writes `p` into `dir`, then runs `then` on its files.
pub(crate) fn write_dump(
    p: &Probe,
    dir: &Path,
    then: Option<OnDump>,
) -> Result<DumpWritten, SweepError> {
    let t = Instant::now();
    let files = p
        .write(dir, DUMP_STEM)
        .map_err(|e| SweepError::Output(e.to_string()))?;
    let seconds = t.elapsed().as_secs_f64();
    let bytes = files
        .iter()
        .filter_map(|f| std::fs::metadata(f).ok())
        .map(|m| m.len())
        .sum::<u64>();
    let made = match then {
        Some(then) => then(&files).map_err(SweepError::Output)?,
        None => Vec::new(),
    };
    Ok(DumpWritten {
        files,
        made,
        notes: p.wav_notes(),
        bytes,
        seconds,
    })
}

/// Turns the lane results of every point of a sweep (by index in `emulated_rates_dps`) into
/// the sweep's result, the same bits whichever runs computed them.
pub fn finish_sweep(
    cfg: &Config,
    lanes: &BTreeMap<usize, LaneResult>,
) -> Result<SweepResult, SweepError> {
    finish_sweep_with(cfg, lanes, &Stage2Leaks::default())
}

/// [`finish_sweep`] with stage-2 leaks computed beforehand (see [`Stage2Leaks`]): the same
/// result, without waiting on the leaks it holds.
pub fn finish_sweep_with(
    cfg: &Config,
    lanes: &BTreeMap<usize, LaneResult>,
    leaks: &Stage2Leaks,
) -> Result<SweepResult, SweepError> {
    let rates = cfg.emulated_rates_dps();
    let missing: Vec<usize> = (0..rates.len())
        .filter(|i| !lanes.contains_key(i))
        .collect();
    if !missing.is_empty() {
        return Err(SweepError::Missing(missing));
    }
    let points: Vec<Point> = rates.iter().map(|&r| cfg.plan_point(r)).collect();
    let lane_results: Vec<LaneResult> = (0..rates.len()).map(|i| lanes[&i]).collect();
    let (samples, point_samples) = canonical_work(cfg, &points);
    let res = post_process_with(cfg, &rates, &points, &lane_results, leaks)?;
    Ok(SweepResult {
        settle_s: cfg.settle_s(),
        fs_hz: cfg.fs_hz(),
        fs_out_hz: cfg.fs_out_hz(),
        samples,
        point_samples,
        ..res
    })
}

#[cfg(test)]
mod resume_tests {
    use super::*;
    use crate::prepared::{run_sweep, run_sweep_with};
    use std::sync::Mutex;

    fn small() -> Config {
        let mut cfg = gyroemu_config::presets::preset("m2tfg-coriolis").unwrap();
        cfg.experiment.average_s = 0.1;
        cfg.experiment.settle_s = Some(0.02);
        cfg.experiment.rates_dps = vec![25.0, 50.0, 75.0, 100.0, 125.0, 150.0];
        cfg
    }

    #[test]
    fn subsets_in_any_grouping_give_the_whole_sweeps_bits() {
        let cfg = small();
        let whole = run_sweep(&cfg, &|_, _| {}, None).unwrap();
        let n = cfg.emulated_rates_dps().len();
        // Odd points first (other lane groups than the whole run's), then the rest resumed.
        let seen = Mutex::new(Vec::new());
        let on_group = |pts: &[(usize, LaneResult)]| {
            seen.lock().unwrap().extend(pts.iter().map(|p| p.0));
            Ok(())
        };
        let odd = run_sweep_with(
            &cfg,
            &|_, _| {},
            None,
            SweepOptions {
                only: Some((1..n).step_by(2).collect()),
                on_group: Some(&on_group),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(!odd.cancelled);
        assert_eq!(odd.computed, (1..n).step_by(2).collect::<Vec<_>>());
        assert!(matches!(
            finish_sweep(&cfg, &odd.lanes),
            Err(SweepError::Missing(_))
        ));
        let rest = run_sweep_with(
            &cfg,
            &|_, _| {},
            None,
            SweepOptions {
                done: odd.lanes,
                on_group: Some(&on_group),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(rest.computed, (0..n).step_by(2).collect::<Vec<_>>());
        let mut s = seen.into_inner().unwrap();
        s.sort_unstable();
        assert_eq!(s, (0..n).collect::<Vec<_>>());
        assert_eq!(finish_sweep(&cfg, &rest.lanes).unwrap(), whole);
    }

    #[test]
    fn a_cancel_keeps_the_points_whose_window_ended_with_their_bits() {
        // One lane group of rotating points, windows of 0.6 to 1.03 s (whole half periods).
        let mut cfg = small();
        cfg.experiment.kind = gyroemu_config::ExperimentKind::Rotating;
        cfg.experiment.rates_dps = vec![200.0, 250.0, 300.0, 350.0];
        cfg.experiment.average_s = 1.1;
        let whole = run_sweep_with(&cfg, &|_, _| {}, None, SweepOptions::default()).unwrap();
        let m = cfg.decimation() as u64;
        let ends: Vec<u64> = cfg
            .emulated_rates_dps()
            .iter()
            .map(|&r| (cfg.n_settle_out() + cfg.plan_point(r).window.samples()) * m)
            .collect();
        // Stop once the shortest window has ended (a report comes every 65 536 samples).
        let at = ends.iter().min().unwrap() + 1000;
        assert!(at + 65_536 < *ends.iter().max().unwrap());
        let cancel = Arc::new(AtomicBool::new(false));
        let stopped_at = AtomicU64::new(0);
        let progress = |done: u64, _: u64| {
            if done >= at && !cancel.swap(true, Ordering::SeqCst) {
                stopped_at.store(done, Ordering::SeqCst);
            }
        };
        let seen = Mutex::new(Vec::new());
        let on_group = |pts: &[(usize, LaneResult)]| {
            seen.lock().unwrap().extend_from_slice(pts);
            Ok(())
        };
        let cut = run_sweep_with(
            &cfg,
            &progress,
            None,
            SweepOptions {
                cancel: Some(cancel.clone()),
                on_group: Some(&on_group),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(cut.cancelled);
        // The stop's block is not averaged: a window ending by its start is complete.
        let stop = stopped_at.load(Ordering::SeqCst) - m;
        let expect: Vec<usize> = (0..ends.len()).filter(|&i| ends[i] <= stop).collect();
        assert!(
            !expect.is_empty() && expect.len() < ends.len(),
            "{expect:?}"
        );
        assert_eq!(cut.computed, expect);
        let seen = seen.into_inner().unwrap();
        assert_eq!(seen.iter().map(|p| p.0).collect::<Vec<_>>(), expect);
        for (i, lane) in seen {
            assert_eq!(lane, whole.lanes[&i], "point {i}");
            assert_eq!(cut.lanes[&i], whole.lanes[&i]);
        }
    }

    #[test]
    fn a_raised_cancel_flag_runs_nothing() {
        let cfg = small();
        let run = run_sweep_with(
            &cfg,
            &|_, _| {},
            None,
            SweepOptions {
                cancel: Some(Arc::new(AtomicBool::new(true))),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(run.cancelled && run.lanes.is_empty() && run.computed.is_empty());
    }

    #[test]
    fn a_failing_point_writer_stops_the_sweep_with_its_error() {
        let cfg = small();
        let fail = |_: &[(usize, LaneResult)]| Err("disk full".to_string());
        let r = run_sweep_with(
            &cfg,
            &|_, _| {},
            None,
            SweepOptions {
                on_group: Some(&fail),
                ..Default::default()
            },
        );
        assert!(matches!(r, Err(SweepError::Output(e)) if e == "disk full"));
    }

    #[test]
    fn a_dump_only_records_and_is_listed_with_its_size() {
        let cfg = small();
        let whole = run_sweep(&cfg, &|_, _| {}, None).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let plan = DumpPlan {
            rate_dps: 75.0,
            start_s: 0.03,
            duration_s: 0.001,
            decimated_duration_s: 0.05,
            nodes: gyroemu_board::DUMP_NODES.map(String::from).to_vec(),
        };
        let saved = Mutex::new(Vec::new());
        let on_group = |pts: &[(usize, LaneResult)]| {
            // The dump group's points come after its dump is on disk.
            let dumped = dir.path().join("dump_fullrate.sigmf-meta").exists();
            saved
                .lock()
                .unwrap()
                .extend(pts.iter().map(|p| (p.0, dumped)));
            Ok(())
        };
        let run = run_sweep_with(
            &cfg,
            &|_, _| {},
            Some(dir.path()),
            SweepOptions {
                dump: Some(plan),
                on_group: Some(&on_group),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(finish_sweep(&cfg, &run.lanes).unwrap(), whole);
        let names: Vec<String> = run
            .dump_files
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        for stem in ["dump_fullrate", "dump_decimated"] {
            for ext in ["csv", "wav", "sigmf-data", "sigmf-meta"] {
                assert!(names.contains(&format!("{stem}.{ext}")), "{names:?}");
            }
        }
        let on_disk: u64 = run
            .dump_files
            .iter()
            .map(|p| std::fs::metadata(p).unwrap().len())
            .sum();
        assert_eq!(run.dump_bytes, on_disk);
        assert_eq!(run.written().files, 8);
        // 75 deg/s is point 2 of the first lane group: saved after the dump was written.
        let saved = saved.into_inner().unwrap();
        assert!(saved.iter().any(|&(i, dumped)| i == 2 && dumped));
        // Windows: 1 ms at the full rate, 50 ms decimated (0.05 fs_out frames).
        let full = gyroemu_io::read_dump(&dir.path().join("dump_fullrate")).unwrap();
        let dec = gyroemu_io::read_dump(&dir.path().join("dump_decimated")).unwrap();
        assert_eq!(full.frames(), (0.001 * cfg.fs_hz()).round() as usize);
        assert_eq!(dec.frames(), (0.05 * cfg.fs_out_hz()).round() as usize);
        assert_eq!(full.extra["f0_hz"], cfg.device.f0_hz);
        assert_eq!(full.extra["rate_dps"], 75.0);
        assert_eq!(dec.extra["decimation"], cfg.decimation() as f64);
    }
}
