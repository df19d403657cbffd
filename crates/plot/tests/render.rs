//! PNG output, text presence, geometry, degenerate inputs and atomicity.

use gyroemu_plot::{
    render_panels_png, render_png, render_png_copies, render_rgb, render_rgb_antialiased, Figure,
    PlotError, Series, SeriesStyle, PALETTE,
};
use std::path::Path;

/// (width, height, bit depth, colour type) from a PNG's signature and IHDR chunk (PNG spec 11.2.2).
fn png_header(path: &Path) -> (u32, u32, u8, u8) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "not a PNG signature");
    assert_eq!(
        &b[8..16],
        b"\0\0\0\x0dIHDR",
        "first chunk must be a 13-byte IHDR"
    );
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    assert_eq!(
        &b[b.len() - 12..],
        b"\0\0\0\0IEND\xaeB`\x82",
        "PNG must end with IEND"
    );
    (be(16), be(20), b[24], b[25])
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn demo(title: &str) -> Figure {
    let xs: Vec<f64> = (0..200).map(|i| i as f64 * 0.05).collect();
    let ys: Vec<f64> = xs.iter().map(|x| (x * 1.3).sin() * 2.0).collect();
    Figure::new(title, "Time (s)", "Rate (deg/s)")
        .with(Series::new(
            "model",
            SeriesStyle::Line,
            xs.clone(),
            ys.clone(),
        ))
        .with(Series::new(
            "limit",
            SeriesStyle::DashedLine,
            xs.clone(),
            vec![1.5; 200],
        ))
        .with(Series::new(
            "board",
            SeriesStyle::Points,
            xs.iter().step_by(10).copied().collect(),
            ys.iter().step_by(10).copied().collect(),
        ))
}

/// Near-black pixel (text, axes, frame); palette colours 0-7 and the grey grid are not.
fn dark(p: &[u8]) -> bool {
    p.iter().all(|&c| c < 100)
}

struct Img {
    w: usize,
    h: usize,
    px: Vec<u8>,
}
impl Img {
    fn at(&self, x: usize, y: usize) -> &[u8] {
        &self.px[(y * self.w + x) * 3..(y * self.w + x) * 3 + 3]
    }
    /// Frame of the plot: first/last rows and columns with a dark run over 40 % of the image
    /// (unbroken: a long bold title darkens that many pixels of a row, in pieces).
    fn frame(&self) -> (usize, usize, usize, usize) {
        let longest_run = |dark_at: &mut dyn Iterator<Item = bool>| {
            dark_at
                .scan(0, |run, d| {
                    *run = if d { *run + 1 } else { 0 };
                    Some(*run)
                })
                .max()
                .unwrap_or(0)
        };
        let row_dark =
            |y: usize| longest_run(&mut (0..self.w).map(|x| dark(self.at(x, y)))) > self.w * 2 / 5;
        let col_dark =
            |x: usize| longest_run(&mut (0..self.h).map(|y| dark(self.at(x, y)))) > self.h * 2 / 5;
        let top = (0..self.h).find(|&y| row_dark(y)).unwrap();
        let bottom = (0..self.h).rev().find(|&y| row_dark(y)).unwrap();
        let left = (0..self.w).find(|&x| col_dark(x)).unwrap();
        let right = (0..self.w).rev().find(|&x| col_dark(x)).unwrap();
        (left, right, top, bottom)
    }
    /// The first and last columns holding ink (any non-white pixel) in rows `ys`.
    fn ink_columns(&self, ys: std::ops::Range<usize>) -> Option<(usize, usize)> {
        let inked = |x: usize| ys.clone().any(|y| self.at(x, y) != [255; 3]);
        Some((
            (0..self.w).find(|&x| inked(x))?,
            (0..self.w).rfind(|&x| inked(x))?,
        ))
    }
    fn dark_in(&self, xs: std::ops::Range<usize>, ys: std::ops::Range<usize>) -> usize {
        ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
            .filter(|&(x, y)| dark(self.at(x, y)))
            .count()
    }
}

fn rgb(fig: &Figure) -> Img {
    Img {
        w: fig.width_px as usize,
        h: fig.height_px as usize,
        px: render_rgb(fig).unwrap(),
    }
}

#[test]
fn png_has_signature_and_requested_size() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("fig.png");
    render_png(&demo("Demo"), &p).unwrap();
    assert_eq!(png_header(&p), (900, 650, 8, 2)); // 8-bit RGB
    let mut f = demo("Small");
    f.width_px = 640;
    f.height_px = 480;
    render_png(&f, &p).unwrap();
    assert_eq!(png_header(&p).0, 640);
    assert_eq!(png_header(&p).1, 480);
    assert_eq!(entries(dir.path()), vec!["fig.png"]);
}

