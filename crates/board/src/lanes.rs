//! How wide a lane group is: eight points in `F64x8` lanes on a CPU with AVX-512, four in
//! `f64x4` lanes elsewhere (or when a process limits itself to four: `--lanes 4`, for tests and
//! benchmarks). On a CPU that runs each 512-bit operation as two 256-bit halves (AMD Zen 4),
//! eight lanes gain on some chains and lose on others, so there the width is chosen per chain
//! ([`max_lanes_for`]). Each lane is its own point, so no result depends on the width or the
//! grouping; the width is a speed choice made at run time.

use crate::params::BoardParams;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The widest lane group (`F64x8`).
pub const MAX_LANES: usize = 8;

/// The lane group of the canonical grouping that results report (the work of a sweep, in
/// `canonical_work`), the same on every CPU whatever width actually ran.
pub const CANONICAL_LANES: usize = 4;

/// `--lanes` not given: the width is chosen per chain ([`max_lanes_for`]).
const AUTO: usize = 0;

/// The widest group this process may use ([`set_max_lanes`]): [`AUTO`], 4 or 8.
static LIMIT: AtomicUsize = AtomicUsize::new(AUTO);

/// The CPU runs eight-lane groups (AVX-512 F, VL, DQ and BW).
pub fn eight_lanes_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        crate::f64x8::available()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Sets this process's lane groups to `lanes` (4 or 8; 8 only on a CPU that runs eight) for
/// every chain, in place of the choice per chain: how `gyroemu --lanes 4|8` compares the two
/// widths (tests, benchmarks). A refusal names the value and the rule, and changes nothing.
pub fn set_max_lanes(lanes: usize) -> Result<(), String> {
    match lanes {
        4 => {}
        8 if eight_lanes_available() => {}
        8 => return Err(
            "--lanes = 8: this CPU lacks AVX-512 (F, VL, DQ and BW), which eight lanes need; use 4"
                .into(),
        ),
        n => return Err(format!("--lanes = {n}: must be 4 or 8")),
    }
    LIMIT.store(lanes, Ordering::Relaxed);
    Ok(())
}

/// The widest lane group this process can run: 8 on a CPU with AVX-512 (unless limited to
/// 4), else 4. What a given chain runs in is [`max_lanes_for`].
pub fn max_lanes() -> usize {
    if LIMIT.load(Ordering::Relaxed) != 4 && eight_lanes_available() {
        8
    } else {
        4
    }
}

/// The widest lane group a board of `p` runs in on this CPU: [`max_lanes`], except on a CPU
/// that splits 512-bit operations in halves ([`halves_512`]), where the noiseless rotating
/// chain runs in four lanes unless `--lanes 8` asks for eight. Measured there (AMD EPYC
/// family 25 model 17, docs/performance.md, twenty-seventh session), eight lanes against four,
/// both threads busy (alternating `run`s of 16 points): the noiseless rotating chain 0.93x at
/// the best run (`reproduce` 5 % longer), the Coriolis chain 1.06x, the rate-table chain
/// 1.08x; the bench's chains with noise and converters 1.07x to 1.19x.
pub fn max_lanes_for(p: &BoardParams) -> usize {
    LaneCpu::this().lanes_for(p)
}

/// What the choice of a lane width knows of the CPU and the process.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LaneCpu {
    /// The widest group the process can run ([`max_lanes`]: 4 or 8).
    pub widest: usize,
    /// `--lanes 8` asks for eight lanes on every chain.
    pub forced_eight: bool,
    /// The CPU runs 512-bit operations as two halves ([`halves_512`]).
    pub halves_512: bool,
}

impl LaneCpu {
    /// This process on this CPU.
    pub fn this() -> Self {
        Self {
            widest: max_lanes(),
            forced_eight: LIMIT.load(Ordering::Relaxed) == 8,
            halves_512: halves_512(),
        }
    }

    /// The widest lane group a board of `p` runs in ([`max_lanes_for`]): four where the CPU
    /// splits 512-bit operations and the chain is the rotating excitation with no noise
    /// source, converter or rail (the board's ideal loop), unless eight are forced.
    pub fn lanes_for(self, p: &BoardParams) -> usize {
        let four_faster = self.halves_512 && p.shape.is_rotating() && !p.imperfect();
        if self.widest == 8 && four_faster && !self.forced_eight {
            4
        } else {
            self.widest
        }
    }
}

