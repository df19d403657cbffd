//! The bundled font: DejaVu Sans registered once with plotters' ab_glyph loader, so text renders
//! on a bare machine without fontconfig or system fonts.

use crate::PlotError;
use plotters::style::{register_font, FontDesc, FontFamily, FontStyle, TextStyle};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

/// Family name under which DejaVu Sans (regular and bold) is registered; every text uses it.
pub const FONT_FAMILY: &str = "gyroemu-dejavu-sans";

static REGISTER: Once = Once::new();
static REGISTERED: AtomicBool = AtomicBool::new(false);

/// Registers the bundled font on first call (thread-safe); later calls only report the outcome.
pub fn ensure_font() -> Result<(), PlotError> {
    REGISTER.call_once(|| {
        let ok = register_font(FONT_FAMILY, FontStyle::Normal, dejavu::sans::regular()).is_ok()
            && register_font(FONT_FAMILY, FontStyle::Bold, dejavu::sans::bold()).is_ok();
        REGISTERED.store(ok, Ordering::SeqCst);
    });
    if REGISTERED.load(Ordering::SeqCst) {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

/// Regular text style of `size_px` in the bundled family.
pub(crate) fn text(size_px: f64) -> TextStyle<'static> {
    FontDesc::new(FontFamily::Name(FONT_FAMILY), size_px, FontStyle::Normal).into()
}

/// Bold text style of `size_px` in the bundled family. Built with `FontDesc::new`: plotters'
/// `FontDesc::style` only relabels and keeps the regular glyphs.
pub(crate) fn bold(size_px: f64) -> TextStyle<'static> {
    FontDesc::new(FontFamily::Name(FONT_FAMILY), size_px, FontStyle::Bold).into()
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    /// Dark pixels of `txt` drawn in `style` on a white in-memory bitmap.
    fn ink(style: &TextStyle, txt: &str) -> usize {
        let (w, h) = (400u32, 80u32);
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let area = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            area.draw(&Text::new(txt.to_string(), (10, 20), style.clone()))
                .unwrap();
            area.present().unwrap();
        }
        buf.chunks(3)
            .filter(|p| p.iter().map(|&c| c as u32).sum::<u32>() < 3 * 128)
            .count()
    }

    #[test]
    fn bundled_regular_and_bold_faces_draw_text() {
        ensure_font().unwrap();
        ensure_font().unwrap(); // idempotent
        let regular = ink(&text(30.0), "Mode 1 (Hz)");
        let heavy = ink(&bold(30.0), "Mode 1 (Hz)");
        assert!(regular > 300, "regular text drew {regular} dark pixels");
        assert!(
            heavy as f64 > 1.2 * regular as f64,
            "bold {heavy} vs regular {regular}"
        );
        assert_eq!(ink(&text(30.0), ""), 0);
    }
}
