//! Rendering figures to PNG files or memory. PNGs are drawn at twice their size and averaged
//! down 2 x 2 (supersampling): plotters' bitmap backend draws lines and markers without
//! anti-aliasing, which looks stepped on slanted lines.

use crate::dirty::Dirty;
use crate::draw::{draw_figure, text_scale};
use crate::error::DrawError;
use crate::fast_lines::{Area, FastLines};
use crate::figure::Figure;
use crate::font::{bold, ensure_font};
use crate::layout::title_scale;
use crate::PlotError;
use image::ImageEncoder;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Mutex;

/// Smallest accepted image (or panel) side: below this axes and labels cannot fit.
pub const MIN_SIDE_PX: u32 = 64;
/// Largest accepted image side (bounds the RGB buffer to 768 MiB).
pub const MAX_SIDE_PX: u32 = 16_384;
/// Supersampling factor of the PNG renderers.
pub const SUPERSAMPLE: u32 = 2;

type DrawResult = Result<(), DrawError>;

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
            reason: "the file name must end in .png (figures are written as PNG)".into(),
        });
    }
    Ok(())
}

/// Averages each `k` x `k` block of an RGB image `w` x `h` (multiples of `k`) into one pixel,
/// rounding to nearest: the image's mean intensity is kept to within half a level.
pub fn downsample_rgb(src: &[u8], w: usize, h: usize, k: usize) -> Vec<u8> {
    let mut out = Vec::new();
    downsample_into(src, w, h, k, &mut out);
    out
}

/// [`downsample_rgb`] into `out` (resized; every byte written).
fn downsample_into(src: &[u8], w: usize, h: usize, k: usize, out: &mut Vec<u8>) {
    let (ow, oh) = (w / k, h / k);
    sized(out, ow * oh * 3);
    if k == 2 {
        for (oy, o) in out.chunks_exact_mut(ow * 3).enumerate() {
            let r0 = &src[2 * oy * w * 3..][..ow * 6];
            let r1 = &src[(2 * oy + 1) * w * 3..][..ow * 6];
            average_rows(r0, r1, o);
        }
        return;
    }
    let n = (k * k) as u32;
    for oy in 0..oh {
        for ox in 0..ow {
            let mut acc = [0u32; 3];
            for dy in 0..k {
                let row = ((oy * k + dy) * w + ox * k) * 3;
                for px in src[row..row + 3 * k].chunks_exact(3) {
                    for c in 0..3 {
                        acc[c] += u32::from(px[c]);
                    }
                }
            }
            let o = (oy * ow + ox) * 3;
            for c in 0..3 {
                out[o + c] = ((acc[c] + n / 2) / n) as u8;
            }
        }
    }
}

/// `out` `len` bytes long, whatever they hold (every byte is overwritten next): a kept buffer
/// that is long enough is cut to length, not cleared.
fn sized(out: &mut Vec<u8>, len: usize) {
    if out.len() < len {
        out.resize(len, 0);
    }
    out.truncate(len);
}

/// One output row of the 2 x 2 average: rows `r0` and `r1` of the canvas, two pixels (6
/// bytes) per output pixel, rounded to nearest.
#[inline]
fn average_rows(r0: &[u8], r1: &[u8], o: &mut [u8]) {
    for ((a, b), d) in r0
        .chunks_exact(6)
        .zip(r1.chunks_exact(6))
        .zip(o.chunks_exact_mut(3))
    {
        for c in 0..3 {
            let sum = u16::from(a[c]) + u16::from(a[c + 3]) + u16::from(b[c]) + u16::from(b[c + 3]);
            d[c] = ((sum + 2) >> 2) as u8;
        }
    }
}

