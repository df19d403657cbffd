//! Where a figure's legend goes: the corner whose box hides the fewest data points, and, when
//! every corner's box would hide some, room made for it at one end of the y axis.

use crate::axis::AxisScale;
use plotters::prelude::SeriesLabelPosition;

/// The corners in the order they are preferred on a tie: (position, right, upper).
const CORNERS: [(SeriesLabelPosition, bool, bool); 4] = [
    (SeriesLabelPosition::UpperLeft, false, true),
    (SeriesLabelPosition::UpperRight, true, true),
    (SeriesLabelPosition::LowerLeft, false, false),
    (SeriesLabelPosition::LowerRight, true, false),
];

/// Where `v` falls on axis `a`, as a fraction of the plot from its low end.
fn frac(v: f64, a: &AxisScale) -> f64 {
    (a.map(v) - a.lo) / (a.hi - a.lo)
}

/// Whether the fraction `f` lies in the band `width` wide at the high (`high`) or low end.
fn in_band(f: f64, high: bool, width: f64) -> bool {
    if high {
        f >= 1.0 - width
    } else {
        f <= width
    }
}

/// How many of `points` a box of `(bw, bh)` (fractions of the plot) in a corner covers.
fn covered(
    points: &[(f64, f64)],
    xa: &AxisScale,
    ya: &AxisScale,
    (bw, bh): (f64, f64),
    right: bool,
    upper: bool,
) -> usize {
    points
        .iter()
        .filter(|&&(x, y)| in_band(frac(x, xa), right, bw) && in_band(frac(y, ya), upper, bh))
        .count()
}

/// The corner whose box (`box_frac`) covers the fewest of `points`, the first on a tie, and
/// how many it covers.
fn fewest_covered(
    points: &[(f64, f64)],
    xa: &AxisScale,
    ya: &AxisScale,
    box_frac: (f64, f64),
) -> (SeriesLabelPosition, usize) {
    let mut best = (SeriesLabelPosition::UpperLeft, usize::MAX);
    for (pos, right, upper) in CORNERS {
        let n = covered(points, xa, ya, box_frac, right, upper);
        if n < best.1 {
            best = (pos, n);
        }
    }
    best
}

/// The corner whose legend box (`box_frac`: its width and height as fractions of the plot)
/// covers the fewest data points, so the legend hides as little as possible: upper left,
/// upper right, lower left, lower right, the first on a tie.
pub(crate) fn legend_corner(
    points: &[(f64, f64)],
    xa: &AxisScale,
    ya: &AxisScale,
    box_frac: (f64, f64),
) -> SeriesLabelPosition {
    fewest_covered(points, xa, ya, box_frac).0
}

/// Smallest share of the grown axis the data may keep: a legend taller than the rest leaves
/// the axis as it is (growing it more would squash the data more than the legend hides).
pub(crate) const MIN_DATA_SHARE: f64 = 0.4;

