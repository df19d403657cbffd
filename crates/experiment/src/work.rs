//! What a run will cost, said before it starts: the operating-point samples it emulates and
//! an estimate of the time from the chain's throughput measured on this machine; a cap above
//! which a run needs the user's explicit consent (`--force`).

use crate::bench::chain;
use crate::lock::lock_blocks;
use crate::split::lanes_of;
use crate::sweep::canonical_work;
use gyroemu_board::Point;
use gyroemu_config::Config;
use gyroemu_core::sig3;

/// Runs above this many operating-point samples are refused unless forced: minutes of a
/// 2-core machine at the chain's rate (docs/performance.md), and far more than any figure of
/// the paper needs (the full `reproduce` is 1.3e9).
pub const MAX_POINT_SAMPLES: u64 = 100_000_000_000;

/// The size of a sweep.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Work {
    /// Operating points emulated.
    pub points: usize,
    /// Operating-point samples emulated (input samples times points per lane group).
    pub point_samples: u64,
    /// The longest point's run (settling plus averaging), s.
    pub longest_s: f64,
    /// The longest point's run in input samples: one lane group runs them in sequence on one
    /// thread, however many threads there are.
    pub longest_samples: u64,
    /// The widest lane group any of the work may run in on this CPU (4 or 8: the chain's
    /// [`gyroemu_board::max_lanes_for`]): an upper bound, as the plan says it ("lane groups of
    /// up to ..."), for the lanes beside the longest point.
    pub widest_lanes: usize,
    /// Input samples of the carrier locks (`[pll]`) run before the points: each one point on
    /// one thread, in sequence with the sweep. Counted against the cap and in the time, apart
    /// from `point_samples` (what the sweeps emulate).
    pub lock_samples: u64,
}

impl Work {
    /// Two pieces of work done one after the other (sums saturate: a lot of huge devices
    /// must stay above the cap, not wrap below it).
    pub fn plus(self, o: Work) -> Work {
        Work {
            points: self.points.saturating_add(o.points),
            point_samples: self.point_samples.saturating_add(o.point_samples),
            longest_s: self.longest_s.max(o.longest_s),
            longest_samples: self.longest_samples.max(o.longest_samples),
            widest_lanes: self.widest_lanes.max(o.widest_lanes),
            lock_samples: self.lock_samples.saturating_add(o.lock_samples),
        }
    }

    /// What the cap weighs: the points' samples and the locks' (saturating).
    pub fn capped_samples(&self) -> u64 {
        self.point_samples.saturating_add(self.lock_samples)
    }

    /// One line for the user: `plan: ` and the [`summary`](Self::summary).
    pub fn describe(&self, point_samples_per_s: Option<f64>) -> String {
        self.describe_at(point_samples_per_s, None)
    }

    /// [`describe`](Self::describe) with the carrier lock's own rate ([`summary_at`](Self::summary_at)).
    pub fn describe_at(&self, point_samples_per_s: Option<f64>, lock_per_s: Option<f64>) -> String {
        format!("plan: {}", self.summary_at(point_samples_per_s, lock_per_s))
    }

    /// [`summary_at`](Self::summary_at) without a measured lock rate.
    pub fn summary(&self, point_samples_per_s: Option<f64>) -> String {
        self.summary_at(point_samples_per_s, None)
    }

    /// The points, their point-samples and, given a throughput on every thread, the time it
    /// should take: the point-samples at that throughput, or, when longer, the longest point's
    /// lane group alone on one thread (a point's samples run in sequence, so more threads do
    /// not shorten it), after the carrier locks at `lock_per_s` input samples/s (one thread;
    /// [`measured_lock_rate`]), or when that is not given at a lane's share of a lane group's
    /// rate (an upper bound: the lock's one-lane board ran 4 times faster on an AMD Zen 4).
    pub fn summary_at(&self, point_samples_per_s: Option<f64>, lock_per_s: Option<f64>) -> String {
        if self.points == 0 {
            // A shard with no point: no longest point, no time to estimate.
            return "no operating point to run".into();
        }
        let time = point_samples_per_s.map_or(String::new(), |r| {
            let lanes = self.widest_lanes.max(1);
            let even = self.point_samples as f64 / r;
            let per_thread = r / rayon::current_num_threads() as f64;
            // One lane alone runs at most a group's rate per lane: the longest point's group,
            // and the locks, which run one point before the sweep.
            let lone_lane = per_thread / lanes as f64;
            let longest = self.longest_samples as f64 / lone_lane;
            let lock = self.lock_samples as f64 / lock_per_s.unwrap_or(lone_lane);
            let bound = if longest > even {
                format!("; its longest lane group alone takes about {longest:.3} s on one thread")
            } else {
                String::new()
            };
            let lock_note = if self.lock_samples > 0 {
                format!(", the carrier lock first about {lock:.3} s of it on one thread")
            } else {
                String::new()
            };
            format!(
                ", about {:.3} s at the {} M point-samples/s measured here (lane groups of up to {lanes}{bound}{lock_note})",
                lock + even.max(longest),
                sig3(r / 1e6),
            )
        });
        let lock = if self.lock_samples > 0 {
            format!(
                ", after a carrier lock of {:.3e} input samples",
                self.lock_samples as f64
            )
        } else {
            String::new()
        };
        format!(
            "{} operating point{}, {:.3e} point-samples (longest point {:.4} s of signal){lock}{time}",
            self.points,
            if self.points == 1 { "" } else { "s" },
            self.point_samples as f64,
            self.longest_s
        )
    }

