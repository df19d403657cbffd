//! The bitmap backend with one faster path: an opaque axis-aligned line wider than one pixel
//! (the figures' grid lines, the sides of their frames, and their axes and tick marks, which
//! arrive as two-point paths) is filled as the rectangle it covers. plotters draws every
//! wide line or path as a polygon, swept one pixel row at a time with an allocation and a
//! sort per row; the grid lines of a run's figures took about 40 % of their drawing time that
//! way. The rectangle is exactly the pixels the polygon path sets (tested pixel for pixel
//! against it), so the figures keep their bytes. Slanted lines and paths (the data) keep
//! plotters' own route.
//!
//! Every call that reaches the bitmap also marks what it may touch in a [`Dirty`], when one
//! is given, so the average that follows reads only those stretches of the canvas.

use crate::dirty::Dirty;
use plotters::coord::Shift;
use plotters::drawing::DrawingArea;
use plotters::prelude::BitMapBackend;
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

/// The drawing area every figure is drawn into: plotters' over this backend.
pub(crate) type Area<'a> = DrawingArea<FastLines<'a>, Shift>;

/// [`BitMapBackend`] with axis-aligned wide lines filled as rectangles, marking what it
/// draws on in the [`Dirty`] it holds, if any.
pub(crate) struct FastLines<'a>(pub BitMapBackend<'a>, pub Option<&'a mut Dirty>);

impl FastLines<'_> {
    /// Marks the box of corners `a` and `b` widened by `margin` pixels, or the whole canvas
    /// when a corner is so far out (or the margin so wide) that plotters' own arithmetic on it
    /// may wrap (`to + 1` at `i32::MAX`) and set pixels elsewhere.
    fn touch(&mut self, a: BackendCoord, b: BackendCoord, margin: u32) {
        const FAR: u32 = 1 << 30;
        let far = |p: BackendCoord| p.0.unsigned_abs() >= FAR || p.1.unsigned_abs() >= FAR;
        if let Some(d) = self.1.as_deref_mut() {
            if far(a) || far(b) || margin >= FAR {
                d.all();
            } else {
                d.rect(a, b, margin as i32);
            }
        }
    }
}

type Error<'a> = DrawingErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>;

/// The rectangle (upper left, bottom right exclusive) of pixels that plotters' polygon path
/// fills for the line `from`-`to` of `width` > 1 pixels, when the line is horizontal or
/// vertical; `None` otherwise.
///
/// The path (`plotters_backend::rasterizer::draw_line`): the line's corners offset by half
/// the width across it, each truncated to an integer, give a rectangle `[xl, xr] x [yt, yb]`;
/// `fill_polygon` sweeps it along its longer side (rows when `xr - xl <= yb - yt`), filling
/// each sweep line between the two edges inclusive, and leaves out the last sweep line when
/// the edges are more than one pixel apart there; its anti-aliasing pixels at the edges have
/// zero coverage (integer edges), which the bitmap ignores.
pub(crate) fn wide_axis_line_rect(
    from: BackendCoord,
    to: BackendCoord,
    width: u32,
) -> Option<(BackendCoord, BackendCoord)> {
    if width <= 1 || (from.0 == to.0) == (from.1 == to.1) {
        return None;
    }
    let r = f64::from(width) / 2.0;
    let across = |c: i32| {
        let (a, b) = ((f64::from(c) - r) as i32, (f64::from(c) + r) as i32);
        (a.min(b), a.max(b))
    };
    let ((xl, xr), (yt, yb)) = if from.0 == to.0 {
        (across(from.0), (from.1.min(to.1), from.1.max(to.1)))
    } else {
        ((from.0.min(to.0), from.0.max(to.0)), across(from.1))
    };
    filled_rect(xl, xr, yt, yb)
}

