//! Split sweeps: a long point's averaging window cut into segments that run as lanes of their
//! own, side by side, each starting at its own place on the time axis and settling anew from
//! rest (`Board::with_starts`), so one long point no longer bounds a run to one thread and one
//! lane. Every sample is still emulated; the segments' averages, weighted by their spans, are
//! the average over the whole window, up to what each segment's settling leaves of its start
//! transient (e^-16 = 1.1e-7 of the response after the default 16 time constants, THEORY
//! section 7, decaying within a time constant of the segment). A sweep whose settling is
//! shorter than the default runs whole.
//!
//! The cut depends on the config alone (never on the machine), so a split sweep gives the
//! same bits on every CPU, lane width and thread count.

use gyroemu_board::{starts_share_carrier, BoardParams, LaneResult, Point, MAX_LANES};
use gyroemu_config::Config;
use gyroemu_core::Complex64;
use gyroemu_lpf::Window;

/// A segment's span is at least this many settling times, so re-settling adds at most 1/64
/// (1.6 %) to the samples a point runs.
pub const MIN_SEGMENT_SETTLES: u64 = 64;

/// Most segments per point.
pub const MAX_SEGMENTS: u64 = 64;

/// One lane of a sweep: a whole point, or one segment of a split point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lane {
    /// The point's index in `emulated_rates_dps`.
    pub point: usize,
    /// The segment's index (0 for a whole point).
    pub segment: usize,
    /// Where the segment starts on the point's averaging axis, decimated samples (0 for a
    /// whole point); its board starts that many blocks late and settles as any run does.
    pub start_block: u64,
    /// The segment's own window (the point's window for a whole point).
    pub window: Window,
}

/// How a split sweep's lanes may share a lane group.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Packing {
    /// Any segments together: every segment start shares the carrier's phase.
    Free,
    /// Only segments that start together (the carrier's phase differs between starts).
    SameStart,
}

/// The lanes of the points `todo` of `cfg`'s sweep (point `i` planned as `plan(i)`), split
/// when `split` is asked and the sweep can be split, else one whole point per lane. A sweep
/// is split when: its points have boxcar windows on a board without noise (a noisy point's
/// segments would draw other streams than the point; a rate table's segments each follow
/// their table from where they start), settling at least the default time; the dump (ending at
/// `dump_end_s` from the start of its run) fits in its point's first segment; and either
/// - `k`, the smallest number of segments that fills whole groups of eight lanes
///   (`8 / gcd(points, 8)`), times the largest whole factor that keeps the longest point's
///   segments at least [`MIN_SEGMENT_SETTLES`] settling times long (at most
///   [`MAX_SEGMENTS`]), is above 1 (long points: every thread and lane busy), or
/// - failing that, cutting each point into the fewest segments that fill whole groups of
///   four (`4 / gcd(points, 4)`, segments that may share any group) runs at least
///   1/[`MIN_IDLE_SAVING`] fewer lane-samples than the whole points do with their groups'
///   idle lanes ([`lane_samples_in_fours`]); where those segments leave lanes of groups of
///   eight idle, two cuts that fill them are weighed by the same rules, the one with fewer
///   lane-samples in groups of eight first: the points with the longest segments taking one
///   segment more each, every point cut evenly (`fill_eights`: Fig. 5's seven 1 s points as
///   32 segments, four points in five and three in four), and the cut by the binary digits
///   of the point count (`binary_cut`: Fig. 5's seven as 4 + 2 + 1 points in halves,
///   quarters and eighths, 24 segments in three full groups of eight, or six of four), which
///   Fig. 5 takes.
///
/// A dump that does not fit keeps the sweep whole: its bits are then a continuous run's, not a
/// split one's (a dump of the first second, as `reproduce` records, always fits).
pub fn lanes_of(
    cfg: &Config,
    todo: &[usize],
    plan: &dyn Fn(usize) -> Point,
    split: bool,
    dump_end_s: Option<f64>,
) -> (Vec<Lane>, Packing) {
    let whole = || {
        let lanes = todo
            .iter()
            .map(|&i| Lane {
                point: i,
                segment: 0,
                start_block: 0,
                window: plan(i).window,
            })
            .collect::<Vec<_>>();
        (lanes, Packing::SameStart)
    };
    if !split || todo.is_empty() || !splittable(cfg) {
        return whole();
    }
    let windows: Option<Vec<(u64, f64)>> = todo
        .iter()
        .map(|&i| match plan(i).window {
            Window::Boxcar { n, frac } => Some((n, frac)),
            Window::Hann { .. } => None,
        })
        .collect();
    let Some(windows) = windows else {
        return whole();
    };
    let longest = windows.iter().map(|w| w.0).max().unwrap_or(0);
    let settle = cfg.n_settle_out().max(1);
    let fill = (MAX_LANES / gcd(todo.len(), MAX_LANES)) as u64;
    let most = longest / (MIN_SEGMENT_SETTLES.saturating_mul(settle));
    let k = fill * (most / fill).min(MAX_SEGMENTS / fill);
    // The cuts to take, in order of preference: per point, its segment length.
    let (cuts, packing) = if k >= 2 {
        let (len, packing) = segment_length(cfg, longest.div_ceil(k));
        (vec![vec![len; todo.len()]], packing)
    } else {
        // Whole points leave lanes of their groups idle; segments that fill groups of four
        // settle anew. The cut is the same on every machine (groups of four on all).
        let fours = (4 / gcd(todo.len(), 4)) as u64;
        if fours < 2 || longest < fours {
            return whole();
        }
        let (len, packing) = segment_length(cfg, longest.div_ceil(fours));
        let n_settle = cfg.n_settle_out();
        let (w, _) = whole();
        let before = lane_samples_in_fours(&w, n_settle);
        let after = lane_samples_in_fours(&cut(todo, &windows, len), n_settle);
        let saves = after.saturating_add(before / MIN_IDLE_SAVING) <= before;
        if packing != Packing::Free || !saves {
            return whole();
        }
        let lens = vec![len; todo.len()];
        // Of the cuts that fill groups of eight, the one with fewer lane-samples first.
        let mut full: Vec<Vec<u64>> = [
            binary_cut(cfg, &windows, &lens),
            fill_eights(cfg, &windows, &lens),
        ]
        .into_iter()
        .flatten()
        .collect();
        full.sort_by_key(|c| cut_cost(&windows, n_settle, c, 8));
        (full.into_iter().chain([lens]).collect(), packing)
    };
    // The dump must end within its point's first segment: within the shortest segment (a
    // point's segments all have its length but its last).
    let holds_dump = |lens: &[u64]| {
        let first = lens.iter().copied().min().unwrap_or(0);
        let first_end_s = (cfg.n_settle_out() + first) as f64 / cfg.fs_out_hz();
        dump_end_s.is_none_or(|e| e <= first_end_s)
    };
    match cuts.iter().find(|lens| holds_dump(lens)) {
        Some(lens) => (cut_each(todo, &windows, lens), packing),
        None => whole(),
    }
}