    /// Refuses work above [`MAX_POINT_SAMPLES`] unless `force`, with what to do.
    pub fn check_cap(&self, force: bool) -> Result<(), String> {
        self.check_cap_with(
            force,
            if self.lock_samples > self.point_samples {
                "shorten pll.lock_s (the loop locks within tens of its time constants; the default is 16 mechanical time constants plus 10 of the loop's)"
            } else {
                "shorten experiment.average_s or experiment.settle_s (the default settling is 16 mechanical time constants Q/(pi f0))"
            },
        )
    }

    /// [`Work::check_cap`] with the keys that size this work named in `remedy`.
    pub fn check_cap_with(&self, force: bool, remedy: &str) -> Result<(), String> {
        if force || self.capped_samples() <= MAX_POINT_SAMPLES {
            return Ok(());
        }
        // With a lock the cap weighs two kinds of samples: say so, and give their sum.
        let what = if self.lock_samples > 0 {
            format!(
                "samples ({:.3e}: the point-samples and the carrier lock's input samples together)",
                self.capped_samples() as f64
            )
        } else {
            "point-samples".to_string()
        };
        Err(format!(
            "{}: above the cap of {:.0e} {what} without --force (a mistyped Q or averaging time would otherwise start a run of days); {remedy}, or add --force to run it anyway",
            self.describe(None),
            MAX_POINT_SAMPLES as f64
        ))
    }
}

/// The carrier lock a run of `cfg` does before its points (`[pll]`, for `pll.lock_s`): its
/// input samples alone; nothing without a `[pll]`. A sweep's own work does not include it:
/// who locks adds it (once per lock run).
pub fn lock_work(cfg: &Config) -> Work {
    let lock_samples = match (&cfg.pll, cfg.pll_lock_s()) {
        (Some(_), Some(t)) => {
            lock_blocks(t, cfg.fs_out_hz()).saturating_mul(cfg.decimation() as u64)
        }
        _ => 0,
    };
    Work {
        lock_samples,
        ..Work::default()
    }
}

/// The work of `cfg`'s sweep.
pub fn sweep_work(cfg: &Config) -> Work {
    let n = cfg.emulated_rates_dps().len();
    points_work(cfg, &(0..n).collect::<Vec<_>>())
}

/// [`sweep_work`] of a split sweep ([`crate::split`]; `dump_end_s`: where its dump ends, s
/// from the start of a run): its longest lane group runs its longest segment.
pub fn split_work(cfg: &Config, dump_end_s: Option<f64>) -> Work {
    let rates = cfg.emulated_rates_dps();
    let todo: Vec<usize> = (0..rates.len()).collect();
    let (lanes, _) = lanes_of(cfg, &todo, &|i| cfg.plan_point(rates[i]), true, dump_end_s);
    let longest = lanes.iter().map(|l| l.window.samples()).max().unwrap_or(1);
    Work {
        longest_samples: (cfg.n_settle_out() + longest) * cfg.decimation() as u64,
        ..sweep_work(cfg)
    }
}

/// The work of the points `indices` of `cfg`'s sweep (a shard's, or those a resumed run has
/// left to run), grouped as [`sweep_work`] groups the whole sweep. Indices past the sweep are
/// ignored.
pub fn points_work(cfg: &Config, indices: &[usize]) -> Work {
    let rates = cfg.emulated_rates_dps();
    let points: Vec<Point> = indices
        .iter()
        .filter_map(|&i| rates.get(i))
        .map(|&r| cfg.plan_point(r))
        .collect();
    let (_, point_samples) = canonical_work(cfg, &points);
    let longest = points.iter().map(|p| p.window.samples()).max().unwrap_or(1);
    Work {
        points: points.len(),
        point_samples,
        longest_s: (cfg.n_settle_out() + longest) as f64 / cfg.fs_out_hz(),
        longest_samples: (cfg.n_settle_out() + longest) * cfg.decimation() as u64,
        widest_lanes: gyroemu_board::max_lanes_for(&cfg.board_params()),
        lock_samples: 0,
    }
}

/// The carrier lock's rate on this machine (input samples/s, one thread) for `cfg`'s `[pll]`,
/// from short timed lock runs (about 2^16 input samples, best of three); `None` without a
/// `[pll]` or where its loop cannot be built (validation says why).
pub fn measured_lock_rate(cfg: &Config) -> Option<f64> {
    let m = cfg.decimation() as u64;
    let blocks = ((1u64 << 16) / m).max(8);
    let mut short = cfg.clone();
    short.pll.as_mut()?.lock_s = Some(blocks as f64 / cfg.fs_out_hz());
    let samples = lock_blocks(short.pll_lock_s()?, cfg.fs_out_hz()) * m;
    (0..3)
        .map(|_| {
            let t = std::time::Instant::now();
            // Whether so short a run locks does not matter here, only its time.
            let built = !matches!(
                crate::lock::lock_config_carrier(&short, &short),
                Err(crate::SweepError::Param(_) | crate::SweepError::Config(_))
            );
            built.then(|| samples as f64 / t.elapsed().as_secs_f64())
        })
        .try_fold(0.0, |best: f64, r| r.map(|r| best.max(r)))
}

