//! Paper-style PNG figures with a bundled font (no system fontconfig).
//!
//! Figures are drawn with plotters' bitmap backend; all text uses DejaVu Sans compiled into the
//! binary (registered with plotters' ab_glyph loader), so rendering works on a bare machine.
//! Files are written atomically through `gyroemu-io`.

mod axis;
mod dirty;
mod draw;
mod error;
mod fast_lines;
mod figure;
mod font;
mod glyphs;
mod layout;
mod legend;
mod polygon;
mod render;

/// A seeded xorshift walk for the pixel tests: each call gives a value in `0..n`.
#[cfg(test)]
pub(crate) fn seeded(mut x: u64) -> impl FnMut(i32) -> i32 {
    move |n: i32| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % n as u64) as i32
    }
}

pub use axis::{finite_bounds, AxisScale, MARGIN_FRACTION};
pub use error::PlotError;
pub use figure::{Figure, Marker, Series, SeriesStyle, PALETTE};
pub use font::{ensure_font, FONT_FAMILY};
pub use render::{
    downsample_rgb, render_panels_png, render_png, render_png_copies, render_rgb,
    render_rgb_antialiased, write_rgb_png, MAX_SIDE_PX, MIN_SIDE_PX, SUPERSAMPLE,
};
