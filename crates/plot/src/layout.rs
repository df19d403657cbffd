//! Where a figure's parts go, worked out before anything is drawn: the title's size, the
//! axes and their ticks, the label areas sized from the tick labels (so nothing overlaps),
//! and room on the y axis for a legend that would otherwise hide data.

use crate::axis::AxisScale;
use crate::error::DrawError;
use crate::fast_lines::Area;
use crate::figure::Figure;
use crate::font::bold;
use crate::legend::headroom;
use plotters::prelude::*;

/// A marker's base radius, in unscaled pixels.
pub(crate) const MARKER_RADIUS: f64 = 3.5;

/// Ring sizes of the hollow-marker series, in order (times twice the base radius): rings of
/// series that coincide nest instead of covering one another, so each shows its colour.
const RING_SCALES: [f64; 4] = [1.0, 1.45, 0.7, 1.2];

/// Radius of the k-th hollow-marker series' rings for a base radius `r`.
pub(crate) fn ring_radius(k: usize, r: i32) -> i32 {
    (f64::from(2 * r) * RING_SCALES[k % RING_SCALES.len()]).round() as i32
}

/// `v` unscaled pixels at scale `s`, at least one.
pub(crate) fn px(v: f64, s: f64) -> i32 {
    (v * s).round().max(1.0) as i32
}

/// The fonts of a figure's tick labels, axis labels and legend.
pub(crate) struct Fonts<'a> {
    pub(crate) tick: TextStyle<'a>,
    pub(crate) desc: TextStyle<'a>,
    pub(crate) legend: TextStyle<'a>,
}

/// A figure's layout (pixels of the drawing area, plotters' conventions).
pub(crate) struct Layout {
    /// The title's font, shrunk to fit; `None` without a title.
    pub(crate) title: Option<TextStyle<'static>>,
    /// Left margin (also the bottom one), right margin, top margin.
    pub(crate) margins: (i32, i32, i32),
    pub(crate) x_area: i32,
    pub(crate) y_area: i32,
    pub(crate) tick_h: u32,
    pub(crate) xa: AxisScale,
    pub(crate) ya: AxisScale,
    pub(crate) x_ticks: Vec<f64>,
    pub(crate) y_ticks: Vec<f64>,
    /// The corner a grown y axis cleared for the legend; `None` when the axis did not grow.
    pub(crate) legend_at: Option<SeriesLabelPosition>,
    /// The frame's width and height less one, as plotters will lay it out.
    pub(crate) frame: (i32, i32),
}