/// Text only exists if the bundled font loaded and rasterised: the strip above the frame holds
/// only the title and the strip left of the frame only tick labels and the axis label.
#[test]
fn title_and_labels_are_drawn_with_the_bundled_font() {
    let with = rgb(&demo("Frequency response of mode 1"));
    let mut without = demo("");
    without.y_label = String::new();
    let without = rgb(&without);
    let (l, _, t, _) = with.frame();
    let title_ink = with.dark_in(0..with.w, 0..t.saturating_sub(2));
    let (l0, _, t0, _) = without.frame();
    let no_title_ink = without.dark_in(0..without.w, 0..t0.saturating_sub(2));
    assert!(title_ink > 300, "title strip has {title_ink} dark pixels");
    assert_eq!(
        no_title_ink, 0,
        "nothing but the title belongs above the frame"
    );
    // Left of the frame, minus the 5 px tick marks: tick labels (+ the rotated y label).
    let ylab_ink = with.dark_in(0..l - 8, t..with.h);
    let ticks_only_ink = without.dark_in(0..l0 - 8, t0..without.h);
    assert!(
        ticks_only_ink > 100,
        "tick labels drew {ticks_only_ink} dark pixels"
    );
    assert!(
        ylab_ink > ticks_only_ink + 200,
        "y label added only {} dark pixels",
        ylab_ink - ticks_only_ink
    );
}

/// A title too long for its figure shrinks to fit inside it, and the frame stays where a
/// full-size title puts it (so panels side by side line up); a short one keeps its size.
#[test]
fn a_long_title_shrinks_to_fit_its_figure() {
    let xs: Vec<f64> = (0..12).map(f64::from).collect();
    let line = |title: &str| {
        Figure::new(title, "x", "y").with(Series::new(
            "a",
            SeriesStyle::Line,
            xs.clone(),
            xs.clone(),
        ))
    };
    // About 1.4 times the width at the title's full size: plotters centres it and cuts both
    // ends at the figure's edges.
    let long = "Low-pass output (decimated): Ω (3.50 Hz) unresolved in 93.8 Hz bins; the 2 fc residual aliases onto DC, twice over";
    // Plain, then supersampled (the PNGs'), where every length is doubled.
    for antialiased in [false, true] {
        let img = |title: &str| {
            let fig = line(title);
            let px = if antialiased {
                render_rgb_antialiased(&fig)
            } else {
                render_rgb(&fig)
            };
            Img {
                w: fig.width_px as usize,
                h: fig.height_px as usize,
                px: px.unwrap(),
            }
        };
        let (shrunk, short) = (img(long), img("Fits"));
        let (_, _, top, _) = shrunk.frame();
        let w = shrunk.w;
        let (lo, hi) = shrunk.ink_columns(0..top - 2).expect("the title is drawn");
        assert!(
            lo >= 8 && hi <= w - 8,
            "title ink in columns {lo} to {hi} of {w}"
        );
        // Spread over most of the width: shrunk to fit, not to nothing.
        assert!(
            hi - lo > w * 8 / 10,
            "title ink in columns {lo} to {hi} of {w}"
        );
        // A title that fits is not stretched to the width: `Fits` stays a word wide.
        let (_, _, top_short, _) = short.frame();
        let (slo, shi) = short
            .ink_columns(0..top_short - 2)
            .expect("the title is drawn");
        assert!(shi - slo < w / 10, "{slo} to {shi}");
        assert_eq!(top, top_short, "the frame moved under the shrunk title");
    }
}

/// Two markers at the data extremes land 0.5/11 and 10.5/11 of the way across the frame
/// (5 % margins on each side of the data span).
#[test]
fn data_map_to_the_frame_with_five_percent_margins() {
    let fig = Figure::new("", "x (m)", "y (V)").with(Series::new(
        "",
        SeriesStyle::Points,
        vec![0.0, 10.0],
        vec![-1.0, 3.0],
    ));
    let img = rgb(&fig);
    let (l, r, t, b) = img.frame();
    let c = PALETTE[0];
    let blue: Vec<(usize, usize)> = (0..img.h)
        .flat_map(|y| (0..img.w).map(move |x| (x, y)))
        .filter(|&(x, y)| img.at(x, y) == [c.0, c.1, c.2])
        .collect();
    let centroid = |pts: Vec<&(usize, usize)>| {
        let n = pts.len() as f64;
        assert!(n > 10.0);
        (
            pts.iter().map(|p| p.0 as f64).sum::<f64>() / n,
            pts.iter().map(|p| p.1 as f64).sum::<f64>() / n,
        )
    };
    let mid = (l + r) / 2;
    let p0 = centroid(blue.iter().filter(|p| p.0 < mid).collect());
    let p1 = centroid(blue.iter().filter(|p| p.0 >= mid).collect());
    let fx = |u: f64| l as f64 + u * (r - l) as f64;
    let fy = |u: f64| b as f64 - u * (b - t) as f64;
    let (a, z) = (0.5 / 11.0, 10.5 / 11.0);
    for (got, want) in [(p0, (fx(a), fy(a))), (p1, (fx(z), fy(z)))] {
        assert!(
            (got.0 - want.0).abs() < 2.0 && (got.1 - want.1).abs() < 2.0,
            "marker at {got:?}, expected {want:?}"
        );
    }
}