/// [`downsample_into`] for `k` = 2 that leaves the canvas white again: each pair of rows is
/// set to 255 right after it is read, while it is still in cache, so the next figure drawn on
/// this canvas need not clear it (a separate clear read all of it back from memory first: a
/// canvas of up to 35 MB, a tenth of a figure's time). A stretch of [`WHITE_RUN`] canvas
/// pixels that is white in both rows gives white and is not written: most of a figure is
/// background, and a stretch left clean in cache costs memory no write-back.
///
/// With `dirty`, the stretches no drawing touched are not even read: they are white.
fn downsample2_whitening(
    src: &mut [u8],
    w: usize,
    h: usize,
    out: &mut Vec<u8>,
    dirty: Option<&Dirty>,
) {
    debug_assert!(
        w.is_multiple_of(2) && h.is_multiple_of(2),
        "a canvas twice an image's size"
    );
    let (ow, oh) = (w / 2, h / 2);
    sized(out, ow * oh * 3);
    let (run, used) = (WHITE_RUN * 3, w * 3);
    for (p, (pair, o)) in src
        .chunks_exact_mut(2 * w * 3)
        .zip(out.chunks_exact_mut(ow * 3))
        .enumerate()
    {
        let (r0, r1) = pair.split_at_mut(used);
        let mut start = 0;
        while start < used {
            let end = (start + run).min(used);
            let d = &mut o[start / 2..end / 2];
            let (a, b) = (&mut r0[start..end], &mut r1[start..end]);
            // Untouched (not read), or white in both rows: white, nothing written back.
            if dirty.is_some_and(|t| !t.touched(p, start / run)) || all_white(a) & all_white(b) {
                d.fill(255);
            } else {
                average_rows(a, b, d);
                a.fill(255);
                b.fill(255);
            }
            start = end;
        }
    }
}

/// Canvas pixels per stretch that [`downsample2_whitening`] skips when white: 64 (192 bytes,
/// three cache lines, a whole number of output pixels).
const WHITE_RUN: usize = crate::dirty::STRETCH;

/// Whether every byte is 255 (a fold without early exit, which vectorises).
#[inline]
fn all_white(b: &[u8]) -> bool {
    b.iter().fold(255u8, |acc, &x| acc & x) == 255
}

/// A buffer kept between figures ([`POOL`]), with how many of its leading bytes are known to
/// be 255 (a canvas left white by [`downsample2_whitening`]).
struct Kept {
    buf: Vec<u8>,
    white: usize,
}

/// Draws `draw` onto a white `w * k` x `h * k` canvas and leaves it averaged down to `w` x `h`
/// in `out`.
fn supersampled<F>(w: u32, h: u32, k: u32, draw: F, out: &mut Vec<u8>) -> Result<(), PlotError>
where
    F: FnOnce(&Area) -> DrawResult,
{
    let (bw, bh) = (w * k, h * k);
    let len = bw as usize * bh as usize * 3;
    // The canvas is kept between figures ([`take_buffer`]): a fresh one of up to 35 MB per
    // figure cost a page fault per 4 KiB (about a tenth of a run's figure time). Only what is
    // not known to be white is cleared.
    let Kept { mut buf, white } = take_buffer(len);
    let dirty = white.min(len)..buf.len().min(len);
    buf[dirty].fill(255);
    buf.resize(len.max(buf.len()), 255);
    let canvas = &mut buf[..len];
    // What the drawing touches, for the 2 x 2 average to read only that.
    let mut dirty = (k == 2).then(|| Dirty::new(bw, bh));
    let drawn: DrawResult = (|| {
        let root = FastLines(BitMapBackend::with_buffer(canvas, (bw, bh)), dirty.as_mut())
            .into_drawing_area();
        draw(&root)?;
        root.present()?;
        Ok(())
    })();
    // Bytes past the canvas keep what they were; its own are white again only if averaged.
    let past = if white > len { white } else { len };
    let (res, white) = match drawn {
        Err(source) => {
            let e = gyroemu_io::IoError::Producer {
                path: "<memory>".into(),
                reason: source,
            };
            (Err(e.into()), 0)
        }
        Ok(()) if k == 1 => {
            buf.truncate(len);
            std::mem::swap(&mut buf, out);
            (Ok(()), 0)
        }
        Ok(()) if k == 2 => {
            downsample2_whitening(
                &mut buf[..len],
                bw as usize,
                bh as usize,
                out,
                dirty.as_ref(),
            );
            (Ok(()), past)
        }
        Ok(()) => {
            downsample_into(&buf[..len], bw as usize, bh as usize, k as usize, out);
            (Ok(()), 0)
        }
    };
    give_back(Kept { buf, white });
    res
}

/// [`supersampled`] into a new buffer (for the caller to keep).
fn in_memory<F>(w: u32, h: u32, k: u32, draw: F) -> Result<Vec<u8>, PlotError>
where
    F: FnOnce(&Area) -> DrawResult,
{
    let mut out = Vec::new();
    supersampled(w, h, k, draw, &mut out)?;
    Ok(out)
}

/// [`supersampled`] into a kept image buffer, encoded once as a PNG and written at each of
/// `paths` (atomically).
fn to_png<F>(paths: &[&Path], w: u32, h: u32, k: u32, draw: F) -> Result<(), PlotError>
where
    F: FnOnce(&Area) -> DrawResult,
{
    // An image buffer: every byte is overwritten, so none is white afterwards.
    let mut rgb = take_buffer(w as usize * h as usize * 3).buf;
    let res = supersampled(w, h, k, draw, &mut rgb).and_then(|()| write_png(paths, w, h, &rgb));
    give_back(Kept { buf: rgb, white: 0 });
    res
}

