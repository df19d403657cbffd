//! How wide a lane group is: eight points in `F64x8` lanes on a CPU with AVX-512, four in
//! `f64x4` lanes elsewhere (or when a process limits itself to four: `--lanes 4`, for tests and
//! benchmarks). Each lane is its own point, so no result depends on the width or the grouping;
//! the width is a speed choice made at run time.

use std::sync::atomic::{AtomicUsize, Ordering};

/// The widest lane group (`F64x8`).
pub const MAX_LANES: usize = 8;

/// The lane group of the canonical grouping that results report (the work of a sweep, in
/// `canonical_work`), the same on every CPU whatever width actually ran.
pub const CANONICAL_LANES: usize = 4;

/// The widest group this process may use ([`set_max_lanes`]).
static LIMIT: AtomicUsize = AtomicUsize::new(MAX_LANES);

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

/// Limits this process's lane groups to `lanes` (4 or 8; 8 only on a CPU that runs eight):
/// how `gyroemu --lanes 4|8` compares the two widths (tests, benchmarks). A refusal names the
/// value and the rule, and changes nothing.
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

/// The widest lane group this process runs: 8 on a CPU with AVX-512 (unless limited), else 4.
pub fn max_lanes() -> usize {
    if LIMIT.load(Ordering::Relaxed) >= 8 && eight_lanes_available() {
        8
    } else {
        4
    }
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
