//! Drawing figures with plotters' bitmap backend and writing them atomically as PNG.

use crate::axis::AxisScale;
use crate::figure::{Figure, SeriesStyle, PALETTE};
use crate::font::{bold, ensure_font, text};
use crate::PlotError;
use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Smallest accepted image (or panel) side: below this axes and labels cannot fit.
pub const MIN_SIDE_PX: u32 = 64;
/// Largest accepted image side (bounds the RGB buffer to 768 MiB).
pub const MAX_SIDE_PX: u32 = 16_384;

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult = Result<(), Box<dyn std::error::Error + Send + Sync>>;

fn check_target(path: &Path, w: u32, h: u32) -> Result<(), PlotError> {
    let ok = |s: u32| (MIN_SIDE_PX..=MAX_SIDE_PX).contains(&s);
    if !ok(w) || !ok(h) {
        return Err(PlotError::InvalidSize {
            path: path.to_path_buf(),
            width_px: w,
            height_px: h,
            max: MAX_SIDE_PX,
        });
    }
    let png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        return Err(PlotError::InvalidLayout {
            path: path.to_path_buf(),
            reason: "the file name must end in .png (the encoder picks the format from it)".into(),
        });
    }
    Ok(())
}

/// Renders `fig` alone into a `width_px` x `height_px` PNG at `path`, atomically (temporary
/// `.png` in the same directory, renamed when complete). Axes span the finite data with a 5 %
/// margin; non-finite points are skipped; empty or constant data get a sensible span.
pub fn render_png(fig: &Figure, path: &Path) -> Result<(), PlotError> {
    check_target(path, fig.width_px, fig.height_px)?;
    ensure_font()?;
    gyroemu_io::write_atomic_via(path, |tmp| {
        let root = BitMapBackend::new(tmp, (fig.width_px, fig.height_px)).into_drawing_area();
        root.fill(&WHITE)?;
        draw_figure(&root, fig)?;
        root.present()?;
        Ok(())
    })?;
    Ok(())
}

/// Renders `fig` into memory: `width_px * height_px * 3` bytes, RGB, row-major from the top
/// left. Same drawing as [`render_png`]; for embedding, inspecting and testing without a file.
pub fn render_rgb(fig: &Figure) -> Result<Vec<u8>, PlotError> {
    check_target(Path::new("memory.png"), fig.width_px, fig.height_px)?;
    ensure_font()?;
    let mut buf = vec![255u8; fig.width_px as usize * fig.height_px as usize * 3];
    let drawn: DrawResult = (|| {
        let root =
            BitMapBackend::with_buffer(&mut buf, (fig.width_px, fig.height_px)).into_drawing_area();
        draw_figure(&root, fig)?;
        root.present()?;
        Ok(())
    })();
    drawn.map_err(|source| gyroemu_io::IoError::Producer {
        path: "<memory>".into(),
        source,
    })?;
    Ok(buf)
}

/// Renders `panels` in a grid of `cols` columns (rows as needed, filled row by row) under an
/// overall `title`, into one `width_px` x `height_px` PNG at `path`, atomically. Each panel's
/// own `width_px`/`height_px` are ignored; its text scales with the cell size.
pub fn render_panels_png(
    title: &str,
    panels: &[Figure],
    cols: usize,
    width_px: u32,
    height_px: u32,
    path: &Path,
) -> Result<(), PlotError> {
    check_target(path, width_px, height_px)?;
    if cols == 0 {
        return Err(PlotError::InvalidLayout {
            path: path.to_path_buf(),
            reason: "zero columns requested".into(),
        });
    }
    let rows = panels.len().div_ceil(cols).max(1);
    let (cell_w, cell_h) = (width_px as usize / cols, height_px as usize / rows);
    if cell_w < 2 * MIN_SIDE_PX as usize || cell_h < 2 * MIN_SIDE_PX as usize {
        return Err(PlotError::InvalidLayout {
            path: path.to_path_buf(),
            reason: format!(
                "{rows} x {cols} panels give {cell_w} x {cell_h} px cells, below {} px per side",
                2 * MIN_SIDE_PX
            ),
        });
    }
    ensure_font()?;
    gyroemu_io::write_atomic_via(path, |tmp| {
        let root = BitMapBackend::new(tmp, (width_px, height_px)).into_drawing_area();
        root.fill(&WHITE)?;
        let body = if title.is_empty() {
            root.clone()
        } else {
            let s = text_scale(width_px, height_px);
            root.margin(px_round(10.0 * s), 0, 0, 0)
                .titled(title, bold(24.0 * s))?
        };
        for (cell, fig) in body.split_evenly((rows, cols)).iter().zip(panels) {
            draw_figure(cell, fig)?;
        }
        root.present()?;
        Ok(())
    })?;
    Ok(())
}

/// Text and line scale for an area: 1 at the default 900 x 650 px; shrinks little in panels
/// (printed figures keep legible text) and is capped for huge images.
fn text_scale(w: u32, h: u32) -> f64 {
    ((w as f64 * h as f64) / (900.0 * 650.0))
        .sqrt()
        .clamp(0.85, 2.0)
}

fn px_round(v: f64) -> i32 {
    v.round() as i32
}