/// The rectangle (upper left, bottom right exclusive) of pixels that `fill_polygon` sets for
/// the rectangle `[xl, xr] x [yt, yb]` with integer corners (the rule above); `None` where it
/// is degenerate, or at the end of `i32`'s range, or wider or taller than `i32` counts.
fn filled_rect(xl: i32, xr: i32, yt: i32, yb: i32) -> Option<(BackendCoord, BackendCoord)> {
    if xl == xr || yt == yb {
        // A degenerate polygon: plotters draws a one-pixel line instead.
        return None;
    }
    // A span past `i32` (a line from -1.5e9 to 1.5e9) would wrap to a negative one and pick
    // the wrong sweep: such a rectangle keeps plotters' path.
    let (w, h) = (xr.checked_sub(xl)?, yb.checked_sub(yt)?);
    // The exclusive corner one past the last pixel: a line at the end of `i32`'s range
    // keeps plotters' path rather than wrap.
    Some(if w <= h {
        // Rows yt ..= yb, the last only if the edges are at most one pixel apart.
        let last = if w > 1 { yb } else { yb.checked_add(1)? };
        ((xl, yt), (xr.checked_add(1)?, last))
    } else {
        let last = if h > 1 { xr } else { xr.checked_add(1)? };
        ((xl, yt), (last, yb.checked_add(1)?))
    })
}

/// The rectangle of pixels that plotters fills for the path `path` of `width` > 1 pixels,
/// when it is one horizontal or vertical segment (the figures' axes and tick marks), given
/// `polygon`, the polygon plotters makes of it (`rasterizer::polygonize`); `None` otherwise.
/// That polygon is the segment's corners offset by half the width across it, rounded; when
/// they make an axis-aligned rectangle, `fill_polygon` fills it as it fills a wide line's.
pub(crate) fn wide_axis_path_rect(
    path: &[BackendCoord],
    width: u32,
    polygon: &[BackendCoord],
) -> Option<(BackendCoord, BackendCoord)> {
    let [from, to] = path else { return None };
    if width <= 1 || (from.0 == to.0) == (from.1 == to.1) || polygon.len() != 4 {
        return None;
    }
    let (xl, xr) = (
        polygon.iter().map(|v| v.0).min()?,
        polygon.iter().map(|v| v.0).max()?,
    );
    let (yt, yb) = (
        polygon.iter().map(|v| v.1).min()?,
        polygon.iter().map(|v| v.1).max()?,
    );
    // Every vertex a corner, and every edge (the last closing the polygon) axis-aligned.
    let corner = |v: &BackendCoord| (v.0 == xl || v.0 == xr) && (v.1 == yt || v.1 == yb);
    let sides = (0..4).all(|i| {
        let (a, b) = (polygon[i], polygon[(i + 1) % 4]);
        (a.0 == b.0) != (a.1 == b.1)
    });
    if !(polygon.iter().all(corner) && sides) {
        return None;
    }
    filled_rect(xl, xr, yt, yb)
}

