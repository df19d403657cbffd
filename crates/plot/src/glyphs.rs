//! Text in the bundled font drawn from glyphs rasterised once per thread. plotters' ab_glyph
//! loader outlines and rasterises every glyph of every string it draws, which was about half
//! of a figure's text time; it places each glyph at the origin (its coverage depends on the
//! character and the size alone) and moves it by whole pixels, so a glyph's coverage, kept,
//! gives the same pixels. [`draw_text`] is plotters' `DrawingBackend::draw_text` with the
//! font's part (`FontDataInternal::draw`, as `TextStyle::draw` calls it) taken from the kept
//! glyphs: the same pixels, drawn in the same order (tested against plotters' own).

use crate::font::FONT_FAMILY;
use ab_glyph::{Font, FontRef, ScaleFont};
use plotters::style::FontStyle;
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{BackendCoord, BackendTextStyle, DrawingBackend, DrawingErrorKind};
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::OnceLock;

/// A glyph as plotters draws it at the origin: its coverage `(x, y, c)` in ab_glyph's order
/// (the pixels it covers at all), and its vertical shift.
struct Glyph {
    y_shift: i32,
    coverage: Vec<(u32, u32, f32)>,
}

/// Glyphs kept per thread, by face (bold or not), character and size (`f32` bits: plotters
/// scales the font by the size as `f32`). Emptied past [`MAX_GLYPHS`].
type Kept = HashMap<(bool, char, u32), Option<Glyph>>;

thread_local! {
    static GLYPHS: RefCell<Kept> = RefCell::new(HashMap::new());
}

/// Bounds the glyphs kept per thread (a figure's text uses a few hundred).
const MAX_GLYPHS: usize = 4096;

/// The bundled faces, as plotters registers them (`FontRef::try_from_slice` of the same
/// bytes); `None` if they do not parse, as plotters would refuse them too.
fn faces() -> Option<&'static (FontRef<'static>, FontRef<'static>)> {
    static FACES: OnceLock<Option<(FontRef<'static>, FontRef<'static>)>> = OnceLock::new();
    FACES
        .get_or_init(|| {
            let regular = FontRef::try_from_slice(dejavu::sans::regular()).ok()?;
            let bold = FontRef::try_from_slice(dejavu::sans::bold()).ok()?;
            Some((regular, bold))
        })
        .as_ref()
}

/// Which bundled face plotters draws `style` in (its fallback for a style not registered is
/// the regular one), or `None` for text in another family. Read from the style's label:
/// plotters resolves a `FontDesc`'s face when it is made, and its `FontDesc::style` changes
/// the label alone, so a style relabelled that way would be drawn here in the other face.
/// This crate makes its styles only by `font::text` and `font::bold` (which make each face
/// under its own label) and never relabels one, nor does plotters.
fn face_of<S: BackendTextStyle>(style: &S) -> Option<(bool, &'static FontRef<'static>)> {
    if style.family().as_str() != FONT_FAMILY {
        return None;
    }
    let (regular, bold) = faces()?;
    Some(match style.style() {
        FontStyle::Bold => (true, bold),
        _ => (false, regular),
    })
}

/// plotters' `DrawingBackend::draw_text` for text in the bundled family, its glyphs from
/// [`GLYPHS`]; `None` (nothing drawn) for any other text, which the caller draws as plotters
/// does.
pub(crate) fn draw_text<DB: DrawingBackend, S: BackendTextStyle>(
    back: &mut DB,
    text: &str,
    style: &S,
    pos: BackendCoord,
) -> Option<Result<(), DrawingErrorKind<DB::ErrorType>>> {
    let (is_bold, face) = face_of(style)?;
    let color = style.color();
    if color.alpha == 0.0 {
        return Some(Ok(()));
    }
    let layout = match style.layout_box(text) {
        Ok(l) => l,
        Err(e) => return Some(Err(DrawingErrorKind::FontError(Box::new(e)))),
    };
    let ((min_x, min_y), (max_x, max_y)) = layout;
    let (width, height) = (max_x - min_x, max_y - min_y);
    let dx = match style.anchor().h_pos {
        HPos::Left => 0,
        HPos::Right => -width,
        HPos::Center => -width / 2,
    };
    let dy = match style.anchor().v_pos {
        VPos::Top => 0,
        VPos::Center => -height / 2,
        VPos::Bottom => -height,
    };
    let trans = style.transform();
    let (w, h) = back.get_size();
    let size = style.size();
    let mut pixel = |x: i32, y: i32, c: f32| {
        // `TextStyle::draw`'s colour, then the backend's placement and clipping.
        let c = color.mix(f64::from(c));
        let (x, y) = trans.transform(x + dx - min_x, y + dy - min_y);
        let (x, y) = (pos.0 + x, pos.1 + y);
        if x >= 0 && x < w as i32 && y >= 0 && y < h as i32 {
            back.draw_pixel((x, y), c)
        } else {
            Ok(())
        }
    };
    // `FontDataInternal::draw` at the origin, as `draw_text` calls it.
    let font = face.as_scaled(size as f32);
    let mut x_shift = 0f32;
    let mut prev = None;
    let drawn = GLYPHS.with_borrow_mut(|kept| {
        if kept.len() > MAX_GLYPHS {
            kept.clear();
        }
        for c in text.chars() {
            if let Some(pc) = prev {
                x_shift += font.kern(font.glyph_id(pc), font.glyph_id(c));
            }
            prev = Some(c);
            let glyph = kept
                .entry((is_bold, c, (size as f32).to_bits()))
                .or_insert_with(|| rasterise(face, size, c));
            if let Some(g) = glyph {
                let xs = x_shift as i32;
                for &(x, y, cov) in &g.coverage {
                    pixel(x as i32 + xs, y as i32 + g.y_shift, cov)?;
                }
            }
            x_shift += font.h_advance(font.glyph_id(c));
        }
        Ok(())
    });
    Some(drawn)
}

