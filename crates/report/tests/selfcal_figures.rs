//! `allan.png` of `gyroemu selfcal`, on a synthetic Allan result (no emulation: the figure is
//! what is under test): a panel of the phase output in degrees beside the rate-equivalent one
//! in deg/h, the readings in the title and the angle random walk's line on the rate panel.

use gyroemu_analysis::allan::fit::NoiseModelFit;
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
        scale_rel_ci95: 0.0,
        model_warning: None,
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
        model_fit: NoiseModelFit::not_fitted("not under test"),
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
        // Three significant figures: ARW = 2e-3 / 0.0418 * 60 = 2.8708 deg/sqrt(h).
        "Allan deviation at zero rate: ARW 2.87 deg/sqrt(h), bias instability 5.00 deg/h"
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

/// White rate noise N = 0.035 deg/s*sqrt(s) (ARW 2.1 deg/sqrt(h)) over a floor of B = 950
/// deg/h (they cross at 0.04 s), exact, from four 1000 s records at tau0 = 0.01 s: no -1/2
/// half decade to read an ARW from, so the fit's N is what the figure and warnings give.
fn fitted_allan() -> AllanResult {
    let (n, b) = (0.035f64, 950.0 / 3600.0);
    let floor2 = 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI * b * b;
    let rate: Vec<AllanPoint> = (0..33)
        .map(|k| {
            let t = 0.01 * 10f64.powf(k as f64 / 8.0);
            AllanPoint {
                tau_s: t,
                adev: (n * n / t + floor2).sqrt(),
                n_terms: 4 * (100_000 - 2 * (t / 0.01).round() as usize + 1),
            }
        })
        .collect();
    let readings = gyroemu_analysis::allan::noise_readings(&rate);
    AllanResult {
        tau0_s: 0.01,
        record_s: 1000.0,
        phase_deg: rate
            .iter()
            .map(|p| AllanPoint {
                adev: p.adev * SCALE,
                ..*p
            })
            .collect(),
        rate_dps: rate,
        readings,
        scale_deg_per_dps: SCALE,
        scale_rel_ci95: 0.0,
        model_warning: None,
    }
}

#[test]
fn the_noise_model_fit_is_drawn_named_and_warned() {
    let a = fitted_allan();
    let r = a.readings.unwrap();
    assert!(r.arw_deg_per_rt_h.is_nan(), "{r:?}");
    let f = r.model_fit;
    assert!((f.arw_deg_per_rt_h / 2.1 - 1.0).abs() < 1e-6, "{f:?}");
    assert!(
        (f.bias_instability_deg_per_h / 950.0 - 1.0).abs() < 1e-6,
        "{f:?}"
    );
    let [_, rate] = allan_panels(&a);
    // No ARW line; the fit's line over the taus it was fitted on, through the curve.
    assert_eq!(rate.series.len(), 2, "{:?}", rate.series);
    let line = &rate.series[1];
    assert_eq!(line.style, SeriesStyle::Line);
    assert_eq!(
        line.name,
        "noise-model fit (IEEE 952): N = 2.10 deg/sqrt(h), B = 950 deg/h"
    );
    assert_eq!(
        (line.xs[0], *line.xs.last().unwrap()),
        (f.tau_min_s, f.tau_max_s)
    );
    for p in a
        .rate_dps
        .iter()
        .filter(|p| p.tau_s >= f.tau_min_s && p.tau_s <= f.tau_max_s)
    {
        let i = line
            .xs
            .iter()
            .position(|&t| (t / p.tau_s - 1.0).abs() < 1e-9)
            .unwrap_or_else(|| panic!("tau {} not on the line", p.tau_s));
        assert!((line.ys[i] / (p.adev * 3600.0) - 1.0).abs() < 1e-6);
    }
    let title = allan_title(&a);
    assert!(
        title.contains("ARW not read (see warnings), bias instability"),
        "{title}"
    );
    assert!(
        title.ends_with("; noise-model fit (IEEE 952): N = 2.10 deg/sqrt(h), B = 950 deg/h"),
        "{title}"
    );
    // The run's warnings give the fit's N beside the refusal.
    let fit_note = |a: &AllanResult| {
        a.warnings()
            .into_iter()
            .find(|w| w.contains("noise-model fit"))
    };
    let note = fit_note(&a).unwrap();
    assert!(
        note.contains("reads N = 2.10 deg/sqrt(h) (95 %: ") && note.contains("B = 950 deg/h"),
        "{note}"
    );
    // None where the slope reading gave an ARW.
    let mut read = a.clone();
    read.readings = Some(readings(2.0, 90.0));
    assert_eq!(fit_note(&read), None);
}

#[test]
fn allan_readings_keep_their_json_keys() {
    // The fit is written beside the readings (`allan.model_fit`), not inside them.
    let v = serde_json::to_value(fitted_allan().readings.unwrap()).unwrap();
    let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(|k| k.as_str()).collect();
    keys.sort();
    assert_eq!(
        keys,
        [
            "arw_deg_per_rt_h",
            "arw_tau_s",
            "arw_warning",
            "bias_instability_deg_per_h",
            "bias_instability_warning",
            "tau_at_min_s"
        ]
    );
}
