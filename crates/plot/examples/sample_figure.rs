//! Renders a sample paper-style figure and a two-panel figure:
//! `cargo run --release -p gyroemu-plot --example sample_figure -- /tmp/plot_sample.png`

use gyroemu_plot::{render_panels_png, render_png, Figure, Series, SeriesStyle};
use std::path::PathBuf;

/// Lorentzian amplitude of a resonator with centre `f0_hz` and quality factor `q`.
fn resonance(f_hz: f64, f0_hz: f64, q: f64) -> f64 {
    let r = f_hz / f0_hz;
    1.0 / ((1.0 - r * r).powi(2) + (r / q).powi(2)).sqrt()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "/tmp/plot_sample.png".into()),
    );
    let f: Vec<f64> = (0..400).map(|i| 19_900.0 + 0.5 * i as f64).collect();
    let model: Vec<f64> = f
        .iter()
        .map(|&x| 2.0e-9 * resonance(x, 20_000.0, 2000.0))
        .collect();
    let mode2: Vec<f64> = f
        .iter()
        .map(|&x| 2.0e-9 * resonance(x, 20_040.0, 1500.0))
        .collect();
    let fm: Vec<f64> = f.iter().step_by(16).copied().collect();
    let meas: Vec<f64> = fm
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            2.0e-9
                * resonance(x, 20_000.0, 2000.0)
                * (1.0 + 0.03 * ((i * 7 % 5) as f64 - 2.0) / 2.0)
        })
        .collect();
    let fig = Figure::new(
        "Drive-mode frequency response",
        "Frequency (Hz)",
        "Displacement amplitude (m)",
    )
    .with(Series::new(
        "Measured (board)",
        SeriesStyle::Points,
        fm,
        meas,
    ))
    .with(Series::new(
        "Model, mode 1",
        SeriesStyle::Line,
        f.clone(),
        model.clone(),
    ))
    .with(Series::new(
        "Model, mode 2",
        SeriesStyle::DashedLine,
        f.clone(),
        mode2.clone(),
    ));
    render_png(&fig, &out)?;

    let phase: Vec<f64> = f
        .iter()
        .map(|&x| {
            let r = x / 20_000.0;
            -(r / 2000.0).atan2(1.0 - r * r).to_degrees()
        })
        .collect();
    let p1 = Figure::new("Mode 1", "Frequency (Hz)", "Amplitude (m)").with(Series::new(
        "mode 1",
        SeriesStyle::Line,
        f.clone(),
        model,
    ));
    let p2 = Figure::new("Mode 1 phase", "Frequency (Hz)", "Phase (deg)").with(Series::new(
        "",
        SeriesStyle::Line,
        f,
        phase,
    ));
    let panels = out.with_file_name("plot_sample_panels.png");
    render_panels_png("Sense and drive modes", &[p1, p2], 2, 1400, 560, &panels)?;
    println!("wrote {} and {}", out.display(), panels.display());
    Ok(())
}