/// A glyph as `FontDataInternal::draw` rasterises it: outlined at the origin at `size`
/// (scaled as `f32`), shifted down by half the size plus its top; `None` where it has no
/// outline (a space).
fn rasterise(face: &FontRef<'static>, size: f64, c: char) -> Option<Glyph> {
    let font = face.as_scaled(size as f32);
    let q = font.outline_glyph(font.scaled_glyph(c))?;
    let rect = q.px_bounds();
    let y_shift = ((size as f32) / 2.0 + rect.min.y) as i32;
    // A pixel of no coverage is left out: drawn, its alpha of 0 leaves the bitmap's pixel as
    // it was (the bitmap returns before writing it).
    let mut coverage = Vec::new();
    q.draw(|x, y, c| {
        if c > 0.0 {
            coverage.push((x, y, c))
        }
    });
    Some(Glyph { y_shift, coverage })
}

#[cfg(test)]
mod tests {
    use crate::fast_lines::FastLines;
    use crate::font::{bold, ensure_font, text};
    use plotters::prelude::*;
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    use plotters::style::FontTransform;
    use plotters_backend::DrawingBackend;

    #[test]
    fn kept_glyphs_draw_plotters_pixels() {
        // Seeded: the figures' characters and a few beyond them (Greek, degree, superscript
        // minus, a character the font lacks), regular and bold, sizes whole and fractional,
        // every anchor, every rotation, positions inside and across the edges, opaque and
        // translucent; each string drawn twice (the second from kept glyphs). The pixels of
        // plotters' own `draw_text` on the bitmap.
        ensure_font().unwrap();
        let (w, h) = (160u32, 120u32);
        let words = [
            "Time (s): the first 160 of 2048 samples",
            "0.7109",
            "-1.0e-6",
            "×10⁻⁶ Ω λ Δφ (deg/s) μm",
            "fig 9: 175 deg/s",
            "lp_q2 mix1_i1 Stage-2",
            "\u{10FFFD}x",
            "",
            " ",
        ];
        let mut walk = crate::seeded(0x0123_4567_89AB_CDEF);
        let mut next = |n: u64| walk(n as i32) as u64;
        let hs = [HPos::Left, HPos::Center, HPos::Right];
        let vs = [VPos::Top, VPos::Center, VPos::Bottom];
        let turns = [
            FontTransform::None,
            FontTransform::Rotate90,
            FontTransform::Rotate180,
            FontTransform::Rotate270,
        ];
        for case in 0..400 {
            let size = [9.0, 12.0, 17.5, 24.0, 31.25][case % 5];
            let base = if case % 3 == 0 {
                bold(size)
            } else {
                text(size)
            };
            let colour = RGBColor(next(256) as u8, next(256) as u8, 90);
            let colour = if case % 4 == 3 {
                colour.mix(0.55)
            } else {
                colour.to_rgba()
            };
            let style = base
                .pos(Pos::new(hs[next(3) as usize], vs[next(3) as usize]))
                .transform(turns[next(4) as usize].clone())
                .color(&colour);
            let word = words[case % words.len()];
            let at = (
                next(w as u64 + 60) as i32 - 30,
                next(h as u64 + 60) as i32 - 30,
            );
            let mut plain = vec![255u8; (w * h * 3) as usize];
            let mut kept = plain.clone();
            {
                let mut p = BitMapBackend::with_buffer(&mut plain, (w, h));
                let mut k = FastLines(BitMapBackend::with_buffer(&mut kept, (w, h)), None);
                for _ in 0..2 {
                    p.draw_text(word, &style, at).unwrap();
                    k.draw_text(word, &style, at).unwrap();
                }
            }
            assert!(
                plain == kept,
                "{word:?} at {at:?}, size {size}, case {case}"
            );
        }
    }

    #[test]
    fn other_families_keep_plotters_path() {
        // Text in a family other than the bundled one is not drawn from kept glyphs (here
        // plotters cannot find it: the same error either way, nothing drawn).
        let style = TextStyle::from(("no-such-family", 12.0).into_font());
        let (w, h) = (40u32, 20u32);
        let mut plain = vec![255u8; (w * h * 3) as usize];
        let mut kept = plain.clone();
        let a = BitMapBackend::with_buffer(&mut plain, (w, h)).draw_text("x", &style, (5, 5));
        let b = FastLines(BitMapBackend::with_buffer(&mut kept, (w, h)), None).draw_text(
            "x",
            &style,
            (5, 5),
        );
        assert_eq!(a.is_err(), b.is_err());
        assert!(plain == kept);
    }
}
