//! `allan.png` of `gyroemu selfcal`, on a synthetic Allan result (no emulation: the figure is
//! what is under test): a panel of the phase output in degrees beside the rate-equivalent one
//! in deg/h, the readings in the title and the angle random walk's line on the rate panel.

use gyroemu_analysis::allan::{AllanPoint, NoiseReadings};
use gyroemu_analysis::selfcal_analyses::AllanResult;
use gyroemu_plot::SeriesStyle;
use gyroemu_report::selfcal_report::{allan_panels, allan_title, render_allan_png};

const SCALE: f64 = 0.0418;

/// White phase noise, sigma = 2e-3 deg / sqrt(tau), over 0.01 to 100 s, and its rate
/// equivalent (phase over `SCALE`), with the given readings.
fn allan(readings: Option<NoiseReadings>) -> AllanResult {
    let taus: Vec<f64> = (0..=16)
        .map(|k| 0.01 * 10f64.powf(k as f64 / 4.0))
        .collect();
    let curve = |scale: f64| -> Vec<AllanPoint> {
        taus.iter()
            .map(|&t| AllanPoint {
                tau_s: t,
                adev: 2e-3 / t.sqrt() / scale,
                n_terms: 1000,
            })
            .collect()
    };
    AllanResult {
        tau0_s: 0.01,
        record_s: 1000.0,
        phase_deg: curve(1.0),
        rate_dps: curve(SCALE),
        readings,
        scale_deg_per_dps: SCALE,
    }
}

fn readings(arw: f64, bi: f64) -> NoiseReadings {
    NoiseReadings {
        arw_deg_per_rt_h: arw,
        arw_tau_s: [0.1, 10.0],
        arw_warning: None,
        bias_instability_deg_per_h: bi,
        tau_at_min_s: 100.0,
        bias_instability_warning: None,
    }
}

#[test]
fn the_phase_deviation_has_its_own_panel_in_degrees() {
    let arw = 2e-3 / SCALE * 60.0;
    let a = allan(Some(readings(arw, 5.0)));
    let [phase, rate] = allan_panels(&a);
    // The phase panel: the measured phase deviation, in degrees, as allan.csv's adev_phase_deg.
    assert!(phase.y_label.contains("phase") && phase.y_label.ends_with("(deg)"));
    assert!(phase.x_log && phase.y_log);
    assert_eq!(phase.series.len(), 1, "{:?}", phase.series);
    let p = &phase.series[0];
    assert_eq!(p.style, SeriesStyle::Points);
    assert_eq!(
        p.xs,
        a.phase_deg.iter().map(|q| q.tau_s).collect::<Vec<_>>()
    );
    assert_eq!(p.ys, a.phase_deg.iter().map(|q| q.adev).collect::<Vec<_>>());
    // The rate panel keeps the deg/h curve and the ARW line, and names the scale factor.
    assert!(rate.y_label.ends_with("(deg/h)"));
    assert!(
        rate.title.contains("0.041800 deg per deg/s"),
        "{}",
        rate.title
    );
    assert_eq!(
        rate.series[0].ys,
        a.rate_dps
            .iter()
            .map(|q| q.adev * 3600.0)
            .collect::<Vec<_>>()
    );
    let arw_line = &rate.series[1];
    assert_eq!(arw_line.name, "angle random walk: N / sqrt(tau)");
    // N / sqrt(tau) in deg/h goes through the white curve.
    for (t, y) in arw_line.xs.iter().zip(&arw_line.ys) {
        let want = 2e-3 / t.sqrt() / SCALE * 3600.0;
        assert!((y / want - 1.0).abs() < 1e-12, "{t}: {y} vs {want}");
    }
    // The two curves differ by the scale factor alone.
    for (p, r) in p.ys.iter().zip(&rate.series[0].ys) {
        assert!((r / 3600.0 * SCALE / p - 1.0).abs() < 1e-12);
    }
    assert_eq!(
        allan_title(&a),
        format!("Allan deviation at zero rate: ARW {arw:.3e} deg/sqrt(h), bias instability 5.000e0 deg/h")
    );
}

#[test]
fn readings_not_taken_say_so_and_draw_no_arw_line() {
    let a = allan(Some(readings(f64::NAN, f64::NAN)));
    let title = allan_title(&a);
    assert_eq!(
        title,
        "Allan deviation at zero rate: ARW not read (see warnings), bias instability not read (see warnings)"
    );
    let [phase, rate] = allan_panels(&a);
    assert_eq!((phase.series.len(), rate.series.len()), (1, 1));
    assert_eq!(allan_title(&allan(None)), "Allan deviation at zero rate");
}

#[test]
fn allan_png_holds_both_panels() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("allan.png");
    render_allan_png(&allan(Some(readings(1.0, 5.0))), &path).unwrap();
    // Two panels side by side: 1600 x 650 px (the rate-only figure was 900 x 650).
    let png = std::fs::read(&path).unwrap();
    assert_eq!(&png[12..16], b"IHDR");
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    assert_eq!((be(&png[16..20]), be(&png[20..24])), (1600, 650));
}