/// The CPU has AVX-512 and runs each 512-bit operation as two 256-bit halves: AMD family
/// 19h (Zen 4; its Zen 3 parts lack AVX-512). Zen 5 (family 1Ah) server and desktop parts
/// and Intel's cores run them whole; Zen 5 mobile parts are said to split them too, but are
/// not told apart here (unmeasured: they run eight lanes on every chain).
pub fn halves_512() -> bool {
    static HALVES: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *HALVES.get_or_init(|| {
        let zen4 = crate::CpuId::this_cpu()
            .is_some_and(|c| c.vendor == "AuthenticAMD" && c.family == 0x19);
        eight_lanes_available() && zen4
    })
}

/// The vector paths this process chose on this CPU, for a benchmark's header: the widest
/// lane group (eight needs AVX-512 F, VL, DQ and BW), whether 512-bit operations are taken to
/// run in halves ([`halves_512`]: AMD family 19h only, so a chain may run four lanes),
/// and the normal generator's fast path ([`gyroemu_core::gauss::fast_path`], its own check).
/// The choices, not a survey of the hardware.
pub fn vector_paths() -> String {
    let lanes = if !eight_lanes_available() {
        "groups of up to four lanes (no AVX-512 F, VL, DQ and BW)"
    } else if max_lanes() == 4 {
        "groups of up to four lanes (limited to four in this process; the CPU has AVX-512 F, VL, DQ and BW)"
    } else if halves_512() {
        "groups of up to eight lanes (AVX-512 F, VL, DQ, BW; 512-bit operations taken to run in halves, AMD family 19h)"
    } else {
        "groups of up to eight lanes (AVX-512 F, VL, DQ, BW)"
    };
    format!(
        "{lanes}; the normal generator: {}",
        gyroemu_core::gauss::fast_path()
    )
}

/// The sizes of the lane groups for `n` points on `threads` threads, in order (points taken
/// in the caller's order), each at most `width` (4 or 8) points. Groups of eight are used only
/// where they do not leave a thread idle that groups of four would keep busy: with at most
/// four points per thread the groups are of four; beyond, as many groups of eight as still
/// leave `threads` groups (or all of eight), the rest split evenly.
pub fn lane_groups(n: usize, threads: usize, width: usize) -> Vec<usize> {
    let threads = threads.max(1);
    let fours = || {
        (0..n.div_ceil(4))
            .map(|g| 4.min(n - 4 * g))
            .collect::<Vec<_>>()
    };
    if width < 8 || n <= 4 * threads {
        return fours();
    }
    let groups = threads.max(n.div_ceil(8));
    // k groups of eight leave n - 8k points for groups - k groups of at least one each.
    let eights = ((n - groups) / 7).min(n / 8);
    let rest = n - 8 * eights;
    let others = groups - eights;
    let mut sizes = vec![8; eights];
    sizes.extend((0..others).map(|g| rest / others + usize::from(g < rest % others)));
    sizes.retain(|&s| s > 0);
    sizes
}

/// What a lane of a group of four costs against one of a group of eight, per sample, where
/// eight run: the same instructions on half the lanes. 1.5 to 1.8 measured on CPUs with full
/// 512-bit units (AMD Zen 5, Intel Xeon), about 1.05 on AMD Zen 4 (which splits them in two
/// halves); the lower end, so groups of four are taken only where they save lane-samples on
/// either.
pub const FOUR_LANE_COST: f64 = 1.5;

/// The sizes of the lane groups for points whose runs are `samples` input samples (longest
/// first), all on one thread, each group at most `width` (4 or 8) points: consecutive points,
/// cut where that makes the least work, a group running as long as its first (longest) point
/// in four lanes (up to four points; cost [`FOUR_LANE_COST`] per lane) or eight (each lane
/// cost 1). Points of one length fill whole groups of `width`; a few long points beside many
/// short ones run in a group of four of their own rather than keep seven lanes idle.
pub fn groups_by_length(samples: &[u64], width: usize) -> Vec<usize> {
    let n = samples.len();
    let width = width.max(1);
    let cost = |first: usize, size: usize| {
        let lanes = if size <= 4 { 4.0 * FOUR_LANE_COST } else { 8.0 };
        samples[first] as f64 * lanes
    };
    // best[i]: the least cost of points i.. and the size of the group starting at i.
    let mut best = vec![(0.0, 0); n + 1];
    for i in (0..n).rev() {
        // Largest first: of equal costs, the fuller group.
        best[i] = (1..=width.min(n - i))
            .rev()
            .map(|size| (cost(i, size) + best[i + size].0, size))
            .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
    }
    let mut sizes = Vec::new();
    let mut i = 0;
    while i < n {
        sizes.push(best[i].1);
        i += best[i].1;
    }
    sizes
}