/// Buffers kept for the next figures (canvases and images): at most [`MAX_POOLED`] of at most
/// [`MAX_KEPT_BUFFER`] bytes each, whatever the number of threads that draw, so two figures
/// drawn at once reuse theirs and a process keeps at most 256 MB (88 MB with the presets').
static POOL: Mutex<Vec<Kept>> = Mutex::new(Vec::new());
/// Buffers in [`POOL`]: a canvas and an image for each of two figures drawn at once.
const MAX_POOLED: usize = 4;
/// Largest buffer kept (bytes): the presets' largest canvas is 35 MB.
const MAX_KEPT_BUFFER: usize = 64 << 20;

/// A kept buffer for `len` bytes (the smallest that holds them, else the largest, to grow),
/// or a new one; its contents are for the caller to overwrite (or, up to `white`, 255).
fn take_buffer(len: usize) -> Kept {
    let mut pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
    let fits = (0..pool.len())
        .filter(|&i| pool[i].buf.capacity() >= len)
        .min_by_key(|&i| pool[i].buf.capacity());
    let pick = fits.or_else(|| (0..pool.len()).max_by_key(|&i| pool[i].buf.capacity()));
    pick.map(|i| pool.swap_remove(i)).unwrap_or(Kept {
        buf: Vec::new(),
        white: 0,
    })
}

/// Keeps `kept` for the next figure, if the pool has room and its buffer is neither empty nor
/// oversized.
fn give_back(kept: Kept) {
    let mut pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
    if pool.len() < MAX_POOLED && (1..=MAX_KEPT_BUFFER).contains(&kept.buf.capacity()) {
        pool.push(kept);
    }
}

/// Encodes an RGB image as PNG once and writes it at each of `paths`, atomically: `image`'s
/// encoder, as plotters' bitmap backend calls it (the same bytes), without copying the image
/// into a backend first.
fn write_png(paths: &[&Path], w: u32, h: u32, rgb: &[u8]) -> Result<(), PlotError> {
    let Some(first) = paths.first() else {
        return Ok(());
    };
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(rgb, w, h, image::ColorType::Rgb8)
        .map_err(|e| gyroemu_io::IoError::Producer {
            path: first.to_path_buf(),
            reason: e.into(),
        })?;
    for path in paths {
        gyroemu_io::write_atomic(path, &bytes)?;
    }
    Ok(())
}

/// Renders `fig` alone into a `width_px` x `height_px` PNG at `path`, atomically (a temporary
/// file in the same directory, renamed when complete), anti-aliased by supersampling. Axes
/// span the finite data with a 5 % margin (whole decades on a log axis); non-finite points are
/// skipped; empty or constant data get a sensible span.
pub fn render_png(fig: &Figure, path: &Path) -> Result<(), PlotError> {
    render_png_copies(fig, &[path])
}

/// [`render_png`] at each of `paths`: drawn and encoded once, the same bytes in every file.
/// Every name is checked before drawing, so a refused one writes none; the files are then
/// written one after another, so a write that fails leaves the ones before it in place.
pub fn render_png_copies(fig: &Figure, paths: &[&Path]) -> Result<(), PlotError> {
    if paths.is_empty() {
        return Ok(());
    }
    for path in paths {
        check_target(path, fig.width_px, fig.height_px)?;
    }
    ensure_font()?;
    let k = SUPERSAMPLE;
    to_png(paths, fig.width_px, fig.height_px, k, |a| {
        draw_figure(a, fig, f64::from(k))
    })
}

/// Renders `fig` into memory without anti-aliasing: `width_px * height_px * 3` bytes, RGB,
/// row-major from the top left, every series in its exact palette colour (for inspecting and
/// testing pixels).
pub fn render_rgb(fig: &Figure) -> Result<Vec<u8>, PlotError> {
    check_target(Path::new("memory.png"), fig.width_px, fig.height_px)?;
    ensure_font()?;
    in_memory(fig.width_px, fig.height_px, 1, |a| draw_figure(a, fig, 1.0))
}

