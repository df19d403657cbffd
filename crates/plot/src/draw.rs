//! Drawing one figure into a drawing area: axes (linear or log), series, markers, legend.

use crate::axis::AxisScale;
use crate::error::DrawError;
use crate::fast_lines::Area;
use crate::figure::{Figure, Series, SeriesStyle, PALETTE};
use crate::font::text;
use crate::layout::{layout, legend_box, px, ring_radius, Fonts, Layout, MARKER_RADIUS};
use crate::legend::legend_corner;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

type DrawResult = Result<(), DrawError>;

/// A linear coordinate over `lo..hi` whose ticks are given (plotters' own choice of round
/// steps cannot be told to keep to whole decades on a log axis).
struct Ticked {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        RangedCoordf64::from(self.lo..self.hi).map(v, limit)
    }
    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.max_num_points() == 0 {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }
    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Text and line scale for an area: 1 at the default 900 x 650 px; shrinks little in panels
/// (printed figures keep legible text) and is capped for huge images.
pub(crate) fn text_scale(w: u32, h: u32) -> f64 {
    ((w as f64 * h as f64) / (900.0 * 650.0))
        .sqrt()
        .clamp(0.85, 2.0)
}

/// The rank of series `i` among the figure's series of its own style (0 for the first).
fn rank(fig: &Figure, i: usize) -> usize {
    let style = fig.series[i].style;
    fig.series[..i].iter().filter(|s| s.style == style).count()
}

/// Size of the k-th filled-marker series' markers for a base radius `r`: each shape a little
/// smaller than the one before, so a later series over an earlier one leaves a visible rim.
fn marker_radius(k: usize, r: i32) -> i32 {
    (r as f64 * [1.25, 1.0, 0.8, 0.9][k % 4]).round().max(1.0) as i32
}

/// Vertices of the k-th marker shape around (0, 0) (k % 4: 1 triangle, 2 square, 3 diamond;
/// 0, the circle, is drawn as a circle).
fn marker_polygon(k: usize, r: i32) -> Vec<(i32, i32)> {
    match k % 4 {
        1 => {
            let t = r + r / 3;
            vec![(0, -t), (t, t), (-t, t)]
        }
        2 => vec![(-r, -r), (r, -r), (r, r), (-r, r)],
        _ => vec![(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)],
    }
}

