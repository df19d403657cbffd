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

/// The corner whose legend box (`box_frac`: its width and height as fractions of the plot)
/// covers the fewest data points, so the legend hides as little as possible: upper left,
/// upper right, lower left, lower right, the first on a tie.
pub(crate) fn legend_corner(
    points: &[(f64, f64)],
    xa: &AxisScale,
    ya: &AxisScale,
    box_frac: (f64, f64),
) -> SeriesLabelPosition {
    let mut best = (usize::MAX, SeriesLabelPosition::UpperLeft);
    for (pos, right, upper) in CORNERS {
        let n = covered(points, xa, ya, box_frac, right, upper);
        if n < best.0 {
            best = (n, pos);
        }
    }
    best.1
}

/// Smallest share of the grown axis the data may keep: a legend taller than this leaves the
/// axis as it is (growing it more would squash the data more than the legend hides).
const MIN_DATA_SHARE: f64 = 0.4;

/// When every corner's legend box (`box_frac`, as in [`legend_corner`]) covers a data point,
/// the y axis grown at one end so that one corner's box, widened by `clear` (fractions of the
/// plot: the legend's distance from the frame and a marker's radius), covers none: the corner
/// that needs the least growth, the first on a tie. `None` when some corner already hides
/// nothing, or when the box and its clearance take more than 1 - [`MIN_DATA_SHARE`] of the
/// plot's height. `n_ticks` sizes the grown axis' tick labels.
pub(crate) fn headroom(
    points: &[(f64, f64)],
    xa: &AxisScale,
    ya: &AxisScale,
    (bw, bh): (f64, f64),
    (cx, cy): (f64, f64),
    n_ticks: usize,
) -> Option<AxisScale> {
    let data_share = 1.0 - bh - cy;
    let hidden = |&(_, right, upper): &(SeriesLabelPosition, bool, bool)| {
        covered(points, xa, ya, (bw, bh), right, upper) > 0
    };
    if data_share < MIN_DATA_SHARE || !CORNERS.iter().all(hidden) {
        return None;
    }
    let mut best: Option<(f64, f64, f64)> = None;
    for (_, right, upper) in CORNERS {
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
        if best.is_none_or(|(span, _, _)| hi - lo < span) {
            best = Some((hi - lo, lo, hi));
        }
    }
    best.map(|(_, lo, hi)| ya.with_range(lo, hi, n_ticks))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes(pts: &[(f64, f64)]) -> (AxisScale, AxisScale) {
        (
            AxisScale::from_values(pts.iter().map(|p| p.0), 5),
            AxisScale::from_values(pts.iter().map(|p| p.1), 5),
        )
    }

    #[test]
    fn the_legend_goes_to_the_corner_it_hides_least() {
        let frame = [(0.0, 0.0), (10.0, 0.0), (0.0, 10.0), (10.0, 10.0)];
        // A cluster under the upper left: the upper right takes the legend.
        let mut pts = frame.to_vec();
        pts.extend([(0.5, 9.5), (1.0, 9.8), (1.5, 9.0)]);
        let (xa, ya) = axes(&pts);
        assert_eq!(
            legend_corner(&pts, &xa, &ya, (0.4, 0.2)),
            SeriesLabelPosition::UpperRight
        );
        // Both upper corners busy, the lower left too: the lower right.
        pts.extend([(9.5, 9.5), (9.0, 9.8), (0.5, 0.5), (1.0, 1.0)]);
        let (xa, ya) = axes(&pts);
        assert_eq!(
            legend_corner(&pts, &xa, &ya, (0.4, 0.2)),
            SeriesLabelPosition::LowerRight
        );
        // Nothing to hide: the upper left.
        let (xa, ya) = axes(&frame);
        assert_eq!(
            legend_corner(&[], &xa, &ya, (0.4, 0.2)),
            SeriesLabelPosition::UpperLeft
        );
    }

    #[test]
    fn no_headroom_while_a_corner_is_free() {
        // Points in three corners only: the lower right is free, the axis stays.
        let pts = [(0.0, 0.0), (0.0, 10.0), (10.0, 10.0), (5.0, 5.0)];
        let (xa, ya) = axes(&pts);
        assert_eq!(headroom(&pts, &xa, &ya, (0.3, 0.2), (0.02, 0.02), 5), None);
    }

    /// Seeded clouds filling the plot: where every corner is busy, the grown axis leaves one corner's
    /// widened box empty, grows at one end only and by no more than the box needs; the
    /// box's corner then is the one `legend_corner` picks.
    #[test]
    fn headroom_clears_one_corner_by_the_least_growth() {
        let mut next = crate::seeded(0x5eed_1e9e);
        let mut grown_cases = 0;
        for case in 0..400 {
            let n = 4 + next(60) as usize;
            let mut pts: Vec<(f64, f64)> = (0..n)
                .map(|_| (f64::from(next(1000)), f64::from(next(1000)) - 300.0))
                .collect();
            // A point near each corner, at its own depth, so the corners need unequal growth.
            let mut near = |end: f64, sign: f64| end + sign * f64::from(next(150));
            pts.extend([
                (near(0.0, 1.0), near(-300.0, 1.0)),
                (near(999.0, -1.0), near(-300.0, 1.0)),
                (near(0.0, 1.0), near(699.0, -1.0)),
                (near(999.0, -1.0), near(699.0, -1.0)),
            ]);
            let (xa, ya) = axes(&pts);
            let bx = (
                0.1 + f64::from(next(40)) / 100.0,
                0.05 + f64::from(next(30)) / 100.0,
            );
            // A clearance of at least 1 %: the farthest point lands on the widened box's edge.
            let clear = (0.01 * f64::from(next(3)), 0.01 * f64::from(1 + next(3)));
            let Some(grown) = headroom(&pts, &xa, &ya, bx, clear, 5) else {
                // Only a free corner or a box too tall for the rule leaves the axis alone.
                let free = CORNERS
                    .iter()
                    .any(|(_, right, upper)| covered(&pts, &xa, &ya, bx, *right, *upper) == 0);
                assert!(free || 1.0 - bx.1 - clear.1 < MIN_DATA_SHARE, "case {case}");
                continue;
            };
            grown_cases += 1;
            assert!(grown.lo <= ya.lo && grown.hi >= ya.hi, "case {case}");
            assert!(
                grown.lo == ya.lo || grown.hi == ya.hi,
                "case {case}: both ends"
            );
            // A widened box, a hair shorter than the clearance, covers nothing in some corner.
            let widened = (bx.0 + clear.0, bx.1 + clear.1 - 1e-9);
            let cleared = CORNERS
                .iter()
                .any(|(_, right, upper)| covered(&pts, &xa, &grown, widened, *right, *upper) == 0);
            assert!(cleared, "case {case}: no corner cleared");
            // No smaller growth clears a corner: 1 % less at the grown end leaves each corner
            // hiding a point.
            let span = grown.hi - grown.lo;
            let less = span - 0.01 * (span - (ya.hi - ya.lo));
            let shrunk = if grown.hi > ya.hi {
                ya.with_range(ya.lo, ya.lo + less, 5)
            } else {
                ya.with_range(ya.hi - less, ya.hi, 5)
            };
            let still_hidden = CORNERS.iter().all(|(_, right, upper)| {
                covered(
                    &pts,
                    &xa,
                    &shrunk,
                    (bx.0 + clear.0, bx.1 + clear.1),
                    *right,
                    *upper,
                ) > 0
            });
            assert!(still_hidden, "case {case}: growth larger than needed");
            // The corner then picked hides nothing.
            let pick = legend_corner(&pts, &xa, &grown, bx);
            let (_, right, upper) = CORNERS.iter().find(|c| c.0 == pick).unwrap();
            assert_eq!(
                covered(&pts, &xa, &grown, bx, *right, *upper),
                0,
                "case {case}"
            );
        }
        assert!(grown_cases >= 100, "only {grown_cases} cases grew the axis");
    }
}