/// Draws one figure filling `area`: title, framed axes with grid, tick labels, axis labels with
/// the scale exponent (if any) at the axis end, series, legend in the upper left.
/// The upper corner whose quarter of the plot holds fewer data points (upper left on a tie),
/// so the legend hides as little as possible.
fn legend_corner(points: &[(f64, f64)], xa: &AxisScale, ya: &AxisScale) -> SeriesLabelPosition {
    let frac = |v: f64, a: &AxisScale| (a.map(v) - a.lo) / (a.hi - a.lo);
    let (mut left, mut right) = (0usize, 0usize);
    for &(x, y) in points {
        if frac(y, ya) > 0.5 {
            if frac(x, xa) < 0.5 {
                left += 1;
            } else {
                right += 1;
            }
        }
    }
    if right < left {
        SeriesLabelPosition::UpperRight
    } else {
        SeriesLabelPosition::UpperLeft
    }
}

fn draw_figure(area: &Area, fig: &Figure) -> DrawResult {
    let (w, h) = area.dim_in_pixel();
    let s = text_scale(w, h);
    let px = |v: f64| (v * s).round().max(1.0) as i32;
    let (tick_font, desc_font, legend_font) = (text(15.0 * s), text(18.0 * s), text(15.0 * s));
    let nx = (w as f64 / 110.0).round().clamp(3.0, 10.0) as usize;
    let ny = (h as f64 / 70.0).round().clamp(3.0, 10.0) as usize;

    let finite = |s: &crate::Series| {
        s.xs.iter()
            .zip(&s.ys)
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|(&x, &y)| (x, y))
            .collect::<Vec<_>>()
    };
    let all: Vec<(f64, f64)> = fig.series.iter().flat_map(finite).collect();
    let xa = AxisScale::from_values(all.iter().map(|p| p.0), nx);
    let ya = AxisScale::from_values(all.iter().map(|p| p.1), ny);

    // Size the label areas from the actual tick labels so nothing overlaps.
    let y_ticks = RangedCoordf64::from(ya.lo..ya.hi).key_points(ny);
    let mut y_tick_w = 0;
    for t in &y_ticks {
        y_tick_w = y_tick_w.max(area.estimate_text_size(&ya.label(*t), &tick_font)?.0);
    }
    let (_, tick_h) = area.estimate_text_size("0", &tick_font)?;
    let (_, desc_h) = area.estimate_text_size("Hg", &desc_font)?;
    let y_area = y_tick_w as i32
        + px(12.0)
        + if fig.y_label.is_empty() {
            0
        } else {
            desc_h as i32 + px(14.0)
        };
    let x_area = tick_h as i32
        + px(14.0)
        + if fig.x_label.is_empty() {
            0
        } else {
            desc_h as i32 + px(14.0)
        };
    let y_exp = ya.exponent_text();
    let x_exp = xa.exponent_text();

    let mut cb = ChartBuilder::on(area);
    cb.margin(px(18.0))
        .margin_right(px(28.0))
        // Room for a "×10ⁿ" above the y axis is always kept so frames of panels line up.
        .margin_top(px(34.0))
        .x_label_area_size(x_area)
        .y_label_area_size(y_area);
    if !fig.title.is_empty() {
        cb.caption(&fig.title, bold(20.0 * s));
    }
    let mut chart = cb.build_cartesian_2d(xa.lo..xa.hi, ya.lo..ya.hi)?;

    let xf = |v: &f64| xa.label(*v);
    let yf = |v: &f64| ya.label(*v);
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
        .bold_line_style(RGBColor(222, 222, 222).stroke_width(1))
        .light_line_style(TRANSPARENT)
        .axis_style(BLACK.stroke_width(1))
        .set_all_tick_mark_size(px(5.0))
        .draw()?;

    let lw = px(2.0) as u32;
    let radius = px(3.5);
    let glyph_w = px(24.0);
    for (i, series) in fig.series.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let line = color.stroke_width(lw);
        let pts = || {
            series
                .xs
                .iter()
                .zip(&series.ys)
                .map(|(&x, &y)| (xa.map(x), ya.map(y)))
        };
        match series.style {
            SeriesStyle::Points => {
                chart.draw_series(
                    pts()
                        .filter(|(x, y)| x.is_finite() && y.is_finite())
                        .map(|p| Circle::new(p, radius, color.filled())),
                )?;
            }
            SeriesStyle::OpenPoints => {
                let ring = color.stroke_width(lw.max(2));
                chart.draw_series(
                    pts()
                        .filter(|(x, y)| x.is_finite() && y.is_finite())
                        .map(|p| Circle::new(p, 2 * radius, ring)),
                )?;
            }
            SeriesStyle::Line | SeriesStyle::DashedLine => {
                // Lines break at non-finite points instead of bridging the gap.
                let v: Vec<(f64, f64)> = pts().collect();
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
        }
        if series.name.is_empty() {
            continue;
        }
        // An empty series carries the legend entry, whatever the data looked like.
        let anno = chart.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?;
        let anno = anno.label(series.name.as_str());
        match series.style {
            SeriesStyle::Points => anno.legend(move |(x, y)| {
                EmptyElement::at((x, y)) + Circle::new((glyph_w / 2, 0), radius, color.filled())
            }),
            SeriesStyle::OpenPoints => anno.legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + Circle::new((glyph_w / 2, 0), 2 * radius, color.stroke_width(lw.max(2)))
            }),
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
    area.draw(&Rectangle::new([(x0, y0), (x1, y1)], BLACK.stroke_width(1)))?;
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

    if fig.series.iter().any(|s| !s.name.is_empty()) {
        chart
            .configure_series_labels()
            .position(legend_corner(&all, &xa, &ya))
            .margin(px(10.0))
            .legend_area_size(glyph_w + px(10.0))
            .label_font(legend_font)
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(90, 90, 90))
            .draw()?;
    }
    Ok(())
}
