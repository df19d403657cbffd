//! What `gyroemu sweep` writes: `sweep.csv` (the measured responses and the fitted models per
//! frequency), `sweep.json` (the fits beside the configured device, the coupled plant and the
//! exact expectation) and `bode.png` (magnitude and phase against frequency). Every file is
//! written atomically.

use crate::error::{create_dir, ReportError};
use crate::sweep_report::{health_json, with_config_warnings};
use gyroemu_analysis::freq_response::{FrequencyResponse, ModeCheck};
use gyroemu_analysis::resonance_fit::ResonanceFit;
use gyroemu_board::Health;
use gyroemu_config::Config;
use gyroemu_core::Complex64;
use gyroemu_io::{write_csv, write_json, CsvCell, CsvTable};
use gyroemu_plot::{render_panels_png, Figure, Series, SeriesStyle};
use serde_json::json;
use std::path::{Path, PathBuf};

/// The files `gyroemu sweep` writes.
pub const FREQ_SWEEP_FILES: [&str; 3] = ["sweep.csv", "sweep.json", "bode.png"];

/// The columns of `sweep.csv`: magnitudes in dB re 1 s (velocity per unit force per unit mass),
/// phases in degrees in (-180, 180].
pub const FREQ_SWEEP_COLUMNS: [&str; 13] = [
    "freq_hz",
    "mag_mode1_db",
    "phase_mode1_deg",
    "mag_mode2_db",
    "phase_mode2_deg",
    "cross_mag_1to2_db",
    "cross_phase_1to2_deg",
    "cross_mag_2to1_db",
    "cross_phase_2to1_deg",
    "fit_mag_mode1_db",
    "fit_phase_mode1_deg",
    "fit_mag_mode2_db",
    "fit_phase_mode2_deg",
];

/// Points of the fitted curves in `bode.png`.
const CURVE_POINTS: usize = 801;

/// `20 log10 |v|` (-inf for 0).
fn db(v: Complex64) -> f64 {
    20.0 * v.norm().log10()
}

/// The phase in degrees (NaN for 0, which has none).
fn deg(v: Complex64) -> f64 {
    if v.norm() == 0.0 {
        f64::NAN
    } else {
        v.arg().to_degrees()
    }
}

/// The fitted model of `fit` at `f` (NaN without a fit).
fn model(fit: Option<ResonanceFit>, f: f64) -> Complex64 {
    fit.map_or(Complex64::new(f64::NAN, f64::NAN), |r| r.response(f))
}

/// The rows of `sweep.csv`.
pub fn freq_sweep_table(r: &FrequencyResponse) -> CsvTable {
    let rows = r
        .measured
        .points
        .iter()
        .map(|p| {
            let f = p.freq_hz;
            let fits = [model(r.modes[0].fit, f), model(r.modes[1].fit, f)];
            let resp = p.response;
            [
                f,
                db(resp[0][0]),
                deg(resp[0][0]),
                db(resp[1][1]),
                deg(resp[1][1]),
                db(resp[0][1]),
                deg(resp[0][1]),
                db(resp[1][0]),
                deg(resp[1][0]),
                db(fits[0]),
                deg(fits[0]),
                db(fits[1]),
                deg(fits[1]),
            ]
            .into_iter()
            .map(CsvCell::F64)
            .collect()
        })
        .collect();
    CsvTable {
        headers: FREQ_SWEEP_COLUMNS.iter().map(|h| h.to_string()).collect(),
        rows,
    }
}