impl<'a> DrawingBackend for FastLines<'a> {
    type ErrorType = <BitMapBackend<'a> as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.0.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), Error<'a>> {
        self.0.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), Error<'a>> {
        self.0.present()
    }

    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<(), Error<'a>> {
        if let Some(d) = self.1.as_deref_mut() {
            d.pixel(point);
        }
        self.0.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), Error<'a>> {
        if style.color().alpha >= 1.0 {
            if let Some((ul, br)) = wide_axis_line_rect(from, to, style.stroke_width()) {
                // The bitmap's filled rectangle takes its bottom right corner exclusive.
                self.touch(ul, br, 0);
                return self.0.draw_rect(ul, br, &style.color(), true);
            }
        }
        // Within the segment's box widened by its half width (and a pixel of rounding).
        self.touch(from, to, style.stroke_width().saturating_add(1));
        self.0.draw_line(from, to, style)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), Error<'a>> {
        // The trait's own `draw_path`, with a wide opaque segment along an axis filled as
        // the rectangle its polygon covers.
        if style.color().alpha == 0.0 {
            return Ok(());
        }
        let width = style.stroke_width();
        if width == 1 {
            let mut begin: Option<BackendCoord> = None;
            for end in path {
                if let Some(begin) = begin {
                    self.draw_line(begin, end, style)?;
                }
                begin = Some(end);
            }
            return Ok(());
        }
        let p: Vec<_> = path.into_iter().collect();
        let polygon = plotters_backend::rasterizer::polygonize(&p, width);
        if style.color().alpha >= 1.0 {
            if let Some((ul, br)) = wide_axis_path_rect(&p, width, &polygon) {
                self.touch(ul, br, 0);
                return self.0.draw_rect(ul, br, &style.color(), true);
            }
        }
        self.fill_polygon(polygon, &style.color())
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), Error<'a>> {
        let vertices: Vec<_> = vert.into_iter().collect();
        crate::polygon::fill_polygon(self, &vertices, style)
    }

    fn draw_text<TStyle: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: BackendCoord,
    ) -> Result<(), Error<'a>> {
        if let Some(drawn) = crate::glyphs::draw_text(self, text, style, pos) {
            return drawn;
        }
        // Another family: the trait's own `draw_text`, on the bitmap, anywhere.
        if let Some(d) = self.1.as_deref_mut() {
            d.all();
        }
        self.0.draw_text(text, style, pos)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), Error<'a>> {
        if fill {
            self.touch(upper_left, bottom_right, 0);
            return self.0.draw_rect(upper_left, bottom_right, style, fill);
        }
        // The bitmap draws an outline as its four sides by plotters' rasterizer on itself, so
        // a wide one (the figures' frames) took the polygon path; the same rasterizer on this
        // backend draws the same four sides in the same order through the fast path above.
        plotters_backend::rasterizer::draw_rect(self, upper_left, bottom_right, style, fill)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), Error<'a>> {
        let end = |p: i32, n: u32| p.saturating_add(n.min(i32::MAX as u32) as i32);
        self.touch(pos, (end(pos.0, size.0), end(pos.1, size.1)), 0);
        self.0.blit_bitmap(pos, size, src)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::style::{Color, RGBAColor, RGBColor};

    const W: u32 = 48;
    const H: u32 = 40;

    /// The canvas after drawing `lines` on plain plotters and on [`FastLines`].
    fn both(lines: &[(BackendCoord, BackendCoord, u32, RGBAColor)]) -> (Vec<u8>, Vec<u8>) {
        let mut plain = vec![255u8; (W * H * 3) as usize];
        let mut fast = plain.clone();
        {
            let mut a = BitMapBackend::with_buffer(&mut plain, (W, H));
            let mut b = FastLines(BitMapBackend::with_buffer(&mut fast, (W, H)), None);
            for &(from, to, w, c) in lines {
                a.draw_line(from, to, &Color::stroke_width(&c, w)).unwrap();
                b.draw_line(from, to, &Color::stroke_width(&c, w)).unwrap();
            }
        }
        (plain, fast)
    }

    #[test]
    fn wide_axis_lines_set_the_polygon_paths_pixels() {
        // Seeded walk: every width 1-8, lengths 0-50 both ways, lines crossing and outside
        // the canvas edges, opaque and translucent colours (those keep the polygon path).
        let mut next = crate::seeded(0x2545_F491_4F6C_DD1D);
        let mut fast_taken = 0;
        for case in 0..4000 {
            let w = 1 + (case % 8) as u32;
            let a = (next(W as i32 + 20) - 10, next(H as i32 + 20) - 10);
            let len = next(51) * if next(2) == 0 { 1 } else { -1 };
            let b = if case % 2 == 0 {
                (a.0, a.1 + len)
            } else {
                (a.0 + len, a.1)
            };
            let colour = RGBColor(next(256) as u8, next(256) as u8, 7);
            let c = if case % 5 == 4 {
                colour.mix(0.6)
            } else {
                colour.to_rgba()
            };
            fast_taken += usize::from(c.3 >= 1.0 && wide_axis_line_rect(a, b, w).is_some());
            let (plain, fast) = both(&[(a, b, w, c)]);
            assert!(
                plain == fast,
                "line {a:?} -> {b:?}, width {w}, colour {c:?}"
            );
        }
        // The walk exercised the fast path, not only the fallback.
        assert!(fast_taken > 2000, "{fast_taken}");
    }

    #[test]
    fn rectangle_outlines_set_the_bitmaps_pixels() {
        // Seeded: outlines of widths 1-8 with corners in any order, inside and across the
        // canvas edges, opaque and translucent; and filled ones, which stay the bitmap's.
        let mut next = crate::seeded(0x9E37_79B9_7F4A_7C15);
        for case in 0..2000 {
            let w = 1 + (case % 8) as u32;
            let a = (next(W as i32 + 20) - 10, next(H as i32 + 20) - 10);
            let b = (next(W as i32 + 20) - 10, next(H as i32 + 20) - 10);
            let colour = RGBColor(next(256) as u8, 9, next(256) as u8);
            let c = if case % 5 == 4 {
                colour.mix(0.6)
            } else {
                colour.to_rgba()
            };
            let fill = case % 7 == 6;
            let mut plain = vec![255u8; (W * H * 3) as usize];
            let mut fast = plain.clone();
            {
                let style = Color::stroke_width(&c, w);
                let mut p = BitMapBackend::with_buffer(&mut plain, (W, H));
                let mut f = FastLines(BitMapBackend::with_buffer(&mut fast, (W, H)), None);
                p.draw_rect(a, b, &style, fill).unwrap();
                f.draw_rect(a, b, &style, fill).unwrap();
            }
            assert!(
                plain == fast,
                "rectangle {a:?} {b:?}, width {w}, colour {c:?}, fill {fill}"
            );
        }
    }

    #[test]
    fn wide_axis_paths_set_the_polygon_paths_pixels() {
        // Seeded: segments along either axis and of any length (zero too), slanted segments
        // and paths of three to six points, widths 1-8, inside and across the canvas edges,
        // opaque and translucent: the pixels of plotters' own `draw_path` on the bitmap.
        let mut next = crate::seeded(0xD1B5_4A32_D192_ED03);
        let mut fast_taken = 0;
        for case in 0..6000 {
            let w = 1 + (case % 8) as u32;
            let mut point = || (next(W as i32 + 20) - 10, next(H as i32 + 20) - 10);
            let a = point();
            let path: Vec<BackendCoord> = match case % 4 {
                0 => vec![a, (a.0, point().1)],
                1 => vec![a, (point().0, a.1)],
                2 => vec![a, point()],
                _ => (0..3 + case % 4).map(|_| point()).collect(),
            };
            let colour = RGBColor(next(256) as u8, next(256) as u8, 40);
            let c = if case % 5 == 4 {
                colour.mix(0.6)
            } else {
                colour.to_rgba()
            };
            let polygon = plotters_backend::rasterizer::polygonize(&path, w);
            fast_taken +=
                usize::from(c.3 >= 1.0 && wide_axis_path_rect(&path, w, &polygon).is_some());
            let mut plain = vec![255u8; (W * H * 3) as usize];
            let mut fast = plain.clone();
            {
                let style = Color::stroke_width(&c, w);
                let mut p = BitMapBackend::with_buffer(&mut plain, (W, H));
                let mut f = FastLines(BitMapBackend::with_buffer(&mut fast, (W, H)), None);
                p.draw_path(path.iter().copied(), &style).unwrap();
                f.draw_path(path.iter().copied(), &style).unwrap();
            }
            assert!(plain == fast, "path {path:?}, width {w}, colour {c:?}");
        }
        // The walk exercised the fast path, not only plotters' own.
        assert!(fast_taken > 1500, "{fast_taken}");
    }

    #[test]
    fn lines_at_the_end_of_the_coordinate_range_keep_plotters_path() {
        // One past the last pixel would wrap at i32::MAX (the whole canvas height filled).
        assert_eq!(wide_axis_line_rect((10, i32::MAX), (30, i32::MAX), 4), None);
        assert_eq!(wide_axis_line_rect((i32::MAX, 5), (i32::MAX, 20), 4), None);
        // Just inside the range the fast path holds (plotters itself overflows at the end, in
        // a debug build, so the comparison stops short of it).
        let black = RGBColor(0, 0, 0).to_rgba();
        assert!(wide_axis_line_rect((10, i32::MAX - 3), (30, i32::MAX - 3), 4).is_some());
        let (plain, fast) = both(&[((10, i32::MAX - 3), (30, i32::MAX - 3), 4, black)]);
        assert!(plain == fast);
    }

    #[test]
    #[cfg_attr(
        debug_assertions,
        ignore = "plotters' own arithmetic overflows on these inputs under overflow checks (the README's checked suite): the test is of the wrapping release build"
    )]
    fn spans_wider_than_i32_keep_plotters_path() {
        // From -1.5e9 to 1.5e9 the span wraps in `i32`: plotters' own pixels, for a line, a
        // two-point path and a rectangle outline, both ways, widths 2 to 5.
        let (a, b) = (-1_500_000_000, 1_500_000_000);
        assert_eq!(filled_rect(a, b, 8, 11), None);
        assert_eq!(filled_rect(8, 11, a, b), None);
        let black = RGBColor(0, 0, 0).to_rgba();
        for w in 2..=5 {
            let style = Color::stroke_width(&black, w);
            for (from, to) in [((a, 10), (b, 10)), ((10, a), (10, b))] {
                let mut plain = vec![255u8; (W * H * 3) as usize];
                let mut fast = plain.clone();
                {
                    let mut p = BitMapBackend::with_buffer(&mut plain, (W, H));
                    let mut f = FastLines(BitMapBackend::with_buffer(&mut fast, (W, H)), None);
                    p.draw_line(from, to, &style).unwrap();
                    f.draw_line(from, to, &style).unwrap();
                    p.draw_path([from, to], &style).unwrap();
                    f.draw_path([from, to], &style).unwrap();
                    p.draw_rect(from, (to.0, to.1 + 3), &style, false).unwrap();
                    f.draw_rect(from, (to.0, to.1 + 3), &style, false).unwrap();
                }
                assert!(plain == fast, "{from:?} -> {to:?}, width {w}");
            }
        }
    }

    #[test]
    fn slanted_and_thin_lines_keep_plotters_path() {
        assert_eq!(wide_axis_line_rect((0, 0), (5, 3), 4), None);
        assert_eq!(wide_axis_line_rect((2, 2), (2, 9), 1), None);
        assert_eq!(wide_axis_line_rect((2, 2), (2, 2), 3), None);
        // A vertical line 2 wide covers the three columns around it, all rows but the last.
        assert_eq!(
            wide_axis_line_rect((5, 10), (5, 2), 2),
            Some(((4, 2), (7, 10)))
        );
    }
    #[test]
    fn every_pixel_drawn_lies_in_a_marked_cell() {
        // Seeded drawings of every kind the figures use and more (paths thin and wide,
        // slanted and along the axes, polygons, rectangles filled and outlined, circles,
        // text in both faces at every rotation, single pixels, a blitted block), opaque and
        // translucent, across and beyond the edges, through plotters' elements on a white
        // canvas: every pixel not white lies in a cell the drawing marked, so the average
        // may skip the others. Most drawings leave cells unmarked (the skip is exercised).
        use crate::dirty::{Dirty, STRETCH};
        use crate::font::{bold, ensure_font, text};
        use plotters::prelude::*;
        use plotters::style::FontTransform;
        ensure_font().unwrap();
        let (w, h) = (300u32, 150u32);
        let walk = std::cell::RefCell::new(crate::seeded(0x5eed_d1a7_0f00_cafe));
        let next = |n: i32| (walk.borrow_mut())(n);
        let mut left_unmarked = 0;
        for case in 0..600 {
            let mut canvas = vec![255u8; (w * h * 3) as usize];
            let mut dirty = Dirty::new(w, h);
            {
                let root = FastLines(
                    BitMapBackend::with_buffer(&mut canvas, (w, h)),
                    Some(&mut dirty),
                )
                .into_drawing_area();
                for _ in 0..3 {
                    let p = || (next(w as i32 + 80) - 40, next(h as i32 + 80) - 40);
                    let axis = |a: (i32, i32)| match next(3) {
                        0 => (a.0, next(h as i32)),
                        1 => (next(w as i32), a.1),
                        _ => (next(w as i32), next(h as i32)),
                    };
                    let c = RGBColor(next(200) as u8, next(200) as u8, next(200) as u8);
                    let c = if next(3) == 0 {
                        c.mix(0.4)
                    } else {
                        c.to_rgba()
                    };
                    let width = 1 + next(7) as u32;
                    let kind = next(9);
                    let r = match kind {
                        0 => {
                            let a = p();
                            let b = axis(a);
                            root.draw(&PathElement::new(
                                vec![a, b],
                                ShapeStyle::from(&c).stroke_width(width),
                            ))
                        }
                        1 => {
                            let pts: Vec<_> = (0..2 + next(5)).map(|_| p()).collect();
                            root.draw(&PathElement::new(
                                pts,
                                ShapeStyle::from(&c).stroke_width(width),
                            ))
                        }
                        2 => root.draw(&Rectangle::new([p(), p()], c.filled())),
                        3 => root.draw(&Rectangle::new(
                            [p(), p()],
                            ShapeStyle::from(&c).stroke_width(width),
                        )),
                        4 => root.draw(&Circle::new(
                            p(),
                            next(30),
                            ShapeStyle::from(&c).stroke_width(width),
                        )),
                        5 => {
                            let pts: Vec<_> = (0..3 + next(6)).map(|_| p()).collect();
                            root.draw(&Polygon::new(pts, c))
                        }
                        6 => {
                            let size = [9.0, 14.5, 24.0][next(3) as usize];
                            let face = if next(2) == 0 { bold(size) } else { text(size) };
                            let turn = [
                                FontTransform::None,
                                FontTransform::Rotate90,
                                FontTransform::Rotate180,
                                FontTransform::Rotate270,
                            ][next(4) as usize]
                                .clone();
                            let style = face.transform(turn).color(&c);
                            root.draw(&Text::new("Phase (mdeg) 42", p(), style))
                        }
                        7 => root.draw(&Pixel::new(p(), c)),
                        _ => {
                            let a = p();
                            let block = vec![40u8; 3 * 7 * 5];
                            root.draw(&BitMapElement::with_owned_buffer(a, (7, 5), block).unwrap())
                        }
                    };
                    r.unwrap();
                }
                root.present().unwrap();
            }
            let mut unmarked = 0;
            for y in 0..h as usize {
                for x in 0..w as usize {
                    let touched = dirty.touched(y / 2, x / STRETCH);
                    let px = &canvas[(y * w as usize + x) * 3..][..3];
                    assert!(touched || px == [255; 3], "case {case}: pixel ({x}, {y})");
                    unmarked += usize::from(!touched);
                }
            }
            left_unmarked += usize::from(unmarked > 0);
        }
        assert!(
            left_unmarked > 300,
            "{left_unmarked} of 600 drawings left cells unmarked"
        );
    }
    #[test]
    #[cfg_attr(
        debug_assertions,
        ignore = "plotters' own arithmetic overflows on these inputs under overflow checks (the README's checked suite): the test is of the wrapping release build"
    )]
    fn draws_far_off_the_canvas_are_marked_too() {
        // Calls that reach the backend with coordinates near the ends of i32 or widths in the
        // millions (plotters' elements clip before this, the backend does not): plotters'
        // `to + 1` wraps there, and a line's box widened by a capped margin missed pixels.
        // Every pixel drawn still lies in a marked cell.
        use crate::dirty::{Dirty, STRETCH};
        use plotters::style::{Color, RGBColor};
        let (w, h) = (300u32, 100u32);
        let red = RGBColor(200, 0, 0);
        let lines: [(BackendCoord, BackendCoord, u32, f64); 5] = [
            ((200, 10), (i32::MAX, 10), 1, 1.0),
            ((0, i32::MAX), (100, i32::MAX), 1, 1.0),
            ((0, i32::MAX), (100, i32::MAX), 1, 0.5),
            ((-2_000_000, -50), (-2_000_000, 500), 5_000_000, 0.5),
            ((i32::MIN, 40), (i32::MAX, 60), 3, 1.0),
        ];
        for (k, &(a, b, width, alpha)) in lines.iter().enumerate() {
            let mut canvas = vec![255u8; (w * h * 3) as usize];
            let mut dirty = Dirty::new(w, h);
            {
                let mut f = FastLines(
                    BitMapBackend::with_buffer(&mut canvas, (w, h)),
                    Some(&mut dirty),
                );
                let style = plotters::style::ShapeStyle::from(&red.mix(alpha)).stroke_width(width);
                f.draw_line(a, b, &style).unwrap();
            }
            for y in 0..h as usize {
                for x in 0..w as usize {
                    let px = &canvas[(y * w as usize + x) * 3..][..3];
                    assert!(
                        dirty.touched(y / 2, x / STRETCH) || px == [255; 3],
                        "line {k}: pixel ({x}, {y}) drawn, not marked"
                    );
                }
            }
        }
    }
}