#[test]
fn degenerate_inputs_render_without_panicking() {
    let dir = tempfile::tempdir().unwrap();
    let nan = f64::NAN;
    let cases: Vec<Vec<Series>> = vec![
        vec![],
        vec![Series::new("empty", SeriesStyle::Line, vec![], vec![])],
        vec![Series::new(
            "all NaN",
            SeriesStyle::Points,
            vec![nan, nan],
            vec![nan, 1.0],
        )],
        vec![Series::new(
            "one point",
            SeriesStyle::Line,
            vec![3.0],
            vec![-2.0],
        )],
        vec![Series::new(
            "flat",
            SeriesStyle::DashedLine,
            vec![1.0, 1.0, 1.0],
            vec![5.0, 5.0, 5.0],
        )],
        vec![Series::new(
            "zeros",
            SeriesStyle::Points,
            vec![0.0; 4],
            vec![0.0; 4],
        )],
        vec![Series::new(
            "gaps",
            SeriesStyle::Line,
            vec![0.0, 1.0, nan, 3.0, 4.0, f64::INFINITY],
            vec![1.0, nan, 2.0, 3.0, 4.0, 5.0],
        )],
        vec![Series::new(
            "len mismatch",
            SeriesStyle::Line,
            vec![0.0, 1.0, 2.0],
            vec![1.0],
        )],
        vec![Series::new(
            "huge",
            SeriesStyle::Points,
            vec![-f64::MAX, f64::MAX],
            vec![1e300, -1e300],
        )],
        vec![Series::new(
            "tiny span",
            SeriesStyle::Line,
            vec![1e-18, 1e-18 + 1e-33],
            vec![20_000.0, 20_000.0 + 1e-12],
        )],
        vec![Series::new(
            "subnormal",
            SeriesStyle::Points,
            vec![5e-324, 1e-320],
            vec![-5e-324, 0.0],
        )],
    ];
    for (i, series) in cases.into_iter().enumerate() {
        let mut fig = Figure::new(format!("case {i} µ°Ω"), "", "");
        fig.series = series;
        render_png(&fig, &dir.path().join(format!("c{i}.png"))).unwrap();
        fig.width_px = 64;
        fig.height_px = 64;
        render_png(&fig, &dir.path().join(format!("s{i}.png"))).unwrap();
        assert_eq!(png_header(&dir.path().join(format!("s{i}.png"))).0, 64);
    }
}

#[test]
fn panels_render_in_a_grid() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("panels.png");
    let figs = [demo("mode 1"), demo("mode 2"), demo("inset")];
    render_panels_png("Both modes", &figs, 2, 1400, 1000, &p).unwrap();
    assert_eq!(png_header(&p).0, 1400);
    assert_eq!(png_header(&p).1, 1000);
    render_panels_png("", &[], 3, 600, 400, &p).unwrap();
    assert!(matches!(
        render_panels_png("x", &figs, 0, 800, 600, &p),
        Err(PlotError::InvalidLayout { .. })
    ));
    assert!(matches!(
        render_panels_png("x", &figs, 3, 200, 200, &p),
        Err(PlotError::InvalidLayout { .. })
    ));
    assert_eq!(entries(dir.path()), vec!["panels.png"]);
}