/// The chain's throughput on this machine and config, point-samples/s on every thread, from a
/// short timed run (about 2^17 input samples per thread: two milliseconds in eight lanes; the
/// three runs were 0.8 % of a `reproduce` at 2^18, whose runs measured the same rate).
pub fn measured_throughput(cfg: &Config) -> f64 {
    let m = cfg.decimation() as u64;
    let n_in = (1u64 << 17).max(8 * m);
    // Best of three: the first run pays for page faults and the vector units' wake-up
    // (a single short run read half the throughput now and then).
    (0..3)
        .map(|_| chain(cfg, n_in, rayon::current_num_threads()))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_of_work_saturate_above_the_cap_instead_of_wrapping_below_it() {
        let huge = Work {
            points: usize::MAX - 1,
            point_samples: u64::MAX - 1,
            longest_s: 1.0,
            longest_samples: 10,
            widest_lanes: 8,
            lock_samples: u64::MAX - 1,
        };
        let w = huge.plus(huge);
        assert_eq!((w.points, w.point_samples), (usize::MAX, u64::MAX));
        assert_eq!((w.lock_samples, w.capped_samples()), (u64::MAX, u64::MAX));
        assert!(w.check_cap(false).is_err());
        assert!(w.check_cap(true).is_ok());
        // Each command names the keys that size its own work.
        let e = w.check_cap_with(false, "lower sweep.points").unwrap_err();
        assert!(e.contains("; lower sweep.points, or add --force"), "{e}");
        assert!(!e.contains("experiment.average_s"), "{e}");
    }

    #[test]
    fn the_plan_states_the_widest_lanes_of_all_its_work() {
        let w = |widest_lanes| Work {
            points: 8,
            point_samples: 80,
            longest_s: 1.0,
            longest_samples: 20,
            widest_lanes,
            lock_samples: 0,
        };
        assert_eq!(w(4).plus(w(8)).widest_lanes, 8);
        assert_eq!(w(8).plus(w(4)).widest_lanes, 8);
        assert_eq!(w(4).plus(w(4)).widest_lanes, 4);
        // The time bound: 20 samples in groups of up to 4 lanes at 4 point-samples/s per
        // thread take 20 s on one thread, above the 8 / (4 * threads) s of an even spread.
        let t = rayon::current_num_threads() as f64;
        let s = w(4).summary(Some(4.0 * t));
        assert!(s.contains("lane groups of up to 4"), "{s}");
        assert!(s.contains("about 20.000 s"), "{s}");
        // The measured rate keeps three figures however slow the CPU (an emulated one's
        // 0.345 M point-samples/s once read as `0 M`).
        let slow = w(4).summary(Some(345_000.0));
        assert!(slow.contains("at the 0.345 M point-samples/s"), "{slow}");
        let fast = w(8).summary(Some(1_173.3e6));
        assert!(fast.contains("at the 1173 M point-samples/s"), "{fast}");
    }

    #[test]
    fn the_cap_weighs_the_lock_beside_the_points() {
        let w = |point_samples, lock_samples| Work {
            points: 1,
            point_samples,
            longest_s: 1.0,
            longest_samples: 1,
            widest_lanes: 4,
            lock_samples,
        };
        let half = MAX_POINT_SAMPLES / 2 + 1;
        // Each half below the cap, their sum above it.
        assert!(w(half, 0).check_cap(false).is_ok());
        assert!(w(0, half).check_cap(false).is_ok());
        let e = w(half, half).check_cap(false).unwrap_err();
        assert!(e.contains("experiment.average_s"), "{e}");
        // What it weighs is said as such, with the sum the cap compared (1.000e11 + 2).
        assert!(
            e.contains("above the cap of 1e11 samples (1.000e11: the point-samples and the carrier lock's input samples together)"),
            "{e}"
        );
        // Without a lock the cap counts point-samples alone, and says only that.
        let e = w(2 * half, 0).check_cap(false).unwrap_err();
        assert!(
            e.contains("above the cap of 1e11 point-samples without"),
            "{e}"
        );
        // The lock the larger part: its key is the one named.
        let e = w(1, 2 * half).check_cap(false).unwrap_err();
        assert!(e.contains("shorten pll.lock_s"), "{e}");
        assert!(!e.contains("experiment.average_s"), "{e}");
        // Without a measured lock rate the lock is timed at a lane's share of a group (the
        // upper bound): 8 samples at 4 point-samples/s per thread in groups of 4.
        let t = rayon::current_num_threads() as f64;
        let s = w(0, 8).summary(Some(4.0 * t));
        assert!(s.contains("the carrier lock first about 8.000 s"), "{s}");
    }
}