/// Draws one figure filling `area`: title, framed axes with grid, tick labels, axis labels with
/// the scale exponent (if any) at the axis end, series (lines first, then filled markers, then
/// hollow ones, so no marker hides under a line), markers, legend. `ss` is the supersampling
/// factor: every length is multiplied by it.
pub(crate) fn draw_figure(area: &Area, fig: &Figure, ss: f64) -> DrawResult {
    let (w, h) = area.dim_in_pixel();
    let (lw_px, lh_px) = (w as f64 / ss, h as f64 / ss);
    let s = text_scale(lw_px as u32, lh_px as u32) * ss;
    let px = |v: f64| px(v, s);
    let fonts = Fonts {
        tick: text(15.0 * s),
        desc: text(18.0 * s),
        legend: text(15.0 * s),
    };
    let nx = (lw_px / 110.0).round().clamp(3.0, 10.0) as usize;
    let ny = (lh_px / 70.0).round().clamp(3.0, 10.0) as usize;

    let plottable = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    let finite = |s: &Series| {
        s.xs.iter()
            .zip(&s.ys)
            .filter(|(x, y)| plottable(**x, fig.x_log) && plottable(**y, fig.y_log))
            .map(|(&x, &y)| (x, y))
            .collect::<Vec<_>>()
    };
    let all: Vec<(f64, f64)> = fig.series.iter().flat_map(finite).collect();
    let Layout {
        title,
        margins: (left, right, top),
        x_area,
        y_area,
        tick_h,
        xa,
        ya,
        x_ticks,
        y_ticks,
        legend_at,
        frame,
    } = layout(area, fig, &all, s, (nx, ny), &fonts)?;
    let Fonts {
        tick: tick_font,
        desc: desc_font,
        legend: legend_font,
    } = fonts;
    let (nx, ny) = (x_ticks.len(), y_ticks.len());
    let y_exp = ya.exponent_text();
    let x_exp = xa.exponent_text();

    let mut cb = ChartBuilder::on(area);
    cb.margin(left)
        .margin_right(right)
        .margin_top(top)
        .x_label_area_size(x_area)
        .y_label_area_size(y_area);
    if let Some(style) = title {
        cb.caption(&fig.title, style);
    }
    let mut chart = cb.build_cartesian_2d(
        Ticked {
            lo: xa.lo,
            hi: xa.hi,
            ticks: x_ticks,
        },
        Ticked {
            lo: ya.lo,
            hi: ya.hi,
            ticks: y_ticks,
        },
    )?;

    let xf = |v: &f64| xa.label(*v);
    let yf = |v: &f64| ya.label(*v);
    let thin = px(1.0) as u32;
    let grid = RGBColor(222, 222, 222);
    chart
        .configure_mesh()
        .x_labels(nx)
        .y_labels(ny)
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .x_desc(fig.x_label.as_str())
        .y_desc(fig.y_label.as_str())
        .label_style(tick_font.clone())
        .axis_desc_style(desc_font)
        .bold_line_style(grid.stroke_width(thin))
        // No light lines at all: drawn transparent they still cost a blend per pixel.
        .max_light_lines(0)
        .axis_style(BLACK.stroke_width(thin))
        .set_all_tick_mark_size(px(5.0))
        .draw()?;
    // Minor grid of a log axis: 2..9 times each decade, fainter than the decades.
    let minor = RGBColor(238, 238, 238).stroke_width(thin);
    for (a, vertical) in [(&xa, true), (&ya, false)] {
        if !a.log || a.hi - a.lo > 12.0 {
            continue;
        }
        for d in a.lo.floor() as i32..=a.hi.ceil() as i32 {
            for m in 2..10 {
                let v = f64::from(d) + f64::from(m).log10();
                if v <= a.lo || v >= a.hi {
                    continue;
                }
                let seg = if vertical {
                    vec![(v, ya.lo), (v, ya.hi)]
                } else {
                    vec![(xa.lo, v), (xa.hi, v)]
                };
                chart.draw_series(std::iter::once(PathElement::new(seg, minor)))?;
            }
        }
    }

    let lw = px(2.0) as u32;
    let radius = px(MARKER_RADIUS);
    let glyph_w = px(24.0);
    let pts = |series: &Series| -> Vec<(f64, f64)> {
        series
            .xs
            .iter()
            .zip(&series.ys)
            .map(|(&x, &y)| (xa.map(x), ya.map(y)))
            .collect()
    };
    // Layers: lines, filled markers, hollow markers; within a layer, series order.
    for layer in 0..3 {
        for (i, series) in fig.series.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let v = pts(series);
            let ok = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
            match (layer, series.style) {
                (1, SeriesStyle::Points) => {
                    let k = rank(fig, i);
                    let r = marker_radius(k, radius);
                    let fill = color.filled();
                    if k.is_multiple_of(4) {
                        chart.draw_series(v.iter().filter(ok).map(|&p| Circle::new(p, r, fill)))?;
                    } else {
                        let shape = marker_polygon(k, r);
                        chart.draw_series(
                            v.iter()
                                .filter(ok)
                                .map(|&p| EmptyElement::at(p) + Polygon::new(shape.clone(), fill)),
                        )?;
                    }
                }
                (2, SeriesStyle::OpenPoints) => {
                    let ring = color.stroke_width(lw.max(2));
                    let r = ring_radius(rank(fig, i), radius);
                    chart.draw_series(v.iter().filter(ok).map(|&p| Circle::new(p, r, ring)))?;
                }
                (0, SeriesStyle::Line | SeriesStyle::DashedLine) => {
                    let line = color.stroke_width(lw);
                    // Lines break at non-finite points instead of bridging the gap.
                    for run in v
                        .split(|(x, y)| !(x.is_finite() && y.is_finite()))
                        .filter(|r| !r.is_empty())
                    {
                        if run.len() == 1 {
                            // An isolated point has no segment to draw: show it as a dot.
                            chart.draw_series(std::iter::once(Circle::new(
                                run[0],
                                lw as i32 + 1,
                                color.filled(),
                            )))?;
                        } else if series.style == SeriesStyle::Line {
                            chart.draw_series(LineSeries::new(run.iter().copied(), line))?;
                        } else {
                            chart.draw_series(DashedLineSeries::new(
                                run.iter().copied(),
                                px(9.0),
                                px(6.0),
                                line,
                            ))?;
                        }
                    }
                }
                _ => {}
            }
        }
    }

    // Legend entries in series order (empty series carry them, whatever the data looked like).
    for (i, series) in fig.series.iter().enumerate() {
        if series.name.is_empty() {
            continue;
        }
        let color = PALETTE[i % PALETTE.len()];
        let line = color.stroke_width(lw);
        let anno = chart.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?;
        let anno = anno.label(series.name.as_str());
        match series.style {
            SeriesStyle::Points => {
                let k = rank(fig, i);
                let r = marker_radius(k, radius);
                let shape: Vec<(i32, i32)> = if k.is_multiple_of(4) {
                    // A polygon of many sides stands for the circle in the legend.
                    (0..24)
                        .map(|j| {
                            let a = std::f64::consts::TAU * f64::from(j) / 24.0;
                            (
                                (r as f64 * a.cos()).round() as i32,
                                (r as f64 * a.sin()).round() as i32,
                            )
                        })
                        .collect()
                } else {
                    marker_polygon(k, r)
                };
                let shape: Vec<(i32, i32)> = shape
                    .into_iter()
                    .map(|(x, y)| (x + glyph_w / 2, y))
                    .collect();
                anno.legend(move |(x, y)| {
                    EmptyElement::at((x, y)) + Polygon::new(shape.clone(), color.filled())
                })
            }
            SeriesStyle::OpenPoints => {
                let r = ring_radius(rank(fig, i), radius);
                anno.legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + Circle::new((glyph_w / 2, 0), r, color.stroke_width(lw.max(2)))
                })
            }
            SeriesStyle::Line => anno.legend(move |(x, y)| {
                EmptyElement::at((x, y)) + PathElement::new(vec![(0, 0), (glyph_w, 0)], line)
            }),
            SeriesStyle::DashedLine => anno.legend(move |(x, y)| {
                let d = glyph_w * 3 / 8;
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (d, 0)], line)
                    + PathElement::new(vec![(glyph_w - d, 0), (glyph_w, 0)], line)
            }),
        };
    }

    // Close the frame (plotters draws only the left and bottom axes) and add scale exponents.
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let (bx, by) = area.get_base_pixel();
    let (x0, x1, y0, y1) = (
        xr.start - bx,
        xr.end - 1 - bx,
        yr.start - by,
        yr.end - 1 - by,
    );
    // The layout is plotters' own.
    debug_assert!(frame.0 <= 0 || frame.1 <= 0 || frame == (x1 - x0, y1 - y0));
    area.draw(&Rectangle::new(
        [(x0, y0), (x1, y1)],
        BLACK.stroke_width(thin),
    ))?;
    if let Some(t) = y_exp {
        area.draw(&Text::new(
            t,
            (x0, y0 - px(8.0) - tick_h as i32),
            tick_font.clone(),
        ))?;
    }
    if let Some(t) = x_exp {
        let (tw, _) = area.estimate_text_size(&t, &tick_font)?;
        area.draw(&Text::new(
            t,
            (x1 - tw as i32, y1 + px(12.0) + tick_h as i32),
            tick_font.clone(),
        ))?;
    }
    draw_markers(area, fig, &xa, (x0, x1, y0, y1), s)?;

    if let Some(legend_box) = legend_box(area, fig, &legend_font, s, (x1 - x0, y1 - y0))? {
        chart
            .configure_series_labels()
            .position(legend_at.unwrap_or_else(|| legend_corner(&all, &xa, &ya, legend_box)))
            .margin(px(10.0))
            .legend_area_size(glyph_w + px(10.0))
            .label_font(legend_font)
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(90, 90, 90))
            .draw()?;
    }
    Ok(())
}