/// One mode's entry of `sweep.json`.
fn mode_json(m: &ModeCheck) -> serde_json::Value {
    let nan = f64::NAN;
    let fit = m.fit;
    let get = |f: fn(&ResonanceFit) -> f64| fit.as_ref().map_or(nan, f);
    let (f0, q) = (get(|r| r.f0_hz), get(|r| r.q));
    let expected = m.expected;
    let (ef0, eq) = (
        expected.map_or(nan, |r| r.f0_hz),
        expected.map_or(nan, |r| r.q),
    );
    json!({
        "mode": m.mode,
        "f0_hz": f0,
        "f0_sigma_hz": get(|r| r.f0_sigma_hz),
        "q": q,
        "q_sigma": get(|r| r.q_sigma),
        "gain_re": get(|r| r.gain_re),
        "gain_im": get(|r| r.gain_im),
        "rms_residual_rel": get(|r| r.rms_residual_rel),
        "configured_f0_hz": m.configured_f0_hz,
        "configured_q": m.configured_q,
        "f0_minus_configured_hz": f0 - m.configured_f0_hz,
        "f0_minus_configured_half_bandwidths": (f0 - m.configured_f0_hz) / m.configured_half_bandwidth_hz(),
        "q_over_configured_minus_1": q / m.configured_q - 1.0,
        "coupled_f0_hz": m.coupled_f0_hz,
        "coupled_q": m.coupled_q,
        "f0_minus_coupled_hz": f0 - m.coupled_f0_hz,
        "q_over_coupled_minus_1": q / m.coupled_q - 1.0,
        "expected_f0_hz": ef0,
        "expected_q": eq,
        "f0_minus_expected_hz": f0 - ef0,
        "q_over_expected_minus_1": q / eq - 1.0,
    })
}

/// The `matrix_fit` entry of `sweep.json`: the identified plant beside the configured one.
fn matrix_json(cfg: &Config, r: &FrequencyResponse) -> serde_json::Value {
    let Some(m) = r.matrix else {
        return serde_json::Value::Null;
    };
    let [(f1, _), (f2, _)] = cfg.mode_resonances_hz();
    let conf_f = [f1, f2];
    let conf_q = [r.modes[0].configured_q, r.modes[1].configured_q];
    let k = cfg.device.quadrature_coupling_rad2_s2;
    json!({
        "f0_hz": m.f0_hz,
        "q": m.q,
        "coupling_rad2_s2": m.coupling_rad2_s2,
        "coupling_21_rad2_s2": m.coupling_21_rad2_s2,
        "damping_coupling_rad_s": m.damping_coupling_rad_s,
        "mass": m.mass,
        "frequencies": m.frequencies,
        "configured_coupling_rad2_s2": k,
        "f0_minus_configured_hz": [m.f0_hz[0] - conf_f[0], m.f0_hz[1] - conf_f[1]],
        "q_over_configured_minus_1": [m.q[0] / conf_q[0] - 1.0, m.q[1] / conf_q[1] - 1.0],
        "coupling_minus_configured_rad2_s2": m.coupling_rad2_s2 - k,
    })
}

/// The contents of `sweep.json`.
pub fn freq_sweep_summary(cfg: &Config, r: &FrequencyResponse) -> serde_json::Value {
    let (split, split_sigma) = r.mode_split_hz();
    let [m1, m2] = &r.modes;
    let configured_split = m2.configured_f0_hz - m1.configured_f0_hz;
    let mut counts = Health::default();
    for p in &r.measured.points {
        counts.add(&p.health[0]);
        counts.add(&p.health[1]);
    }
    json!({
        "gyroemu_version": env!("CARGO_PKG_VERSION"),
        "response": "velocity per unit force per unit mass, s: the averaged stage-1 phasor divided by the drive phasor, device.transduction_a_s_per_m, the TIA response H_TIA(f), the low-pass DC gain L(0) and the DAC hold sinc(f Ts) e^(-j pi f Ts)",
        "model": "g j w / (w0^2 - w^2 + j w w0 / Q) per mode, fitted to the driven response",
        "modes": [mode_json(m1), mode_json(m2)],
        "mode_split_hz": split,
        "mode_split_sigma_hz": split_sigma,
        "configured_mode_split_hz": configured_split,
        "mode_split_minus_configured_hz": split - configured_split,
        "coupled_mode_split_hz": m2.coupled_f0_hz - m1.coupled_f0_hz,
        "matrix_fit": matrix_json(cfg, r),
        "frequencies": r.measured.points.len(),
        "settle_s": r.measured.settle_s,
        "average_s": r.measured.average_s,
        "point_samples": r.measured.point_samples,
        "sweep": cfg.sweep_resolved(),
        "converter_counts": health_json(&counts),
        "problems": r.measured.problems,
        "warnings": with_config_warnings(cfg.validate_sweep(), &r.measured.warnings),
        "config": cfg,
    })
}