/// Per point, the segment lengths of a cut whose lanes fill whole groups of eight, if the cut
/// at `lens` (per point, decimated samples) leaves lanes of them idle: the points whose
/// segments are the longest (as many as there are idle lanes, at most one each) take one
/// segment more, and every point's segments are made even (its window over its count), if
/// those segments still share any group ([`Packing::Free`]) and the new cut runs at least
/// 1/[`MIN_IDLE_SAVING`] fewer lane-samples in groups of eight and at most
/// 1/`MIN_IDLE_SAVING` more in groups of four (the same cut on every machine: a gain where
/// eight lanes run, no real loss where four do). Fig. 5's 28 segments of 0.255 s ran as three
/// groups of eight and one of four; as 20 of 0.204 s and 12 of 0.255 s they fill four: 9 %
/// fewer lane-samples in eights, 1 % more in fours.
fn fill_eights(cfg: &Config, windows: &[(u64, f64)], lens: &[u64]) -> Option<Vec<u64>> {
    let mut counts: Vec<u64> = windows
        .iter()
        .zip(lens)
        .map(|(w, &l)| segments_of(w.0, l))
        .collect();
    let idle = (8 - counts.iter().sum::<u64>() % 8) % 8;
    if idle == 0 || idle as usize > windows.len() {
        return None;
    }
    // The longest segments first (of equal ones, the earlier point's).
    let mut order: Vec<usize> = (0..windows.len()).collect();
    order.sort_by_key(|&p| core::cmp::Reverse(windows[p].0.div_ceil(counts[p])));
    for &p in &order[..idle as usize] {
        counts[p] += 1;
    }
    let even = counted_cut(&cfg.board_params(), windows, &counts)?;
    pays_off(windows, cfg.n_settle_out(), lens, &even).then_some(even)
}

/// The segments a window of `n` decimated samples runs as, cut at `len` ([`cut_each`]).
fn segments_of(n: u64, len: u64) -> u64 {
    n.div_ceil(len.max(1)).max(1)
}

/// Per point, the length of its `counts[p]` even segments (its window over its count, as
/// [`segment_length_on`] rounds it), if every point then runs as exactly that many segments
/// and they share any group ([`Packing::Free`]): the cuts of [`fill_eights`] and
/// [`binary_cut`], which fix each point's count ([`even_cut`] fixes a common length).
fn counted_cut(p: &BoardParams, windows: &[(u64, f64)], counts: &[u64]) -> Option<Vec<u64>> {
    windows
        .iter()
        .zip(counts)
        .map(|(&(n, _), &c)| {
            let (len, packing) = segment_length_on(p, n.div_ceil(c));
            (packing == Packing::Free && segments_of(n, len) == c).then_some(len)
        })
        .collect()
}

/// Per point, the segment lengths of the cut by the binary digits of the point count: with
/// every group full, a cut's lane-samples are the points' own plus a settling per segment, so
/// the fewest segments that fill whole groups of eight cost the least. Whole groups' worth of
/// points (the longest) run whole; of the rest, `r` = 4 + 2 + 1 at most, each power of two
/// `2^b` in `r` takes the next `2^b` points (the longest first), each cut in `8 / 2^b`
/// segments: one full group per power, every segment in it of one length, and full groups
/// of four too (the same cut on every machine). Fig. 5's seven BAW points run as four in
/// halves, two in quarters and one in eighths: 24 segments in three groups, where
/// [`fill_eights`]' 32 took four (4.6 % fewer lane-samples). Taken where it pays off against
/// the cut at `lens` ([`pays_off`]) and its segments share any group.
fn binary_cut(cfg: &Config, windows: &[(u64, f64)], lens: &[u64]) -> Option<Vec<u64>> {
    let n = windows.len();
    let rest = n % MAX_LANES;
    if rest == 0 {
        return None;
    }
    // Points by window length, longest first (of equal ones, the earlier point).
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&p| core::cmp::Reverse(windows[p].0));
    // The longest `n - rest` run whole; the rest, in `order`, take the powers of two in
    // `rest` from the largest down.
    let mut counts = vec![1u64; n];
    let mut next = n - rest;
    for b in (0..MAX_LANES.trailing_zeros()).rev() {
        let size = 1usize << b;
        if rest & size != 0 {
            for &p in &order[next..next + size] {
                counts[p] = (MAX_LANES / size) as u64;
            }
            next += size;
        }
    }
    // The whole points' windows are the longest, so they share any group wherever the cut
    // ones do: one rule for all.
    let cut = counted_cut(&cfg.board_params(), windows, &counts)?;
    pays_off(windows, cfg.n_settle_out(), lens, &cut).then_some(cut)
}

