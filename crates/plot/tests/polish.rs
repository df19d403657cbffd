//! Figure polish: coincident series stay visible, PNGs are anti-aliased, log axes space
//! decades evenly, markers land at their abscissa.

use gyroemu_plot::{
    downsample_rgb, render_rgb, render_rgb_antialiased, Figure, Series, SeriesStyle, PALETTE,
};
use std::collections::HashSet;

fn count(img: &[u8], c: plotters::style::RGBColor) -> usize {
    img.chunks(3).filter(|p| p == &[c.0, c.1, c.2]).count()
}

#[test]
fn coincident_series_all_show_their_colour() {
    let xs: Vec<f64> = (0..12).map(f64::from).collect();
    let ys: Vec<f64> = xs.iter().map(|x| 0.5 * x).collect();
    let fig = Figure::new("", "x", "y")
        .with(Series::new(
            "mode 1",
            SeriesStyle::Points,
            xs.clone(),
            ys.clone(),
        ))
        .with(Series::new(
            "mode 2",
            SeriesStyle::Points,
            xs.clone(),
            ys.clone(),
        ))
        .with(Series::new(
            "theory",
            SeriesStyle::Line,
            xs.clone(),
            ys.clone(),
        ))
        .with(Series::new(
            "estimate",
            SeriesStyle::OpenPoints,
            xs.clone(),
            ys.clone(),
        ))
        .with(Series::new("cross", SeriesStyle::OpenPoints, xs, ys));
    let img = render_rgb(&fig).unwrap();
    // Each series paints well beyond its legend glyph: 12 markers (or the line) of its own
    // (the two hollow ones as nested rings).
    for (i, want) in [(0, 200), (1, 150), (2, 150), (3, 150), (4, 150)] {
        let n = count(&img, PALETTE[i]);
        assert!(n > want, "series {i} shows {n} pixels of its colour");
    }
}

#[test]
fn downsampling_keeps_the_mean_intensity() {
    let (w, h) = (64usize, 38usize);
    let mut s: u32 = 12345;
    let src: Vec<u8> = (0..w * h * 3)
        .map(|_| {
            s = s.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            (s >> 16) as u8
        })
        .collect();
    let out = downsample_rgb(&src, w, h, 2);
    assert_eq!(out.len(), w * h * 3 / 4);
    let mean = |v: &[u8]| v.iter().map(|&b| f64::from(b)).sum::<f64>() / v.len() as f64;
    // Each output level is the block mean rounded to nearest: within half a level on average.
    assert!(
        (mean(&out) - mean(&src)).abs() <= 0.5,
        "{} vs {}",
        mean(&out),
        mean(&src)
    );
    // A uniform block stays exactly its value.
    assert_eq!(downsample_rgb(&[7u8; 12], 2, 2, 2), vec![7, 7, 7]);
    // The 2 x 2 fast path equals the general block average (k = 2 against a direct sum).
    let out2 = downsample_rgb(&src, w, h, 2);
    for oy in 0..h / 2 {
        for ox in 0..w / 2 {
            for c in 0..3 {
                let at = |x: usize, y: usize| u32::from(src[(y * w + x) * 3 + c]);
                let sum = at(2 * ox, 2 * oy)
                    + at(2 * ox + 1, 2 * oy)
                    + at(2 * ox, 2 * oy + 1)
                    + at(2 * ox + 1, 2 * oy + 1);
                assert_eq!(u32::from(out2[(oy * (w / 2) + ox) * 3 + c]), (sum + 2) / 4);
            }
        }
    }
    // k = 3 (the general path) on a 6 x 3 image: two output pixels.
    let px: Vec<u8> = (0..54).map(|i| (i * 5) as u8).collect();
    let o3 = downsample_rgb(&px, 6, 3, 3);
    let want = |ox: usize, c: usize| {
        let s: u32 = (0..3)
            .flat_map(|y| (0..3).map(move |x| (x, y)))
            .map(|(x, y)| u32::from(px[(y * 6 + 3 * ox + x) * 3 + c]))
            .sum();
        ((s + 4) / 9) as u8
    };
    assert_eq!(
        o3,
        (0..2)
            .flat_map(|ox| (0..3).map(move |c| want(ox, c)))
            .collect::<Vec<_>>()
    );
}

#[test]
fn png_markers_are_anti_aliased() {
    // plotters fills circles and rings without anti-aliasing (their edges step by whole
    // pixels); the PNG path draws at twice the size and averages, so edges blend.
    let fig = Figure::new("", "", "")
        .with(Series::new(
            "",
            SeriesStyle::Points,
            vec![0.0, 0.5, 1.0],
            vec![0.0, 0.37, 0.5],
        ))
        .with(Series::new(
            "",
            SeriesStyle::OpenPoints,
            vec![0.25, 0.75],
            vec![0.1, 0.2],
        ));
    let (w, h) = (fig.width_px as usize, fig.height_px as usize);
    let interior = |img: &[u8]| -> HashSet<[u8; 3]> {
        (h / 4..3 * h / 4)
            .flat_map(|y| (w / 4..3 * w / 4).map(move |x| (x, y)))
            .map(|(x, y)| {
                let o = (y * w + x) * 3;
                [img[o], img[o + 1], img[o + 2]]
            })
            .collect()
    };
    let plain = interior(&render_rgb(&fig).unwrap());
    let smooth = interior(&render_rgb_antialiased(&fig).unwrap());
    // plotters blends a few edge pixels of its own; averaging adds many more shades.
    assert!(
        smooth.len() > 3 * plain.len(),
        "{} shades anti-aliased, {} plain",
        smooth.len(),
        plain.len()
    );
}