#[test]
fn failed_renders_leave_nothing_under_the_final_name() {
    let dir = tempfile::tempdir().unwrap();
    // Missing directory: refused at temp-file creation, naming the path.
    let missing = dir.path().join("nope").join("f.png");
    let e = render_png(&demo("x"), &missing).unwrap_err();
    assert!(e.to_string().contains("nope"), "{e}");
    assert!(!missing.exists());

    // Existing target kept when the request is refused.
    let keep = dir.path().join("keep.png");
    std::fs::write(&keep, b"old").unwrap();
    let mut bad = demo("x");
    bad.width_px = 0;
    assert!(matches!(
        render_png(&bad, &keep),
        Err(PlotError::InvalidSize { .. })
    ));
    assert!(matches!(
        render_png(&demo("x"), &dir.path().join("f.jpeg")),
        Err(PlotError::InvalidLayout { .. })
    ));

    // Failure at the very end: the target name is a directory, so the rename fails after a
    // complete render; the temporary PNG must be gone.
    let blocker = dir.path().join("blocked.png");
    std::fs::create_dir(&blocker).unwrap();
    std::fs::write(blocker.join("inside"), b"x").unwrap();
    let e = render_png(&demo("x"), &blocker).unwrap_err();
    assert!(e.to_string().contains("blocked.png"), "{e}");
    assert!(blocker.is_dir());
    assert_eq!(std::fs::read(&keep).unwrap(), b"old");
    assert_eq!(entries(dir.path()), vec!["blocked.png", "keep.png"]);
}

/// One figure under several names: each file has the bytes `render_png` writes alone, and a
/// name refused before drawing writes none of them.
#[test]
fn copies_have_the_bytes_of_a_render_and_a_refused_name_writes_none() {
    let dir = tempfile::tempdir().unwrap();
    let [alone, a, b] = ["alone.png", "a.png", "b.png"].map(|f| dir.path().join(f));
    render_png(&demo("Copies"), &alone).unwrap();
    render_png_copies(&demo("Copies"), &[&a, &b]).unwrap();
    let want = std::fs::read(&alone).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), want);
    assert_eq!(std::fs::read(&b).unwrap(), want);
    // A different figure gives different bytes (the comparison above can fail).
    render_png(&demo("Other"), &alone).unwrap();
    assert_ne!(std::fs::read(&alone).unwrap(), want);

    let (c, jpeg) = (dir.path().join("c.png"), dir.path().join("d.jpeg"));
    assert!(matches!(
        render_png_copies(&demo("x"), &[&c, &jpeg]),
        Err(PlotError::InvalidLayout { .. })
    ));
    assert!(!c.exists() && !jpeg.exists());
    // No names: nothing drawn, nothing written.
    render_png_copies(&demo("x"), &[]).unwrap();
    assert_eq!(entries(dir.path()), vec!["a.png", "alone.png", "b.png"]);
}

/// A figure's file has the bytes `image`'s PNG encoder (what plotters' bitmap backend saves
/// with) gives for the figure's pixels: the encoding is `image`'s, whatever path writes it.
#[test]
fn files_have_the_bytes_of_image_for_their_pixels() {
    use image::ImageEncoder;
    let dir = tempfile::tempdir().unwrap();
    let mut small = demo("Small");
    (small.width_px, small.height_px) = (300, 200);
    for fig in [demo("Bytes"), small] {
        let path = dir.path().join("f.png");
        render_png(&fig, &path).unwrap();
        let rgb = gyroemu_plot::render_rgb_antialiased(&fig).unwrap();
        let mut want = Vec::new();
        image::codecs::png::PngEncoder::new(&mut want)
            .write_image(&rgb, fig.width_px, fig.height_px, image::ColorType::Rgb8)
            .unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), want, "{}", fig.title);
    }
}

/// Figures drawn into buffers kept from earlier figures (larger, smaller, drawn at once on
/// several threads) come out as when drawn first: no pixel of an earlier figure survives.
#[test]
fn kept_buffers_leave_nothing_of_earlier_figures() {
    let dir = tempfile::tempdir().unwrap();
    let small = {
        let mut f = demo("small");
        (f.width_px, f.height_px) = (300, 200);
        f
    };
    let first_png = dir.path().join("first.png");
    render_png(&small, &first_png).unwrap();
    let first_rgb = gyroemu_plot::render_rgb_antialiased(&small).unwrap();
    // Larger figures, some at once, leave their buffers behind.
    std::thread::scope(|s| {
        for t in 0..4 {
            let dir = dir.path();
            s.spawn(move || {
                let mut big = demo(&format!("big {t}"));
                (big.width_px, big.height_px) = (1400, 1000);
                render_png(&big, &dir.join(format!("big{t}.png"))).unwrap();
                render_panels_png(
                    "panels",
                    &[big.clone(), big],
                    2,
                    1600,
                    900,
                    &dir.join(format!("p{t}.png")),
                )
                .unwrap();
            });
        }
    });
    let again_png = dir.path().join("again.png");
    render_png(&small, &again_png).unwrap();
    assert_eq!(
        std::fs::read(&first_png).unwrap(),
        std::fs::read(&again_png).unwrap()
    );
    assert!(gyroemu_plot::render_rgb_antialiased(&small).unwrap() == first_rgb);
}
