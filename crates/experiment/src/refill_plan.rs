//! Lane groups whose lanes run points back to back (`Board::run_refilled`): a lane whose
//! point has ended takes the next at the first block where a refill keeps the bits, so
//! points of unequal lengths share groups without idle lanes, each settling once. The cut of
//! long points into segments is chosen for that packing; like every cut, it depends on the
//! configs alone, while the packing (which lane runs what, when) may depend on the machine,
//! which changes no bit.

use crate::split::{cut_each, cut_targets, even_cut, gcd, Packing};
use gyroemu_board::{starts_share_carrier, BoardParams};

/// Input samples between the oscillators' exact re-sets, where a lane may be refilled.
const RESYNC: u64 = gyroemu_nco::RESYNC as u64;

/// Decimation blocks between the blocks where a lane of `p`'s board may take another point:
/// the fewest whose input samples are a whole number of the oscillators' re-set intervals and
/// of the carrier's repeat (so a point refilled there sees the carrier's phase its start gives
/// it), or `None` where the carrier repeats only after more than 2^20 such steps (a detuned
/// carrier: refill would not keep the bits).
pub fn refill_grain(p: &BoardParams) -> Option<u64> {
    let m = p.decimation.max(1) as u64;
    let base = RESYNC / gcd(m as usize, RESYNC as usize) as u64;
    (0..=20)
        .map(|e| base << e)
        .find(|&g| starts_share_carrier(p, &[0, g * m]))
}

/// One lane group of refilled lanes: per lane, its jobs in order, each with the block it
/// starts at (the first at 0).
pub type RefilledGroup = Vec<Vec<(usize, u64)>>;

/// Packs jobs of `runs[j]` blocks each (settling included) into `lanes` lanes, longest job
/// first onto the lane that can start it soonest (a lane's next job starts at the first
/// multiple of `grain` at or after its last job's end); the lanes, longest first, then make
/// groups of `width`. Returns the groups and the lane-blocks they run (each group its width
/// times its longest lane, idle lanes included).
fn pack_into(runs: &[u64], lanes: usize, width: usize, grain: u64) -> (Vec<RefilledGroup>, u64) {
    let mut order: Vec<usize> = (0..runs.len()).collect();
    order.sort_by_key(|&j| (core::cmp::Reverse(runs[j]), j));
    // Per lane: its jobs and where it ends.
    let mut lane_jobs: Vec<(Vec<(usize, u64)>, u64)> = vec![(Vec::new(), 0); lanes.max(1)];
    for j in order {
        let next = |l: &(Vec<(usize, u64)>, u64)| {
            if l.0.is_empty() {
                0
            } else {
                l.1.next_multiple_of(grain.max(1))
            }
        };
        let (best, _) = lane_jobs
            .iter()
            .enumerate()
            .min_by_key(|(i, l)| (next(l), *i))
            .expect("at least one lane");
        let lane = &mut lane_jobs[best];
        let at = next(lane);
        lane.0.push((j, at));
        lane.1 = at + runs[j];
    }
    lane_jobs.retain(|l| !l.0.is_empty());
    lane_jobs.sort_by_key(|l| core::cmp::Reverse(l.1));
    let mut cost = 0;
    let groups = lane_jobs
        .chunks(width.max(1))
        .map(|g| {
            cost += width as u64 * g[0].1;
            g.iter().map(|l| l.0.clone()).collect()
        })
        .collect();
    (groups, cost)
}

/// The packing of jobs of `runs[j]` blocks into groups of `width` refilled lanes that runs
/// the fewest lane-blocks (`pack_into` for every number of groups up to one job a lane; of
/// equal costs, the more groups), with its cost.
pub fn pack_refilled(runs: &[u64], width: usize, grain: u64) -> (Vec<RefilledGroup>, u64) {
    let width = width.max(1);
    let most = runs.len().div_ceil(width).max(1);
    (1..=most)
        .map(|g| pack_into(runs, g * width, width, grain))
        .reduce(|best, next| if next.1 <= best.1 { next } else { best })
        .expect("at least one number of groups")
}