/// The two panels of `bode.png`: magnitude (log axis) and phase, both modes measured, their
/// fits as lines, and the cross-coupling where there is any.
fn bode_panels(r: &FrequencyResponse) -> Vec<Figure> {
    let pts = &r.measured.points;
    let fs: Vec<f64> = pts.iter().map(|p| p.freq_hz).collect();
    let (lo, hi) = (fs[0], fs[fs.len() - 1]);
    let curve: Vec<f64> = (0..CURVE_POINTS)
        .map(|i| lo + (hi - lo) * i as f64 / (CURVE_POINTS - 1) as f64)
        .collect();
    let x_label = "Frequency (Hz)";
    let mut mag = Figure::new("", x_label, "|velocity / force| (s)").log_y();
    let mut phase = Figure::new("", x_label, "Phase (deg)");
    for m in 0..2 {
        let data: Vec<Complex64> = pts.iter().map(|p| p.response[m][m]).collect();
        let name = format!("mode {}, measured", m + 1);
        mag = mag.with(Series::new(
            name.clone(),
            SeriesStyle::Points,
            fs.clone(),
            data.iter().map(|v| v.norm()).collect(),
        ));
        phase = phase.with(Series::new(
            name,
            SeriesStyle::Points,
            fs.clone(),
            data.iter().map(|&v| deg(v)).collect(),
        ));
    }
    for (m, check) in r.modes.iter().enumerate() {
        let Some(fit) = check.fit else { continue };
        let name = format!("mode {} fit: f0 {:.6} Hz, Q {:.1}", m + 1, fit.f0_hz, fit.q);
        let model: Vec<Complex64> = curve.iter().map(|&f| fit.response(f)).collect();
        mag = mag.with(Series::new(
            name.clone(),
            SeriesStyle::Line,
            curve.clone(),
            model.iter().map(|v| v.norm()).collect(),
        ));
        phase = phase.with(Series::new(
            name,
            SeriesStyle::Line,
            curve.clone(),
            model.iter().map(|&v| deg(v)).collect(),
        ));
    }
    for (m, k) in [(0, 1), (1, 0)] {
        let data: Vec<Complex64> = pts.iter().map(|p| p.response[m][k]).collect();
        if data.iter().all(|v| v.norm().is_nan() || v.norm() == 0.0) {
            continue;
        }
        let name = format!("cross: mode {} read, mode {} driven", k + 1, m + 1);
        mag = mag.with(Series::new(
            name.clone(),
            SeriesStyle::OpenPoints,
            fs.clone(),
            data.iter().map(|v| v.norm()).collect(),
        ));
        phase = phase.with(Series::new(
            name,
            SeriesStyle::OpenPoints,
            fs.clone(),
            data.iter().map(|&v| deg(v)).collect(),
        ));
    }
    vec![mag, phase]
}

/// The title of `bode.png`.
fn bode_title(r: &FrequencyResponse) -> String {
    let (split, sigma) = r.mode_split_hz();
    format!(
        "Stepped-sine frequency response: mode split {split:.6} Hz (+- {sigma:.1e}), configured {:.6} Hz",
        r.modes[1].configured_f0_hz - r.modes[0].configured_f0_hz
    )
}

/// Writes `sweep.csv`, `sweep.json` and `bode.png` into `out` (created if needed); returns
/// their paths.
pub fn write_freq_sweep(
    out: &Path,
    cfg: &Config,
    r: &FrequencyResponse,
) -> Result<Vec<PathBuf>, ReportError> {
    create_dir(out)?;
    let paths: Vec<PathBuf> = FREQ_SWEEP_FILES.iter().map(|f| out.join(f)).collect();
    write_csv(&paths[0], &freq_sweep_table(r))?;
    write_json(&paths[1], &freq_sweep_summary(cfg, r))?;
    render_panels_png(&bode_title(r), &bode_panels(r), 1, 1400, 1300, &paths[2])?;
    Ok(paths)
}