/// The lane-samples of `windows` cut at `lens` (per point) in groups of `width`.
fn cut_cost(windows: &[(u64, f64)], n_settle: u64, lens: &[u64], width: usize) -> u64 {
    let todo: Vec<usize> = (0..windows.len()).collect();
    lane_samples_in(&cut_each(&todo, windows, lens), n_settle, width)
}

/// The cut at `after` (per point) is worth taking over the one at `before`: at least
/// 1/[`MIN_IDLE_SAVING`] fewer lane-samples in groups of eight and at most 1/`MIN_IDLE_SAVING`
/// more in groups of four (a gain where eight lanes run, no real loss where four do).
fn pays_off(windows: &[(u64, f64)], n_settle: u64, before: &[u64], after: &[u64]) -> bool {
    let cost = |lens: &[u64]| [8, 4].map(|width| cut_cost(windows, n_settle, lens, width));
    saves_enough(cost(before), cost(after))
}

/// A plan that runs `after` lane-samples in groups of eight and of four (`[eights, fours]`)
/// is worth taking over one that runs `before`: at least 1/[`MIN_IDLE_SAVING`] fewer in
/// eights and at most 1/`MIN_IDLE_SAVING` more in fours (the rule of [`pays_off`], for plans
/// costed otherwise: refilled lanes).
pub(crate) fn saves_enough(before: [u64; 2], after: [u64; 2]) -> bool {
    let [eights, fours] = before;
    let gains = after[0].saturating_add(eights / MIN_IDLE_SAVING) <= eights;
    let fair = after[1] <= fours.saturating_add(fours / MIN_IDLE_SAVING);
    gains && fair
}

/// A split for idle lanes is taken only if it runs at least 1/this fewer lane-samples (a
/// smaller gain is not worth other bits than the whole points').
pub const MIN_IDLE_SAVING: u64 = 32;

/// The points `todo` (boxcar windows `windows`: decimated samples and fractional end) cut
/// into segments of `len` decimated samples, the last of each point shorter.
fn cut(todo: &[usize], windows: &[(u64, f64)], len: u64) -> Vec<Lane> {
    cut_each(todo, windows, &vec![len; todo.len()])
}

/// [`cut`] with each point's own segment length (`lens`, beside `todo`).
pub(crate) fn cut_each(todo: &[usize], windows: &[(u64, f64)], lens: &[u64]) -> Vec<Lane> {
    let mut lanes = Vec::new();
    for ((&i, &(n, frac)), &len) in todo.iter().zip(windows).zip(lens) {
        // A zero length would never end the point.
        let len = len.max(1);
        let mut a = 0;
        let mut segment = 0;
        while a < n || (a == n && segment == 0) {
            let b = (a + len).min(n);
            // The point's fractional end sample goes with its last segment.
            let window = Window::Boxcar {
                n: b - a,
                frac: if b == n { frac } else { 0.0 },
            };
            lanes.push(Lane {
                point: i,
                segment,
                start_block: a,
                window,
            });
            segment += 1;
            a = b;
        }
    }
    lanes
}

/// The decimated samples `lanes` occupy in groups of four, longest first, each group running
/// `n_settle` plus its longest window, idle lanes included: what they cost where a lane group
/// of four runs at the cost of four lanes, whatever its lanes do.
pub fn lane_samples_in_fours(lanes: &[Lane], n_settle: u64) -> u64 {
    lane_samples_in(lanes, n_settle, 4)
}

/// [`lane_samples_in_fours`] in groups of `width` lanes.
pub fn lane_samples_in(lanes: &[Lane], n_settle: u64, width: usize) -> u64 {
    let mut runs: Vec<u64> = lanes
        .iter()
        .map(|l| n_settle + l.window.samples())
        .collect();
    runs.sort_unstable_by(|a, b| b.cmp(a));
    runs.chunks(width.max(1)).map(|g| width as u64 * g[0]).sum()
}

/// A board `cfg` describes runs segments that start late (no noise: a segment would draw
/// other normals than its point; a rate table's lanes each follow their table from where they
/// start), and each settles at least the default time: the start transient a split point
/// averages is each segment's, so it must be as small as the one a whole run leaves.
pub fn splittable(cfg: &Config) -> bool {
    cfg.board_params().noise.is_none() && cfg.settle_s() >= cfg.default_settle_s()
}