#[test]
fn log_axis_spaces_decades_evenly() {
    let fig = Figure::new("", "x", "y")
        .with(Series::new(
            "",
            SeriesStyle::Points,
            vec![1.0, 2.0, 3.0, 4.0],
            vec![1e-12, 1e-6, 1.0, 0.0],
        ))
        .log_y();
    let img = render_rgb(&fig).unwrap();
    let w = fig.width_px as usize;
    let c = PALETTE[0];
    let rows: Vec<(usize, usize)> = img
        .chunks(3)
        .enumerate()
        .filter(|(_, p)| p == &[c.0, c.1, c.2])
        .map(|(i, _)| (i % w, i / w))
        .collect();
    // Three markers (0 has no logarithm): centroids by column band.
    let xs: Vec<usize> = rows.iter().map(|p| p.0).collect();
    let (x_min, x_max) = (*xs.iter().min().unwrap(), *xs.iter().max().unwrap());
    let third = (x_max - x_min) / 3;
    let cy = |lo: usize, hi: usize| {
        let v: Vec<f64> = rows
            .iter()
            .filter(|p| p.0 >= lo && p.0 <= hi)
            .map(|p| p.1 as f64)
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let (a, b, d) = (
        cy(x_min, x_min + third / 2),
        cy(x_min + third, x_max - third),
        cy(x_max - third / 2, x_max),
    );
    assert!(a > b && b > d, "{a} {b} {d}");
    assert!(
        ((a - b) - (b - d)).abs() < 2.0,
        "6 decades: {} px then {} px",
        a - b,
        b - d
    );
}

#[test]
fn markers_draw_a_dashed_line_at_their_abscissa() {
    let fig = Figure::new("", "x", "y")
        .with(Series::new(
            "",
            SeriesStyle::Line,
            vec![0.0, 10.0],
            vec![0.0, 1.0],
        ))
        .with_marker(5.0, "f0");
    let img = render_rgb(&fig).unwrap();
    let w = fig.width_px as usize;
    let grey = [70u8, 70, 70];
    let cols: Vec<usize> = img
        .chunks(3)
        .enumerate()
        .filter(|(_, p)| *p == grey)
        .map(|(i, _)| i % w)
        .collect();
    assert!(cols.len() > 100, "{} marker pixels", cols.len());
    // The line's column is the most common one; x = 5 lies mid-way between the 5 % margins.
    let mut hist = std::collections::HashMap::new();
    for c in cols {
        *hist.entry(c).or_insert(0) += 1;
    }
    let (col, _) = hist.into_iter().max_by_key(|e| e.1).unwrap();
    let without = render_rgb(&Figure {
        markers: Vec::new(),
        ..fig.clone()
    })
    .unwrap();
    assert_eq!(without.chunks(3).filter(|p| *p == grey).count(), 0);
    assert!(
        (col as f64 - w as f64 / 2.0).abs() < 0.1 * w as f64,
        "marker at column {col}"
    );
}

/// A legend never hides data: with data in all four corners, the y axis grows to make room
/// for it. Every marker of a 5 x 5 grid (linear, and decades on a log axis) keeps all its pixels
/// of its exact colour (a marker under the legend's 90 % white box loses them) against the
/// same figure without a legend.
#[test]
fn a_legend_with_every_corner_busy_hides_no_marker() {
    for log in [false, true] {
        let grid: Vec<(f64, f64)> = (0..25)
            .map(|k| (f64::from(k % 5), f64::from(k / 5)))
            .map(|(x, y)| (x, if log { 10f64.powf(y) } else { y }))
            .collect();
        let data = Series::new(
            "",
            SeriesStyle::Points,
            grid.iter().map(|p| p.0).collect(),
            grid.iter().map(|p| p.1).collect(),
        );
        let mut bare = Figure::new("", "x", "y").with(data);
        if log {
            bare = bare.log_y();
        }
        // The legend's one entry draws nothing in the plot (no finite point), in its own colour.
        let named = bare.clone().with(Series::new(
            "a legend entry of some length",
            SeriesStyle::Points,
            vec![f64::NAN],
            vec![f64::NAN],
        ));
        let without = count(&render_rgb(&bare).unwrap(), PALETTE[0]);
        let with = count(&render_rgb(&named).unwrap(), PALETTE[0]);
        assert!(
            without > 25 * 20,
            "log {log}: {without} pixels for 25 markers"
        );
        assert_eq!(with, without, "log {log}: markers hidden under the legend");
    }
}