/// Renders `fig` into memory exactly as [`render_png`] encodes it: drawn at
/// [`SUPERSAMPLE`] times the size and averaged down.
pub fn render_rgb_antialiased(fig: &Figure) -> Result<Vec<u8>, PlotError> {
    check_target(Path::new("memory.png"), fig.width_px, fig.height_px)?;
    ensure_font()?;
    let k = SUPERSAMPLE;
    in_memory(fig.width_px, fig.height_px, k, |a| {
        draw_figure(a, fig, f64::from(k))
    })
}

/// Encodes an RGB image (`width_px * height_px * 3` bytes, as [`render_rgb_antialiased`]
/// gives) as a PNG at `path`, atomically: the bytes [`render_png`] writes for the same pixels.
pub fn write_rgb_png(
    path: &Path,
    width_px: u32,
    height_px: u32,
    rgb: &[u8],
) -> Result<(), PlotError> {
    check_target(path, width_px, height_px)?;
    if rgb.len() != width_px as usize * height_px as usize * 3 {
        return Err(gyroemu_io::IoError::Producer {
            path: path.to_path_buf(),
            reason: format!(
                "{} bytes for a {width_px} x {height_px} RGB image (it takes {})",
                rgb.len(),
                width_px as usize * height_px as usize * 3
            )
            .into(),
        }
        .into());
    }
    write_png(&[path], width_px, height_px, rgb)
}