/// Per point, the segment length (decimated samples) of the cut of points of boxcar windows
/// `windows` (decimated samples and fractional end; all settling `n_settle`) whose lanes run
/// the fewest lane-samples in groups of eight, or `None` to run them whole: a cut is taken
/// only if it runs at least 1/[`MIN_IDLE_SAVING`] fewer lane-samples in groups of eight than
/// the whole points and no more than 1/`MIN_IDLE_SAVING` more in groups of four (the same
/// cut on every machine). The cuts weighed are those that bring every lane within a common
/// length: each point in the fewest even segments within it, for every length a point's
/// even cut gives, as it is and rounded by `segment` (at most [`MAX_SEGMENTS`] segments a
/// point); `segment` rounds a length up
/// to one whose segments may share any group, or says they may not ([`Packing::SameStart`]:
/// that cut is not weighed). The bandwidth sweep's points (settling 12.25 s, windows of 40,
/// 20, 10, 6.7 and five of 4 s) run as 13 lanes of at most 22.25 s: groups of eight of 22.25
/// and 16.25 s (739 408 lane-samples counted in eights), against 1 315 408 whole (in groups
/// of eight of 52.25 and 16.25 s; the lane groups a CPU runs may differ, not the cut).
pub fn cut_to_fill(
    windows: &[(u64, f64)],
    n_settle: u64,
    segment: &dyn Fn(u64) -> (u64, Packing),
) -> Option<Vec<u64>> {
    let whole: Vec<u64> = windows.iter().map(|w| w.0.max(1)).collect();
    let mut best: Option<(u64, usize, Vec<u64>)> = None;
    for t in cut_targets(windows, segment) {
        let Some(lens) = even_cut(windows, t, segment) else {
            continue;
        };
        let lanes: usize = windows
            .iter()
            .zip(&lens)
            .map(|(w, &l)| w.0.div_ceil(l) as usize)
            .sum();
        let c8 = cut_cost(windows, n_settle, &lens, 8);
        // Of equal costs, the fewer lanes (the less settling).
        if best.as_ref().is_none_or(|(b, n, _)| (c8, lanes) < (*b, *n)) {
            best = Some((c8, lanes, lens));
        }
    }
    let (_, _, lens) = best?;
    (lens != whole && pays_off(windows, n_settle, &whole, &lens)).then_some(lens)
}

/// Every common length a point's even cut gives (each point in 1 to [`MAX_SEGMENTS`]
/// segments), before and after `segment` rounds it, ascending: the lengths a cut of
/// [`even_cut`] is weighed at.
pub(crate) fn cut_targets(
    windows: &[(u64, f64)],
    segment: &dyn Fn(u64) -> (u64, Packing),
) -> Vec<u64> {
    let mut targets: Vec<u64> = windows
        .iter()
        .flat_map(|w| (1..=MAX_SEGMENTS).map(move |c| w.0.div_ceil(c)))
        .flat_map(|t| [t, segment(t).0])
        .filter(|&t| t > 0)
        .collect();
    targets.sort_unstable();
    targets.dedup();
    targets
}

/// Per point, the length of its fewest even segments within `t` decimated samples (rounded
/// up by `segment`), if every point's segments may share any group and stay within `t`.
pub(crate) fn even_cut(
    windows: &[(u64, f64)],
    t: u64,
    segment: &dyn Fn(u64) -> (u64, Packing),
) -> Option<Vec<u64>> {
    windows
        .iter()
        .map(|&(n, _)| {
            let count = n.div_ceil(t).max(1);
            if count > MAX_SEGMENTS {
                return None;
            }
            if count == 1 {
                return Some(n.max(1));
            }
            let (len, packing) = segment(n.div_ceil(count));
            let fits = len > 0 && len <= t && n.div_ceil(len) == count;
            (packing == Packing::Free && fits).then_some(len)
        })
        .collect()
}

/// The segment length (decimated samples) for at least `len`: rounded up to a whole number
/// of the carrier's repeat where that repeat is short (then any segments share a lane group),
/// else `len` (segments share a group only with those starting with them).
pub fn segment_length(cfg: &Config, len: u64) -> (u64, Packing) {
    segment_length_on(&cfg.board_params(), len)
}

/// [`segment_length`] on the board `p` (for callers that weigh many lengths: a rate table's
/// board parameters take steady-state solves to build).
pub fn segment_length_on(p: &BoardParams, len: u64) -> (u64, Packing) {
    let m = p.decimation as u64;
    // The carrier's phase word repeats after a power of two of samples: the first power of
    // two of blocks at which it does, if one below 1/16 of the segment.
    (0..=20)
        .map(|e| 1u64 << e)
        .take_while(|&u| 16 * u <= len)
        .find(|&u| starts_share_carrier(p, &[0, u * m]))
        .map_or((len, Packing::SameStart), |u| {
            (len.div_ceil(u) * u, Packing::Free)
        })
}