/// The layout of `fig` in `area` at text scale `s` (supersampling included), with about
/// `nx` and `ny` ticks, for its plottable points `all`.
pub(crate) fn layout(
    area: &Area,
    fig: &Figure,
    all: &[(f64, f64)],
    s: f64,
    (nx, ny): (usize, usize),
    fonts: &Fonts,
) -> Result<Layout, DrawError> {
    let (w, h) = area.dim_in_pixel();
    let px = |v: f64| px(v, s);
    let (tick_font, desc_font, legend_font) = (&fonts.tick, &fonts.desc, &fonts.legend);
    let (left, right) = (px(18.0), px(28.0));
    // A long title (a spectrum panel's notes) shrinks to fit between the margins, where
    // plotters centres it, down to half its size, as a set's overall title does; plotters
    // would cut it off at the figure's edges. The height plotters gives a caption follows its
    // font, so the top margin takes up what the smaller font leaves: the frame stays where a
    // full-size title puts it, in line with its neighbours' in a set of panels.
    let (mut title_room, mut caption_h) = (0, 0);
    let title = if fig.title.is_empty() {
        None
    } else {
        let full = bold(20.0 * s);
        let (tw, th_full) = area.estimate_text_size(&fig.title, &full)?;
        let room = (w as i32 - left - right).max(1);
        let fit = title_scale(0.98 * f64::from(room), tw);
        let style = bold(20.0 * s * fit);
        let (_, th) = area.estimate_text_size(&fig.title, &style)?;
        title_room = caption_height(th_full) - caption_height(th);
        caption_h = caption_height(th);
        Some(style)
    };
    // Room for a "×10ⁿ" above the y axis is always kept so frames of panels line up.
    let top = px(34.0) + title_room;

    let xa = axis(all.iter().map(|p| p.0), fig.x_log, nx);
    let mut ya = axis(all.iter().map(|p| p.1), fig.y_log, ny);
    let x_ticks = xa.ticks(nx);

    // Size the label areas from the actual tick labels so nothing overlaps.
    let (_, tick_h) = area.estimate_text_size("0", tick_font)?;
    let (_, desc_h) = area.estimate_text_size("Hg", desc_font)?;
    let y_area_of = |ticks: &[f64], ya: &AxisScale| -> Result<i32, DrawError> {
        let mut y_tick_w = 0;
        for t in ticks {
            y_tick_w = y_tick_w.max(area.estimate_text_size(&ya.label(*t), tick_font)?.0);
        }
        Ok(y_tick_w as i32
            + px(12.0)
            + if fig.y_label.is_empty() {
                0
            } else {
                desc_h as i32 + px(14.0)
            })
    };
    let mut y_ticks = ya.ticks(ny);
    let mut y_area = y_area_of(&y_ticks, &ya)?;
    let x_area = tick_h as i32
        + px(14.0)
        + if fig.x_label.is_empty() {
            0
        } else {
            desc_h as i32 + px(14.0)
        };
    // When the legend would hide data in every corner, the y axis grows at one end to make
    // room for it (`legend::headroom`). The frame's size is plotters' layout: the margins (the
    // bottom one is `left`), the caption and the label areas. A grown axis' labels may be
    // wider and the frame narrower, so the growth is worked out again until they settle.
    let frame_of = |y_area: i32| {
        (
            w as i32 - left - right - y_area - 1,
            h as i32 - top - left - caption_h - x_area - 1,
        )
    };
    let radius = px(MARKER_RADIUS);
    let bare = (ya.clone(), y_ticks.clone(), y_area);
    let mut cleared = None;
    for _ in 0..3 {
        let frame = frame_of(y_area);
        if frame.0 <= 0 || frame.1 <= 0 {
            break;
        }
        let Some(bx) = legend_box(area, fig, legend_font, s, frame)? else {
            break;
        };
        // plotters' 5 px between the legend and the frame, and the largest ring's radius.
        let clear = f64::from(5 + ring_radius(1, radius) + 2);
        let clear = (clear / f64::from(frame.0), clear / f64::from(frame.1));
        let Some((grown, corner)) = headroom(all, &xa, &bare.0, bx, clear, ny) else {
            (ya, y_ticks, y_area) = bare.clone();
            cleared = None;
            break;
        };
        y_ticks = grown.ticks(ny);
        y_area = y_area_of(&y_ticks, &grown)?;
        ya = grown;
        cleared = Some(corner);
        if frame_of(y_area) == frame {
            break;
        }
    }
    Ok(Layout {
        title,
        margins: (left, right, top),
        x_area,
        y_area,
        tick_h,
        frame: frame_of(y_area),
        xa,
        ya,
        x_ticks,
        y_ticks,
        legend_at: cleared,
    })
}

/// The scale that fits a title `text_w` pixels wide at full size into `room` pixels: never
/// above full size, never below half (a longer title is cut rather than made unreadable). The
/// rule of every title, a figure's, a panel's or a set's.
pub(crate) fn title_scale(room: f64, text_w: u32) -> f64 {
    (room / f64::from(text_w.max(1))).clamp(0.5, 1.0)
}

/// The height plotters' `DrawingArea::titled` takes for a caption `text_h` high: the text and a
/// padding of min(text_h / 2, 5) above and below it.
fn caption_height(text_h: u32) -> i32 {
    let pad = (text_h / 2).min(5) as i32;
    text_h as i32 + 2 * pad
}

/// The legend box as fractions of a frame `frame` pixels wide and high: its widest label plus
/// the marker and margins, one row per named series; `None` when no series is named.
pub(crate) fn legend_box(
    area: &Area,
    fig: &Figure,
    font: &TextStyle,
    s: f64,
    frame: (i32, i32),
) -> Result<Option<(f64, f64)>, DrawError> {
    let rows = fig.series.iter().filter(|s| !s.name.is_empty()).count();
    if rows == 0 {
        return Ok(None);
    }
    let (mut label_w, mut label_h) = (0u32, 0u32);
    for se in &fig.series {
        let (w, h) = area.estimate_text_size(&se.name, font)?;
        label_w = label_w.max(w);
        label_h = label_h.max(h);
    }
    Ok(Some((
        ((label_w as f64 + 60.0 * s) / frame.0.max(1) as f64).min(1.0),
        ((rows as f64 * (label_h as f64 + 8.0 * s) + 20.0 * s) / frame.1.max(1) as f64).min(1.0),
    )))
}

/// The axis of one coordinate of the figure's plottable points.
fn axis(vals: impl Iterator<Item = f64>, log: bool, n: usize) -> AxisScale {
    if log {
        AxisScale::log_from_values(vals)
    } else {
        AxisScale::from_values(vals, n)
    }
}