/// Renders `panels` in a grid of `cols` columns (rows as needed, filled row by row) under an
/// overall `title`, into one `width_px` x `height_px` PNG at `path`, atomically and
/// anti-aliased. Each panel's own `width_px`/`height_px` are ignored; its text scales with
/// the cell size.
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
    let k = SUPERSAMPLE;
    let ss = f64::from(k);
    to_png(&[path], width_px, height_px, k, |root| {
        let body = if title.is_empty() {
            root.clone()
        } else {
            let s = text_scale(width_px, height_px) * ss;
            // A long title shrinks to fit the width (down to half its size).
            let (tw, _) = root.estimate_text_size(title, &bold(24.0 * s))?;
            let fit = title_scale(0.96 * f64::from(width_px) * ss, tw);
            root.margin((10.0 * s).round() as i32, 0, 0, 0)
                .titled(title, bold(24.0 * s * fit))?
        };
        for (cell, fig) in body.split_evenly((rows, cols)).iter().zip(panels) {
            draw_figure(cell, fig, ss)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pool_keeps_at_most_its_bound() {
        let kept = |buf: Vec<u8>| Kept { buf, white: 0 };
        for n in [0usize, 1, 1000, MAX_KEPT_BUFFER + 1] {
            give_back(kept(Vec::with_capacity(n)));
        }
        for _ in 0..10 {
            give_back(kept(vec![0u8; 100]));
        }
        let pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
        assert!(pool.len() <= MAX_POOLED);
        assert!(pool
            .iter()
            .all(|b| (1..=MAX_KEPT_BUFFER).contains(&b.buf.capacity())));
    }

    #[test]
    fn the_two_by_two_average_is_the_rounded_mean_of_each_block() {
        // Against the mean written out pixel by pixel, on seeded canvases 2 to 150 pixels
        // wide (shorter than a whitening stretch of 64, a whole number of them, and between).
        let mut next = crate::seeded(0x9E37_79B9_7F4A_7C15);
        for w in [2, 4, 30, 32, 34, 62, 64, 66, 96, 128, 150] {
            let h = 4;
            let src: Vec<u8> = (0..w * h * 3).map(|_| next(256) as u8).collect();
            let px = |x: usize, y: usize, c: usize| u32::from(src[(y * w + x) * 3 + c]);
            let want: Vec<u8> = (0..h / 2)
                .flat_map(|oy| (0..w / 2).map(move |ox| (ox, oy)))
                .flat_map(|(ox, oy)| {
                    (0..3).map(move |c| {
                        let sum = px(2 * ox, 2 * oy, c)
                            + px(2 * ox + 1, 2 * oy, c)
                            + px(2 * ox, 2 * oy + 1, c)
                            + px(2 * ox + 1, 2 * oy + 1, c);
                        ((sum + 2) / 4) as u8
                    })
                })
                .collect();
            assert_eq!(downsample_rgb(&src, w, h, 2), want, "width {w}");
        }
    }

    #[test]
    fn averaging_that_whitens_gives_the_averages_and_leaves_the_canvas_white() {
        // Seeded canvases of 150 x 6 pixels (two whole stretches of 64 and a part of 22 per
        // row): every byte random, and white with a few bytes of ink (one in 97, so some
        // stretches are white in both rows, some in one, some in neither). The same output
        // as the plain average, and every canvas byte 255 after.
        let (w, h) = (150, 6);
        let mut next = crate::seeded(0x2545_f491_4f6c_dd1d);
        let random: Vec<u8> = (0..w * h * 3).map(|_| next(256) as u8).collect();
        let sparse: Vec<u8> = (0..w * h * 3)
            .map(|_| match next(97) {
                0 => next(255) as u8,
                _ => 255,
            })
            .collect();
        let runs = |c: &[u8]| {
            let white = |r: usize, k: usize| {
                let row = &c[r * w * 3..][..w * 3];
                row[k * WHITE_RUN * 3..][..(WHITE_RUN * 3).min(w * 3 - k * WHITE_RUN * 3)]
                    .iter()
                    .all(|&b| b == 255)
            };
            let pairs = (0..h / 2).flat_map(|p| (0..3).map(move |k| (p, k)));
            pairs
                .map(|(p, k)| (white(2 * p, k) as u8) + (white(2 * p + 1, k) as u8))
                .fold([0; 3], |mut n, x| {
                    n[x as usize] += 1;
                    n
                })
        };
        // The sparse canvas has stretch pairs of each kind: white in none, one and both rows.
        assert!(runs(&sparse).iter().all(|&n| n > 0), "{:?}", runs(&sparse));
        for src in [random, sparse] {
            let want = downsample_rgb(&src, w, h, 2);
            let mut canvas = src.clone();
            let mut out = vec![9u8; 1000];
            downsample2_whitening(&mut canvas, w, h, &mut out, None);
            assert_eq!(out, want);
            assert!(canvas.iter().all(|&b| b == 255));
            // With the cells of the inked pixels marked (the rest left unread): the same.
            let mut dirty = Dirty::new(w as u32, h as u32);
            for (i, px) in src.chunks_exact(3).enumerate() {
                if px != [255; 3] {
                    dirty.pixel(((i % w) as i32, (i / w) as i32));
                }
            }
            let mut canvas = src.clone();
            downsample2_whitening(&mut canvas, w, h, &mut out, Some(&dirty));
            assert_eq!(out, want);
            assert!(canvas.iter().all(|&b| b == 255));
        }
    }

    #[test]
    fn an_image_drawn_in_memory_writes_the_bytes_of_render_png() {
        use crate::figure::{Figure, Series, SeriesStyle};
        let xs: Vec<f64> = (0..40).map(f64::from).collect();
        let ys: Vec<f64> = xs.iter().map(|x| (x * 0.3).cos()).collect();
        let mut fig =
            Figure::new("in memory", "x", "y").with(Series::new("line", SeriesStyle::Line, xs, ys));
        (fig.width_px, fig.height_px) = (300, 200);
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
        render_png(&fig, &a).unwrap();
        let rgb = render_rgb_antialiased(&fig).unwrap();
        write_rgb_png(&b, 300, 200, &rgb).unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        // An image of the wrong size is refused, nothing written.
        let c = dir.path().join("c.png");
        assert!(write_rgb_png(&c, 300, 201, &rgb).is_err());
        assert!(!c.exists());
    }

    #[test]
    fn figures_drawn_on_kept_canvases_are_those_drawn_on_fresh_ones() {
        use crate::figure::{Figure, Series, SeriesStyle};
        // A large figure, a small one and the large one again, in one thread: the kept canvas
        // (left white by the averaging, or partly by a smaller figure) gives the bytes of a
        // fresh one, which a render after emptying the pool gets.
        let fig = |n: usize, w: u32, h: u32| {
            let xs: Vec<f64> = (0..n).map(|i| i as f64).collect();
            let ys: Vec<f64> = xs.iter().map(|x| (x * 0.37).sin()).collect();
            let mut f = Figure::new("kept", "x", "y")
                .with(Series::new(
                    "line",
                    SeriesStyle::Line,
                    xs.clone(),
                    ys.clone(),
                ))
                .with(Series::new("points", SeriesStyle::Points, xs, ys));
            f.width_px = w;
            f.height_px = h;
            f
        };
        let (big, small) = (fig(300, 640, 480), fig(50, 200, 150));
        let fresh = |f: &Figure| {
            POOL.lock().unwrap_or_else(|e| e.into_inner()).clear();
            render_rgb_antialiased(f).unwrap()
        };
        let (big0, small0) = (fresh(&big), fresh(&small));
        for f in [&big, &small, &big, &small, &big] {
            let want = if f.width_px == 640 { &big0 } else { &small0 };
            assert_eq!(&render_rgb_antialiased(f).unwrap(), want);
        }
    }
}