pub(crate) fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The lane groups of `lanes`, longest first, cut where `sizes` says for a set of lanes (in
/// that order): any lanes together ([`Packing::Free`], so lanes of one length share a group),
/// or only lanes with the same start.
pub fn pack(
    lanes: &[Lane],
    packing: Packing,
    sizes: &dyn Fn(&[Lane]) -> Vec<usize>,
) -> Vec<Vec<Lane>> {
    let sets: Vec<Vec<Lane>> = match packing {
        Packing::Free => {
            let mut v = lanes.to_vec();
            v.sort_by_key(|l| core::cmp::Reverse(l.window.samples()));
            vec![v]
        }
        Packing::SameStart => {
            let mut starts: Vec<u64> = lanes.iter().map(|l| l.start_block).collect();
            starts.sort_unstable();
            starts.dedup();
            starts
                .iter()
                .map(|&s| {
                    let mut v: Vec<Lane> = lanes
                        .iter()
                        .filter(|l| l.start_block == s)
                        .copied()
                        .collect();
                    v.sort_by_key(|l| core::cmp::Reverse(l.window.samples()));
                    v
                })
                .collect()
        }
    };
    let mut groups = Vec::new();
    for set in &sets {
        let mut rest = &set[..];
        for size in sizes(set) {
            let (g, r) = rest.split_at(size);
            groups.push(g.to_vec());
            rest = r;
        }
    }
    groups
}

/// A split point's result from its segments' (each with its window): every average weighted
/// by its segment's span, the counts added. A whole point's single lane is its result as is.
pub fn combine(segments: &[(Window, LaneResult)]) -> LaneResult {
    if let [(_, only)] = segments {
        return *only;
    }
    let total: f64 = segments.iter().map(|(w, _)| w.span()).sum();
    let mean = |f: &dyn Fn(&LaneResult) -> Complex64| {
        segments
            .iter()
            .map(|(w, r)| f(r) * w.span())
            .fold(Complex64::new(0.0, 0.0), |a, b| a + b)
            / total
    };
    let mut out = LaneResult::default();
    for k in 0..2 {
        out.z[k] = mean(&|r| r.z[k]);
        out.c[k] = mean(&|r| r.c[k]);
        out.s[k] = mean(&|r| r.s[k]);
        for h in 0..out.table_z[k].len() {
            out.table_z[k][h] = mean(&|r| r.table_z[k][h]);
        }
    }
    for (_, r) in segments {
        out.health.add(&r.health);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_config::presets::preset;

    /// Groups of eight lanes, the last of what is left.
    fn eights(set: &[Lane]) -> Vec<usize> {
        let n = set.len();
        (0..n.div_ceil(8)).map(|g| 8.min(n - 8 * g)).collect()
    }

    fn lanes(cfg: &Config, split: bool, dump_end_s: Option<f64>) -> (Vec<Lane>, Packing) {
        let rates = cfg.emulated_rates_dps();
        let todo: Vec<usize> = (0..rates.len()).collect();
        lanes_of(cfg, &todo, &|i| cfg.plan_point(rates[i]), split, dump_end_s)
    }

    /// Each point's segments tile its window: they start at 0 and follow on one another, each
    /// a boxcar of weight 1, the last with the point's fractional end; their spans add up
    /// to the window's.
    fn check_tiling(cfg: &Config, lanes: &[Lane]) {
        let rates = cfg.emulated_rates_dps();
        for (i, &r) in rates.iter().enumerate() {
            let Window::Boxcar { n, frac } = cfg.plan_point(r).window else {
                panic!("boxcar presets")
            };
            let segs: Vec<&Lane> = lanes.iter().filter(|l| l.point == i).collect();
            let mut at = 0;
            for (s, l) in segs.iter().enumerate() {
                assert_eq!((l.segment, l.start_block), (s, at), "point {i}");
                let Window::Boxcar { n: len, frac: f } = l.window else {
                    panic!()
                };
                let last = s + 1 == segs.len();
                assert_eq!(f, if last { frac } else { 0.0 }, "point {i} segment {s}");
                at += len;
            }
            assert_eq!(at, n, "point {i}");
            let spans: f64 = segs.iter().map(|l| l.window.span()).sum();
            assert_eq!(spans, n as f64 + frac, "point {i}");
        }
    }

    #[test]
    fn fig9s_points_split_into_eight_segments_that_fill_groups_of_eight() {
        let cfg = preset("m2tfg-rotating").unwrap();
        let (lanes, packing) = lanes(&cfg, true, None);
        assert_eq!(packing, Packing::Free);
        check_tiling(&cfg, &lanes);
        let settle = cfg.n_settle_out();
        for i in 0..7 {
            let segs: Vec<&Lane> = lanes.iter().filter(|l| l.point == i).collect();
            // The 25 deg/s point's window is a few periods shorter: its last segment too.
            assert_eq!(segs.len(), 8, "point {i}");
            for l in &segs[..7] {
                assert!(l.window.samples() > MIN_SEGMENT_SETTLES * settle, "{l:?}");
            }
        }
        // 56 lanes: seven whole groups of eight (and fourteen of four).
        assert_eq!(lanes.len() % 8, 0);
        // Every start shares the carrier (fs = 16 f0, decimation 100: multiples of 4 blocks).
        let m = cfg.decimation() as u64;
        let starts: Vec<u64> = lanes.iter().map(|l| l.start_block * m).collect();
        assert!(starts_share_carrier(&cfg.board_params(), &starts));
    }

    #[test]
    fn what_cannot_or_need_not_be_split_runs_whole() {
        let whole = |cfg: &Config, dump: Option<f64>| {
            let (l, _) = lanes(cfg, true, dump);
            l.iter().all(|l| l.segment == 0 && l.start_block == 0)
                && l.len() == cfg.emulated_rates_dps().len()
        };
        let fig9 = preset("m2tfg-rotating").unwrap();
        assert!(!whole(&fig9, None));
        // Not asked.
        let (l, _) = lanes(&fig9, false, None);
        assert_eq!(l.len(), 7);
        // Too short for two segments of 64 settling times (the --quick average of 15 s).
        let mut quick = fig9.clone();
        quick.experiment.average_s = 15.0;
        assert!(whole(&quick, None));
        // Noise: a segment would draw other normals than its point.
        let mut noisy = fig9.clone();
        noisy.noise = Some(gyroemu_config::NoiseConfig {
            seed: 1,
            tia_current_noise_a_per_rthz: 1e-13,
            ..Default::default()
        });
        assert!(whole(&noisy, None));
        // A Hann window weighs a sample by where it lies in the whole window.
        let mut hann = fig9.clone();
        hann.experiment.window = gyroemu_config::WindowKind::Hann;
        assert!(whole(&hann, None));
        // A settling shorter than the default would leave a larger transient in every
        // segment; a longer one keeps the split (while segments stay 64 settlings long).
        let mut short = fig9.clone();
        short.experiment.settle_s = Some(0.9 * fig9.default_settle_s());
        assert!(whole(&short, None));
        let mut long = fig9.clone();
        long.experiment.settle_s = Some(1.2 * fig9.default_settle_s());
        assert!(!whole(&long, None));
        // A dump that ends past the first segment.
        assert!(whole(&fig9, Some(100.0)));
        assert!(!whole(&fig9, Some(10.0)));
        // A rate table's segments follow their tables from where they start: its preset's
        // seven 10 s points (settling 12.25 s) gain nothing from segments and run whole, as
        // `reproduce` runs them; at 2000 s they split.
        let mut table = preset("m2tfg-ratetable").unwrap();
        assert!(whole(&table, None));
        table.experiment.average_s = 2000.0;
        assert!(!whole(&table, None));
        // Noise still keeps a rate table whole.
        table.noise = noisy.noise;
        assert!(whole(&table, None));
    }

    #[test]
    fn fig5s_seven_points_split_into_segments_that_fill_groups_of_eight() {
        // Seven BAW points of 1.02 s, settling 20 ms: too short for 64 settling times a
        // segment, so they would run whole in groups of four and three (one lane in eight
        // idle). Cut by the binary digits of seven (4 + 2 + 1): the four longest points in
        // halves, the next two in quarters, the shortest in eighths, 24 lanes in three full
        // groups of eight (or six of four); each segment settles anew. (Four segments a point
        // and a fifth for the four longest, `fill_eights`' cut, took 32 lanes.)
        let cfg = preset("baw-rotating").unwrap();
        let (lanes, packing) = lanes(&cfg, true, None);
        assert_eq!(packing, Packing::Free);
        check_tiling(&cfg, &lanes);
        assert_eq!(lanes.len(), 24);
        let settle = cfg.n_settle_out();
        let (whole, _) = lanes_of(
            &cfg,
            &(0..7).collect::<Vec<_>>(),
            &|i| cfg.plan_point(cfg.emulated_rates_dps()[i]),
            false,
            None,
        );
        let n = |i: usize| {
            whole
                .iter()
                .find(|l| l.point == i)
                .unwrap()
                .window
                .samples()
        };
        let segments = |i: usize| lanes.iter().filter(|l| l.point == i).count();
        let mut by_length: Vec<usize> = (0..7).collect();
        by_length.sort_by_key(|&i| core::cmp::Reverse(n(i)));
        for (rank, &i) in by_length.iter().enumerate() {
            let want = match rank {
                0..4 => 2,
                4..6 => 4,
                _ => 8,
            };
            assert_eq!(segments(i), want, "point {i}");
        }
        // Lane-samples, L = 50.5 s for s the settling: whole in fours 8 (s + L); cut, in
        // fours or eights alike, 8 (s + L/2) + 8 (s + L/4) + 8 (s + L/8): 7 L + 24 s, every
        // lane busy. `fill_eights`' cut ran 16 (s + L/4) + 16 (s + L/5) in eights.
        let (s, l) = (settle as f64, whole[0].window.samples() as f64);
        let binary = 8.0 * (3.0 * s + l / 2.0 + l / 4.0 + l / 8.0);
        let saving = |after: u64, before: f64| 1.0 - after as f64 / before;
        for width in [4, 8] {
            let cut = saving(lane_samples_in(&lanes, settle, width), binary);
            assert!(cut.abs() < 1e-3, "{width}: {cut}");
        }
        let fours = saving(lane_samples_in_fours(&lanes, settle), 8.0 * (s + l));
        assert!(fours > 0.08, "{fours}");
        let eights = saving(
            lane_samples_in(&lanes, settle, 8),
            16.0 * (2.0 * s + l / 4.0 + l / 5.0),
        );
        assert!(eights > 0.04, "{eights}");
        // Every start shares the carrier, so any segments share a group.
        let m = cfg.decimation() as u64;
        let starts: Vec<u64> = lanes.iter().map(|l| l.start_block * m).collect();
        assert!(starts_share_carrier(&cfg.board_params(), &starts));
    }

    #[test]
    fn a_dump_past_the_shorter_segments_keeps_the_cut_in_fours() {
        // Fig. 5's first segments end 0.02 + 0.2 s from the start cut in five, 0.02 + 0.25 s
        // cut in four: a dump ending between keeps the 28 segments, one beyond them whole.
        let cfg = preset("baw-rotating").unwrap();
        let count = |end_s: f64| lanes(&cfg, true, Some(end_s)).0.len();
        assert_eq!(count(0.2), 32);
        assert_eq!(count(0.25), 28);
        assert_eq!(count(0.3), 7);
    }

    #[test]
    fn idle_lanes_are_filled_only_where_that_saves_lane_samples() {
        let base = preset("baw-rotating").unwrap();
        let whole = |cfg: &Config| {
            let (l, _) = lanes(cfg, true, None);
            l.iter().all(|l| l.segment == 0) && l.len() == cfg.emulated_rates_dps().len()
        };
        assert!(!whole(&base));
        // Eight points fill their groups of four: nothing to gain.
        let mut eight = base.clone();
        eight.experiment.rates_dps.push(1440.0);
        assert!(whole(&eight));
        // Six points (groups of four and two) take two segments each, twelve lanes; those
        // leave four lanes of groups of eight idle, so the four longest take three: 16 lanes.
        let mut six = base.clone();
        six.experiment.rates_dps.truncate(6);
        let (l, _) = lanes(&six, true, None);
        assert_eq!(l.len(), 16);
        // Windows of 10 settling times (seven faster rates, so that 0.2 s covers half their
        // modulation period): four segments would add three settlings a point, more than the
        // idle lanes cost (28 x 3.5 against 8 x 11 settling times).
        let mut short = base.clone();
        short.experiment.rates_dps = (0..7).map(|i| 1800.0 + 360.0 * f64::from(i)).collect();
        short.experiment.average_s = 10.0 * base.settle_s();
        if let Err(e) = short.validate() {
            panic!("{e}");
        }
        assert!(whole(&short));
        // Twenty settling times save nothing (28 x 6 = 8 x 21): whole too; forty save 6 %
        // (28 x 11 against 8 x 41).
        short.experiment.average_s = 20.0 * base.settle_s();
        assert!(whole(&short));
        short.experiment.average_s = 40.0 * base.settle_s();
        assert!(!whole(&short));
        // Six of those points at ten settling times: two segments each fill groups of four
        // (12 x 6 against 8 x 11), but a third for the four longest would cost groups of four
        // 5.6 % more (4 x 6 + 12 x 13/3 = 76 against 12 x 6), over 1/32. Cut by the binary
        // digits of six (4 + 2), the four longest in halves and the two shortest (windows
        // shorter by their whole half modulation periods) in quarters, groups of eight run
        // a fifth less and groups of four 1.1 % more: 16 lanes, that cut's. At forty, 16 too.
        let count = |cfg: &Config| lanes(cfg, true, None).0.len();
        short.experiment.rates_dps.truncate(6);
        short.experiment.average_s = 10.0 * base.settle_s();
        let (l, _) = lanes(&short, true, None);
        let mut per_point: Vec<usize> = (0..6)
            .map(|i| l.iter().filter(|l| l.point == i).count())
            .collect();
        per_point.sort();
        assert_eq!(per_point, [2, 2, 2, 2, 4, 4]);
        short.experiment.average_s = 40.0 * base.settle_s();
        assert_eq!(count(&short), 16);
        // Fig. 9 --quick (15 s, settling 0.71 s): four segments would save 0.6 %, under 1/32.
        let mut quick = preset("m2tfg-rotating").unwrap();
        quick.experiment.average_s = 15.0;
        assert!(whole(&quick));
        // A carrier whose phase does not repeat: segments could share a group only with
        // those that start with them, so they cannot fill the idle lanes.
        let mut odd = base.clone();
        odd.drive.carrier_hz = Some(odd.device.f0_hz + 0.1);
        odd.validate().unwrap();
        assert!(whole(&odd));
    }

    /// Any length, segments sharing any group.
    fn free(len: u64) -> (u64, Packing) {
        (len, Packing::Free)
    }

    #[test]
    fn the_bandwidth_sweeps_long_points_are_cut_to_its_ten_second_lanes() {
        // Settling 12.25 s and windows of 40, 20, 10, 6.67 and five of 4 s at 2.4 kHz out.
        let s = 29_412;
        let mut windows = vec![(96_000, 0.0), (48_000, 0.0), (24_000, 0.0), (16_000, 0.0)];
        windows.extend([(9_600, 0.0); 5]);
        let lens = cut_to_fill(&windows, s, &free).expect("cut");
        // The 40 s point in four, the 20 s one in two: 13 lanes of at most 10 s windows.
        assert_eq!(
            lens,
            [24_000, 24_000, 24_000, 16_000, 9_600, 9_600, 9_600, 9_600, 9_600]
        );
        let todo: Vec<usize> = (0..9).collect();
        let cut = cut_each(&todo, &windows, &lens);
        assert_eq!(cut.len(), 13);
        // A boxcar of n runs n + 1 samples. Groups of eight: 8 (s + 10 s) + 8 (s + 4 s),
        // against 8 (s + 40 s) + 8 (s + 4 s) whole; in fours 4 (2 (s + 10 s) + 2 (s + 4 s))
        // against 4 (s + 40 s) + 8 (s + 4 s).
        let (ten, four, forty) = (s + 24_001, s + 9_601, s + 96_001);
        assert_eq!(lane_samples_in(&cut, s, 8), 8 * ten + 8 * four);
        assert_eq!(lane_samples_in(&cut, s, 4), 8 * ten + 8 * four);
        let whole = cut_each(
            &todo,
            &windows,
            &windows.iter().map(|w| w.0).collect::<Vec<_>>(),
        );
        assert_eq!(lane_samples_in(&whole, s, 8), 8 * forty + 8 * four);
        assert_eq!(lane_samples_in(&whole, s, 4), 4 * forty + 8 * four);
        // Segments that could share a group only with those starting with them: no cut.
        let by_start = |len: u64| (len, Packing::SameStart);
        assert_eq!(cut_to_fill(&windows, s, &by_start), None);
        // Lengths rounded up to a carrier repeat of 4 blocks: two points of 1000 blocks and
        // two of 330 (no settling) are weighed with the 1000s in three segments of 336
        // (rounded from 334): eight lanes within 336 blocks, 8 x 337 lane-samples, against
        // 8 x 501 for the best cut at a length that needs no rounding (the 1000s in two).
        let by4 = |len: u64| (len.div_ceil(4) * 4, Packing::Free);
        let w = [(1_000, 0.0), (1_000, 0.0), (330, 0.0), (330, 0.0)];
        assert_eq!(cut_to_fill(&w, 0, &by4), Some(vec![336, 336, 330, 330]));
        // A segment function that gives 0 is never taken.
        let nothing = |_: u64| (0, Packing::Free);
        assert_eq!(cut_to_fill(&[(1_000, 0.0); 4], 0, &nothing), None);
    }

    #[test]
    fn a_cut_is_taken_only_where_eights_gain_and_fours_do_not_lose() {
        // Four points of 100 blocks with no settling: two segments each fill a group of eight
        // (8 x 50 against 8 x 100) and cost groups of four nothing (2 x 4 x 50 = 4 x 100);
        // four segments cost the same in eights but settle more: two it is.
        assert_eq!(cut_to_fill(&[(100, 0.0); 4], 0, &free), Some(vec![50; 4]));
        // Settling 10 blocks: groups of eight still gain (8 x 60 against 8 x 110), but
        // groups of four would run 480 lane-samples against 440 whole: no cut.
        assert_eq!(cut_to_fill(&[(100, 0.0); 4], 10, &free), None);
        // Eight equal points fill their group whole.
        assert_eq!(cut_to_fill(&[(100, 0.0); 8], 10, &free), None);
        // A cut that saves less than 1/32 in eights is not taken: six points of 100 and one
        // of 104 (settling 10), the longest cut in two, fill the eighth lane and gain 4 of
        // 115 lane-samples a lane (3.5 %); with 103, 3 of 114 (2.6 %).
        let mut w = vec![(100, 0.0); 6];
        w.push((104, 0.0));
        assert_eq!(
            cut_to_fill(&w, 10, &free),
            Some(vec![100, 100, 100, 100, 100, 100, 52])
        );
        w[6] = (103, 0.0);
        assert_eq!(cut_to_fill(&w, 10, &free), None);
    }

    #[test]
    fn lane_samples_in_fours_count_each_group_at_its_longest_lane() {
        let lane = |n: u64| Lane {
            point: 0,
            segment: 0,
            start_block: 0,
            window: Window::Boxcar { n, frac: 0.0 },
        };
        // A boxcar of n runs n + 1 samples (its fractional end): after a settling of 2,
        // (13, 12, 11, 10) and (9), longest first.
        let lanes: Vec<Lane> = [7, 10, 6, 9, 8].into_iter().map(lane).collect();
        assert_eq!(lane_samples_in_fours(&lanes, 2), 4 * 13 + 4 * 9);
        assert_eq!(lane_samples_in_fours(&[], 2), 0);
    }

    #[test]
    fn a_carrier_that_does_not_repeat_packs_segments_by_start() {
        let mut cfg = preset("m2tfg-rotating").unwrap();
        // 15 000.1 Hz at 240 kHz: no short repeat of the carrier's phase word.
        cfg.drive.carrier_hz = Some(15_000.1);
        let (lanes, packing) = lanes(&cfg, true, None);
        assert_eq!(packing, Packing::SameStart);
        check_tiling(&cfg, &lanes);
        let groups = pack(&lanes, packing, &eights);
        for g in &groups {
            assert!(g.iter().all(|l| l.start_block == g[0].start_block), "{g:?}");
        }
        // A lane of every point at each start (the longest window sets the length).
        assert_eq!(groups.iter().map(Vec::len).sum::<usize>(), lanes.len());
    }

    #[test]
    fn free_packing_puts_lanes_of_one_length_together() {
        let cfg = preset("m2tfg-rotating").unwrap();
        let (lanes, packing) = lanes(&cfg, true, None);
        let groups = pack(&lanes, packing, &eights);
        assert_eq!(groups.len(), lanes.len() / 8);
        let len = |l: &Lane| l.window.samples();
        // Longest first: no group holds a lane longer than any of an earlier group.
        for w in groups.windows(2) {
            let shortest = w[0].iter().map(len).min().unwrap();
            assert!(w[1].iter().all(|l| len(l) <= shortest));
        }
    }

    #[test]
    fn segments_combine_into_the_mean_of_the_whole_window() {
        let r = |z: f64, h: u64| LaneResult {
            z: [Complex64::new(z, -z), Complex64::new(2.0 * z, 0.5)],
            c: [Complex64::new(z, 1.0), Complex64::new(-z, z)],
            s: [Complex64::new(3.0, z), Complex64::new(z, z * z)],
            health: gyroemu_board::Health {
                samples: h,
                dac_zero: [h / 2, 1],
                ..Default::default()
            },
            ..Default::default()
        };
        // Means 0.5 over 3 samples, 2.0 over 4, -1.0 over 2.25: the whole mean is the
        // sum 1.5 + 8 - 2.25 = 7.25 over 9.25 samples.
        let parts = [
            (Window::Boxcar { n: 3, frac: 0.0 }, r(0.5, 10)),
            (Window::Boxcar { n: 4, frac: 0.0 }, r(2.0, 20)),
            (Window::Boxcar { n: 2, frac: 0.25 }, r(-1.0, 30)),
        ];
        let c = combine(&parts);
        let want = 7.25 / 9.25;
        assert!((c.z[0] - Complex64::new(want, -want)).norm() < 1e-15);
        assert!((c.c[1] - Complex64::new(-want, want)).norm() < 1e-15);
        // A channel constant over the segments keeps its value.
        assert!((c.s[0].re - 3.0).abs() < 1e-15 && (c.c[0].im - 1.0).abs() < 1e-15);
        assert_eq!(c.health.samples, 60);
        assert_eq!(c.health.dac_zero, [30, 3]);
        // One segment: its result, bit for bit.
        assert_eq!(combine(&parts[1..2]), parts[1].1);
    }
}