/// Dashed grey vertical lines at the figure's markers inside the frame `(x0, x1, y0, y1)`,
/// each labelled near the bottom; labels step up so neighbours do not overwrite each other,
/// and sit left of their line in the right third of the plot.
fn draw_markers(
    area: &Area,
    fig: &Figure,
    xa: &AxisScale,
    (x0, x1, y0, y1): (i32, i32, i32, i32),
    s: f64,
) -> DrawResult {
    let px = |v: f64| (v * s).round().max(1.0) as i32;
    let colour = RGBColor(70, 70, 70);
    let font = text(14.0 * s).color(&colour);
    let (_, th) = area.estimate_text_size("Hg", &font)?;
    let mut placed: Vec<(i32, i32)> = Vec::new();
    for m in &fig.markers {
        let u = (xa.map(m.x) - xa.lo) / (xa.hi - xa.lo);
        if !(0.0..=1.0).contains(&u) {
            continue;
        }
        let x = x0 + (u * f64::from(x1 - x0)).round() as i32;
        let (dash, gap) = (px(5.0), px(4.0));
        let mut y = y0;
        while y < y1 {
            let e = (y + dash).min(y1);
            area.draw(&PathElement::new(
                vec![(x, y), (x, e)],
                colour.stroke_width(px(1.0) as u32),
            ))?;
            y = e + gap;
        }
        if m.label.is_empty() {
            continue;
        }
        let (tw, _) = area.estimate_text_size(&m.label, &font)?;
        let tx = if u > 0.66 {
            x - tw as i32 - px(4.0)
        } else {
            x + px(4.0)
        };
        // The first row free of labels overlapping this one horizontally.
        let mut row = 0;
        while placed
            .iter()
            .any(|&(r, px0)| r == row && (px0 - tx).abs() < tw as i32 + px(6.0))
        {
            row += 1;
        }
        placed.push((row, tx));
        // Rows stack up from the bottom of the plot, away from peaks and the legend.
        let ty = y1 - px(4.0) - th as i32 - row * (th as i32 + px(2.0));
        area.draw(&Rectangle::new(
            [
                (tx - px(1.0), ty),
                (tx + tw as i32 + px(1.0), ty + th as i32),
            ],
            WHITE.mix(0.8).filled(),
        ))?;
        area.draw(&Text::new(m.label.clone(), (tx, ty), font.clone()))?;
    }
    Ok(())
}