/// When every corner's legend box (`box_frac`, as in [`legend_corner`]) covers a data point:
/// the y axis grown at one end, by the least that leaves one corner's box, widened by `clear`
/// (fractions of the plot: the legend's gap to the frame and a marker's radius), covering
/// none, and that corner (the first on a tie). `None` when some corner already covers nothing,
/// or when box and clearance take more than 1 - [`MIN_DATA_SHARE`] of the plot's height.
/// `n_ticks` sizes the grown axis' tick labels.
pub(crate) fn headroom(
    points: &[(f64, f64)],
    xa: &AxisScale,
    ya: &AxisScale,
    (bw, bh): (f64, f64),
    (cx, cy): (f64, f64),
    n_ticks: usize,
) -> Option<(AxisScale, SeriesLabelPosition)> {
    let data_share = 1.0 - bh - cy;
    if data_share < MIN_DATA_SHARE || fewest_covered(points, xa, ya, (bw, bh)).1 == 0 {
        return None;
    }
    let mut best: Option<(f64, f64, f64, SeriesLabelPosition)> = None;
    for (pos, right, upper) in CORNERS {
        // The plotted values under the widened box's side of the plot.
        let ys = points
            .iter()
            .filter(|p| in_band(frac(p.0, xa), right, bw + cx))
            .map(|p| ya.map(p.1));
        // The new end puts the farthest of them at `data_share` of the grown span.
        let (lo, hi) = if upper {
            let top = ys.fold(ya.lo, f64::max);
            (ya.lo, ya.hi.max(ya.lo + (top - ya.lo) / data_share))
        } else {
            let bottom = ys.fold(ya.hi, f64::min);
            (ya.lo.min(ya.hi - (ya.hi - bottom) / data_share), ya.hi)
        };
        if best.as_ref().is_none_or(|b| hi - lo < b.0) {
            best = Some((hi - lo, lo, hi, pos));
        }
    }
    best.map(|(_, lo, hi, pos)| (ya.with_range(lo, hi, n_ticks), pos))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes(pts: &[(f64, f64)], y_log: bool) -> (AxisScale, AxisScale) {
        let ys = pts.iter().map(|p| p.1);
        (
            AxisScale::from_values(pts.iter().map(|p| p.0), 5),
            if y_log {
                AxisScale::log_from_values(ys)
            } else {
                AxisScale::from_values(ys, 5)
            },
        )
    }

    /// Written out here, not taken from the code under test: where `v` falls on `a`, from 0
    /// at its low end to 1 at its high end.
    fn at(a: &AxisScale, v: f64) -> f64 {
        let plotted = if a.log {
            v.log10()
        } else {
            v / 10f64.powi(a.exp10)
        };
        (plotted - a.lo) / (a.hi - a.lo)
    }

    /// Whether a box `(bw, bh)` in the corner (`right`, `upper`) covers none of `pts`.
    fn corner_free(
        pts: &[(f64, f64)],
        (xa, ya): (&AxisScale, &AxisScale),
        (bw, bh): (f64, f64),
        (right, upper): (bool, bool),
    ) -> bool {
        !pts.iter().any(|&(x, y)| {
            let (fx, fy) = (at(xa, x), at(ya, y));
            (if right { fx >= 1.0 - bw } else { fx <= bw })
                && (if upper { fy >= 1.0 - bh } else { fy <= bh })
        })
    }

    fn side(pos: &SeriesLabelPosition) -> (bool, bool) {
        match pos {
            SeriesLabelPosition::UpperLeft => (false, true),
            SeriesLabelPosition::UpperRight => (true, true),
            SeriesLabelPosition::LowerLeft => (false, false),
            _ => (true, false),
        }
    }

    #[test]
    fn the_legend_goes_to_the_corner_it_hides_least() {
        let frame = [(0.0, 0.0), (10.0, 0.0), (0.0, 10.0), (10.0, 10.0)];
        // A cluster under the upper left: the upper right takes the legend.
        let mut pts = frame.to_vec();
        pts.extend([(0.5, 9.5), (1.0, 9.8), (1.5, 9.0)]);
        let (xa, ya) = axes(&pts, false);
        assert_eq!(
            legend_corner(&pts, &xa, &ya, (0.4, 0.2)),
            SeriesLabelPosition::UpperRight
        );
        // Both upper corners busy, the lower left too: the lower right.
        pts.extend([(9.5, 9.5), (9.0, 9.8), (0.5, 0.5), (1.0, 1.0)]);
        let (xa, ya) = axes(&pts, false);
        assert_eq!(
            legend_corner(&pts, &xa, &ya, (0.4, 0.2)),
            SeriesLabelPosition::LowerRight
        );
        // Nothing to hide: the upper left.
        let (xa, ya) = axes(&frame, false);
        assert_eq!(
            legend_corner(&[], &xa, &ya, (0.4, 0.2)),
            SeriesLabelPosition::UpperLeft
        );
    }

    #[test]
    fn no_headroom_while_a_corner_is_free() {
        // Points in three corners only: the lower right is free, the axis stays.
        let pts = [(0.0, 0.0), (0.0, 10.0), (10.0, 10.0), (5.0, 5.0)];
        let (xa, ya) = axes(&pts, false);
        assert_eq!(headroom(&pts, &xa, &ya, (0.3, 0.2), (0.02, 0.02), 5), None);
    }

    /// The least span, found by bisection, at which the widened box in a corner covers no
    /// point once the axis grows at that corner's end.
    fn least_span(
        pts: &[(f64, f64)],
        (xa, ya): (&AxisScale, &AxisScale),
        widened: (f64, f64),
        (right, upper): (bool, bool),
    ) -> f64 {
        let grown = |span: f64| {
            if upper {
                ya.with_range(ya.lo, ya.lo + span, 5)
            } else {
                ya.with_range(ya.hi - span, ya.hi, 5)
            }
        };
        let free = |span: f64| corner_free(pts, (xa, &grown(span)), widened, (right, upper));
        let (mut lo, mut hi) = (ya.hi - ya.lo, 100.0 * (ya.hi - ya.lo));
        assert!(free(hi));
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if free(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }

    /// Seeded clouds on linear, scaled (x 1e-9) and log axes: where every corner is busy,
    /// the axis grows at the cleared corner's end only, its widened box then covers nothing,
    /// the growth is the least any corner needs (bisected corner by corner), and
    /// `legend_corner` agrees that corner is free.
    #[test]
    fn headroom_clears_one_corner_by_the_least_growth() {
        let mut next = crate::seeded(0x5eed_1e9e);
        let mut grown_cases = [0; 3];
        for case in 0..600 {
            let kind = case % 3;
            // y from a uniform draw in 0..1000 (-300..699 before scaling).
            let y_of = |u: i32| match kind {
                0 => f64::from(u) - 300.0,
                1 => (f64::from(u) - 300.0) * 1e-9,
                _ => 10f64.powf(f64::from(u) / 250.0 - 2.0),
            };
            let n = 4 + next(60) as usize;
            let mut pts: Vec<(f64, f64)> = (0..n)
                .map(|_| (f64::from(next(1000)), y_of(next(1000))))
                .collect();
            // A point near each corner, at its own depth, so the corners need unequal growth.
            for (x, u) in [(0, 0), (999, 0), (0, 999), (999, 999)] {
                let toward = |e: i32, d: i32| if e == 0 { d } else { e - d };
                pts.push((f64::from(toward(x, next(150))), y_of(toward(u, next(150)))));
            }
            let (xa, ya) = axes(&pts, kind == 2);
            let bx = (
                0.1 + f64::from(next(40)) / 100.0,
                0.05 + f64::from(next(30)) / 100.0,
            );
            // A clearance of at least 1 %: the farthest point lands on the widened box's edge.
            let clear = (0.01 * f64::from(next(3)), 0.01 * f64::from(1 + next(3)));
            let corners = [(false, true), (true, true), (false, false), (true, false)];
            let Some((grown, pos)) = headroom(&pts, &xa, &ya, bx, clear, 5) else {
                // Only a free corner or a box too tall for the rule leaves the axis alone.
                let free = corners
                    .iter()
                    .any(|c| corner_free(&pts, (&xa, &ya), bx, *c));
                assert!(free || 1.0 - bx.1 - clear.1 < MIN_DATA_SHARE, "case {case}");
                continue;
            };
            grown_cases[kind] += 1;
            let (right, upper) = side(&pos);
            assert_eq!((grown.log, grown.exp10), (ya.log, ya.exp10), "case {case}");
            if upper {
                assert!(grown.lo == ya.lo && grown.hi > ya.hi, "case {case}");
            } else {
                assert!(grown.lo < ya.lo && grown.hi == ya.hi, "case {case}");
            }
            // The widened box, a hair shorter than the clearance, covers nothing there.
            let widened = (bx.0 + clear.0, bx.1 + clear.1 - 1e-9);
            assert!(
                corner_free(&pts, (&xa, &grown), widened, (right, upper)),
                "case {case}: {pos:?} not cleared"
            );
            // No corner clears with less.
            let widened = (bx.0 + clear.0, bx.1 + clear.1);
            let least = corners
                .iter()
                .map(|c| least_span(&pts, (&xa, &ya), widened, *c))
                .fold(f64::INFINITY, f64::min);
            let span = grown.hi - grown.lo;
            assert!(
                span <= least * (1.0 + 1e-9),
                "case {case}: span {span}, {least} would do"
            );
            assert!(
                span >= least * (1.0 - 1e-6),
                "case {case}: {span} < {least}"
            );
            let pick = legend_corner(&pts, &xa, &grown, bx);
            assert!(
                corner_free(&pts, (&xa, &grown), bx, side(&pick)),
                "case {case}"
            );
        }
        assert!(
            grown_cases.iter().all(|&n| n >= 50),
            "cases that grew the axis, linear / scaled / log: {grown_cases:?}"
        );
    }
}