/// Per point, the segment length (decimated samples) of the cut of points of boxcar windows
/// `windows` (decimated samples and fractional end; all settling `n_settle`) whose segments,
/// packed into refilled groups of eight lanes ([`pack_refilled`]), run the fewest
/// lane-samples, with that count. The cuts weighed are [`crate::split::cut_to_fill`]'s (each
/// point in the fewest even segments within a common length, for every length a point's even
/// cut gives, as it is and rounded by `segment`) and the whole points; `segment` rounds a
/// length up to one whose segments share the carrier's phase at their starts ([`Packing::Free`];
/// a cut whose segments do not is not weighed). The same cut on every machine.
pub fn cut_to_refill(
    windows: &[(u64, f64)],
    n_settle: u64,
    grain: u64,
    segment: &dyn Fn(u64) -> (u64, Packing),
) -> (Vec<u64>, u64) {
    let whole: Vec<u64> = windows.iter().map(|w| w.0.max(1)).collect();
    let runs_of = |lens: &[u64]| -> Vec<u64> {
        let todo: Vec<usize> = (0..windows.len()).collect();
        cut_each(&todo, windows, lens)
            .iter()
            .map(|l| n_settle + l.window.samples())
            .collect()
    };
    let cost = |runs: &[u64]| (pack_refilled(runs, 8, grain).1, runs.len());
    let mut best = (cost(&runs_of(&whole)), whole);
    // From the longest common length down: a shorter one cuts more segments, each settling,
    // so the lane-blocks the segments themselves run only grow, and once they reach the best
    // packing's, no packing of a finer cut can beat it (the weighing stays a few
    // milliseconds where every cut's packing took twelve).
    for t in cut_targets(windows, segment).into_iter().rev() {
        let Some(lens) = even_cut(windows, t, segment) else {
            continue;
        };
        let runs = runs_of(&lens);
        if runs.iter().sum::<u64>() >= best.0 .0 {
            break;
        }
        let c = cost(&runs);
        // Of equal lane-samples, the fewer segments (the less settling, the fewer other bits).
        if c < best.0 {
            best = (c, lens);
        }
    }
    (best.1, best.0 .0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_config::presets::preset;

    #[test]
    fn the_grain_is_whole_carrier_periods_and_re_sets() {
        // fs = 16 fc, decimation 100: 1600 samples, the first multiple of 64 and 16 blocks.
        let m2tfg = preset("m2tfg-rotating").unwrap().board_params();
        assert_eq!(refill_grain(&m2tfg), Some(16));
        // Decimation 1000: 8000 samples (125 re-sets, 500 carrier periods).
        let baw = preset("baw-rotating").unwrap().board_params();
        let m = baw.decimation as u64;
        let g = refill_grain(&baw).unwrap();
        assert_eq!((g * m) % 64, 0);
        assert!(starts_share_carrier(&baw, &[0, g * m]));
        assert!(
            !(1..g).any(|h| (h * m).is_multiple_of(64) && starts_share_carrier(&baw, &[0, h * m]))
        );
        // A carrier off every power-of-two fraction of fs never repeats soon enough.
        let detuned = BoardParams {
            carrier_hz: m2tfg.carrier_hz * (1.0 + 1e-7),
            ..m2tfg
        };
        assert_eq!(refill_grain(&detuned), None);
    }

    /// Every job once; in each lane back to back, a later job at a grain multiple at or after
    /// the lane's last end; the cost each group's width times its longest lane.
    fn check_packing(runs: &[u64], width: usize, grain: u64) -> u64 {
        let (groups, cost) = pack_refilled(runs, width, grain);
        let mut seen = vec![0; runs.len()];
        let mut want = 0;
        for g in &groups {
            assert!(!g.is_empty() && g.len() <= width, "{groups:?}");
            let mut longest = 0;
            for lane in g {
                let mut end = 0;
                for (k, &(j, at)) in lane.iter().enumerate() {
                    seen[j] += 1;
                    if k == 0 {
                        assert_eq!(at, 0);
                    } else {
                        assert!(at >= end && at % grain == 0, "{lane:?}");
                    }
                    end = at + runs[j];
                }
                longest = longest.max(end);
            }
            want += width as u64 * longest;
        }
        assert!(seen.iter().all(|&n| n == 1), "{seen:?}");
        assert_eq!(cost, want);
        cost
    }

    #[test]
    fn packings_run_every_job_once_back_to_back_at_the_grain() {
        // Seeded sweeps of job sets, widths and grains.
        let mut g = gyroemu_core::check::Gen::new(7);
        for _ in 0..300 {
            let n = 1 + (g.u64() % 20) as usize;
            let runs: Vec<u64> = (0..n).map(|_| 1 + g.u64() % 500).collect();
            let width = [1, 4, 8][(g.u64() % 3) as usize];
            let grain = 1 + g.u64() % 40;
            let cost = check_packing(&runs, width, grain);
            // Never worse than every job in a lane of its own (groups of the longest first).
            let mut alone = runs.clone();
            alone.sort_unstable_by(|a, b| b.cmp(a));
            let idle: u64 = alone.chunks(width).map(|c| width as u64 * c[0]).sum();
            assert!(cost <= idle, "{runs:?} in {width}: {cost} > {idle}");
        }
    }

    #[test]
    fn short_jobs_share_a_lane_where_that_runs_fewer_lane_blocks() {
        // Two lanes: 10 alone, then 4 + 4 + 4 back to back (12): one group, 24 lane-blocks,
        // where a lane each takes two groups and 2 x 10 + 2 x 4 = 28.
        let (groups, cost) = pack_refilled(&[10, 4, 4, 4], 2, 1);
        assert_eq!(cost, 24);
        assert_eq!(
            groups,
            vec![vec![vec![(1, 0), (2, 4), (3, 8)], vec![(0, 0)]]]
        );
        // A grain of 5 starts the second and third 4 at 5 and 10: 14, no better than 28 / 2.
        assert_eq!(check_packing(&[10, 4, 4, 4], 2, 5), 28);
    }

    /// `cut_to_refill` weighing every cut, with no early stop: the reference its pruned
    /// search must equal.
    fn cut_to_refill_exhaustive(
        windows: &[(u64, f64)],
        n_settle: u64,
        grain: u64,
        segment: &dyn Fn(u64) -> (u64, Packing),
    ) -> (Vec<u64>, u64) {
        let todo: Vec<usize> = (0..windows.len()).collect();
        let cost = |lens: &[u64]| {
            let runs: Vec<u64> = cut_each(&todo, windows, lens)
                .iter()
                .map(|l| n_settle + l.window.samples())
                .collect();
            (pack_refilled(&runs, 8, grain).1, runs.len())
        };
        let whole: Vec<u64> = windows.iter().map(|w| w.0.max(1)).collect();
        let mut best = (cost(&whole), whole);
        for t in cut_targets(windows, segment) {
            if let Some(lens) = even_cut(windows, t, segment) {
                let c = cost(&lens);
                if c < best.0 {
                    best = (c, lens);
                }
            }
        }
        (best.1, best.0 .0)
    }

    #[test]
    fn the_pruned_search_finds_the_exhaustive_ones_cost_and_cut() {
        let mut g = gyroemu_core::check::Gen::new(11);
        for _ in 0..60 {
            let n = 1 + (g.u64() % 9) as usize;
            let windows: Vec<(u64, f64)> = (0..n).map(|_| (1 + g.u64() % 3000, 0.0)).collect();
            let n_settle = 1 + g.u64() % 400;
            let step = 1 + g.u64() % 8;
            let segment = |len: u64| (len.div_ceil(step) * step, Packing::Free);
            let fast = cut_to_refill(&windows, n_settle, 16, &segment);
            let slow = cut_to_refill_exhaustive(&windows, n_settle, 16, &segment);
            // The same cost; of equal costs the fewest segments (the exhaustive search may
            // meet another cut of that count first).
            assert_eq!(fast.1, slow.1, "{windows:?} settling {n_settle}");
            let count = |lens: &[u64]| -> u64 {
                windows
                    .iter()
                    .zip(lens)
                    .map(|(w, &l)| w.0.div_ceil(l).max(1))
                    .sum()
            };
            assert_eq!(count(&fast.0), count(&slow.0), "{windows:?}");
        }
    }

    #[test]
    fn the_bandwidth_sweeps_cut_halves_its_longest_point() {
        // Its windows (decimated samples) and settling; segments share the carrier at
        // multiples of four blocks.
        let mut windows = vec![(96_000, 0.0), (48_000, 0.0), (24_000, 0.0), (16_000, 0.0)];
        windows.extend([(9_600, 0.0); 5]);
        let segment = |len: u64| (len.div_ceil(4) * 4, Packing::Free);
        let (lens, cost) = cut_to_refill(&windows, 29_412, 16, &segment);
        let mut want = vec![48_000, 48_000, 24_000, 16_000];
        want.extend([9_600; 5]);
        assert_eq!(lens, want);
        // One group of eight, as long as its lanes of two 4 s points: 29 412 + 9 601 blocks
        // each, the second from the grain's block 39 024 (the 20 s point's and the halves'
        // lanes: 77 413).
        assert_eq!(cost, 8 * (39_024 + 39_013));
    }
}