/// The sizes of the lane groups of points of a board of `p` whose runs are `samples` input
/// samples (longest first) for `threads` threads: cut by the runs ([`groups_by_length`]) on one
/// thread (a thread of a pool shared with other work), else to keep every thread busy
/// ([`lane_groups`]); each at most [`max_lanes_for`] `p`.
pub fn group_sizes(p: &BoardParams, samples: &[u64], threads: usize) -> Vec<usize> {
    let width = max_lanes_for(p);
    if threads == 1 {
        groups_by_length(samples, width)
    } else {
        lane_groups(samples.len(), threads, width)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_cover_the_points_fill_the_threads_and_fit_their_width() {
        for width in [4, 8] {
            for threads in 1..=9 {
                for n in 0..=70 {
                    let g = lane_groups(n, threads, width);
                    assert_eq!(g.iter().sum::<usize>(), n, "{n} {threads} {width}");
                    assert!(g.iter().all(|&s| (1..=width).contains(&s)), "{g:?}");
                    // Never fewer groups than threads (or than groups of four would give).
                    assert!(
                        g.len() >= threads.min(n.div_ceil(4)),
                        "{n} {threads}: {g:?}"
                    );
                    if width == 4 || n <= 4 * threads {
                        assert_eq!(g.len(), n.div_ceil(4), "{n} {threads}: {g:?}");
                    } else {
                        // Eights where the threads stay busy: no more groups than needed.
                        assert!(
                            g.len() <= threads.max(n.div_ceil(8)),
                            "{n} {threads}: {g:?}"
                        );
                    }
                }
            }
        }
        // Examples on two threads: 9 points as 8 + 1, 20 as 8 + 8 + 4, 7 as 4 + 3.
        assert_eq!(lane_groups(9, 2, 8), [8, 1]);
        assert_eq!(lane_groups(20, 2, 8), [8, 8, 4]);
        assert_eq!(lane_groups(7, 2, 8), [4, 3]);
        assert_eq!(lane_groups(16, 1, 8), [8, 8]);
    }

    /// Every partition into consecutive groups of at most `width`, by brute force.
    fn cheapest(samples: &[u64], width: usize) -> f64 {
        let n = samples.len();
        let cost = |first: usize, size: usize| {
            samples[first] as f64 * if size <= 4 { 4.0 * FOUR_LANE_COST } else { 8.0 }
        };
        (0u32..1 << n.saturating_sub(1))
            .filter_map(|cuts| {
                let mut total = 0.0;
                let mut start = 0;
                for i in 1..=n {
                    if i == n || cuts >> (i - 1) & 1 == 1 {
                        if i - start > width {
                            return None;
                        }
                        total += cost(start, i - start);
                        start = i;
                    }
                }
                Some(total)
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn groups_by_length_cost_the_least_of_every_partition() {
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            seed >> 40
        };
        for width in [4, 8] {
            for n in 0..=12 {
                let mut s: Vec<u64> = (0..n).map(|_| 1 + next() % 100).collect();
                s.sort_unstable_by(|a, b| b.cmp(a));
                let g = groups_by_length(&s, width);
                assert_eq!(g.iter().sum::<usize>(), n);
                assert!(g.iter().all(|&k| (1..=width).contains(&k)), "{g:?}");
                let mut at = 0;
                let mut total = 0.0;
                for &k in &g {
                    total += s[at] as f64 * if k <= 4 { 4.0 * FOUR_LANE_COST } else { 8.0 };
                    at += k;
                }
                assert_eq!(total, cheapest(&s, width), "{s:?} {width}: {g:?}");
            }
        }
        // Equal runs fill whole groups; the bandwidth sweep's runs (settling 12.2 s plus two
        // table periods or 4 s) keep its four longer points apart from its five shortest:
        // 522 x 6 + 162 x 8 = 4428 against 522 x 8 + 162 x 6 = 5148 as eight and one.
        assert_eq!(groups_by_length(&[5; 16], 8), [8, 8]);
        let bw = [522, 322, 222, 189, 162, 162, 162, 162, 162];
        assert_eq!(groups_by_length(&bw, 8), [4, 5]);
        assert_eq!(groups_by_length(&bw, 4), [4, 4, 1]);
    }

    #[test]
    fn a_bad_lane_limit_is_refused_and_changes_nothing() {
        let before = max_lanes();
        assert!(set_max_lanes(3).unwrap_err().contains("must be 4 or 8"));
        assert!(set_max_lanes(16).is_err());
        if !eight_lanes_available() {
            assert!(set_max_lanes(8).unwrap_err().contains("AVX-512"));
        }
        assert_eq!(max_lanes(), before);
    }
}
