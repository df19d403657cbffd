//! The series of `gyroemu run`'s plot.png, checked against closed forms and independently
//! computed values (not pixels): a theory line per mode wherever the modes' theories differ,
//! lines over the whole span of the rates, labels that say what is drawn and what was refused;
//! and `reproduce`'s Fig. 6 (the Coriolis and the rescaled rotating points, each with its fit).

use gyroemu_config::presets::preset;
use gyroemu_config::Config;
use gyroemu_experiment::fit::fit_line;
use gyroemu_experiment::{theory_deg, SweepResult};
use gyroemu_plot::{Figure, Series, SeriesStyle};
use gyroemu_report::reproduce::fig6;
use gyroemu_report::run_title;
use gyroemu_report::sweep_report::sweep_figure;
use std::f64::consts::PI;

/// A sweep result whose measured phases are `phase(rate)` (no emulation: the figure is what is
/// under test), with the fits `run` would compute from them.
fn result(cfg: &Config, phase: impl Fn(f64) -> [f64; 2]) -> SweepResult {
    let rates = cfg.experiment.rates_dps.clone();
    let points: Vec<_> = rates
        .iter()
        .map(|&x| gyroemu_experiment::PointResult {
            rate_dps: x,
            phase_deg: phase(x),
            theory_deg: theory_deg(cfg, x),
            paper_i_deg: None,
            raw_psi_deg: None,
            alpha_deg: None,
            single_mixer_dc_v: None,
            table_lag_deg: None,
            table_lag_theory_deg: None,
            averaged_s: 1.0,
        })
        .collect();
    let fit = [0, 1].map(|k| {
        let ys: Vec<f64> = points.iter().map(|p| p.phase_deg[k]).collect();
        fit_line(&rates, &ys)
    });
    SweepResult {
        shape: cfg.shape(),
        points,
        compensation: Vec::new(),
        fit,
        theory_slope_deg_per_dps: [f64::NAN; 2],
        settle_s: 0.0,
        fs_hz: 0.0,
        fs_out_hz: 0.0,
        samples: 0,
        point_samples: 0,
        health: Default::default(),
        problems: Vec::new(),
        warnings: Vec::new(),
    }
}

fn figure(cfg: &Config) -> Figure {
    let r = result(cfg, |x| theory_deg(cfg, x));
    sweep_figure(cfg, &r, &run_title(cfg))
}

fn lines(fig: &Figure) -> Vec<&Series> {
    fig.series
        .iter()
        .filter(|s| s.style == SeriesStyle::Line)
        .collect()
}

/// The line's y at abscissa `x` (one of its samples).
fn y_at(s: &Series, x: f64) -> f64 {
    let i = s.xs.iter().position(|&v| v == x).expect("a sample at x");
    s.ys[i]
}

fn rotating(rates: &[f64]) -> Config {
    let mut cfg = preset("m2tfg-rotating").unwrap();
    cfg.device.q = 2000.0;
    cfg.experiment.rates_dps = rates.to_vec();
    cfg
}

fn coriolis(rates: &[f64]) -> Config {
    let mut cfg = preset("m2tfg-coriolis").unwrap();
    cfg.device.q = 2000.0;
    cfg.experiment.rates_dps = rates.to_vec();
    cfg
}

/// The ideal rotating psi (THEORY.md section 4): the mean of the two sidebands' lags.
fn ideal_psi_deg(f0: f64, q: f64, omega_dps: f64) -> f64 {
    let (w0, om) = (2.0 * PI * f0, omega_dps * PI / 180.0);
    let d = |s: f64| (q * om * (2.0 * w0 + s * om) / (w0 * (w0 + s * om))).atan();
    0.5 * (d(1.0) + d(-1.0)) * 180.0 / PI
}

#[test]
fn an_imperfect_mode_2_with_equal_drives_gets_its_own_theory_line() {
    // The reviewer's case: F1 = F2, mode 2 1 Hz up, a 3-degree phase-shifter error. Mode 2's
    // psi at 25 deg/s is 3.9905 deg by an independent sideband-phasor computation.
    let mut cfg = rotating(&[25.0, 100.0, 175.0]);
    cfg.device.mode2_f0_offset_hz = 1.0;
    cfg.board.phase_shifter_error_deg = 3.0;
    let fig = figure(&cfg);
    let l = lines(&fig);
    assert_eq!(l.len(), 2, "{:?}", fig.series);
    assert!(l[0].name.ends_with("mode 1") && l[1].name.ends_with("mode 2"));
    assert!((y_at(l[0], 25.0) - ideal_psi_deg(15000.0, 2000.0, 25.0)).abs() < 1e-6);
    assert!(
        (y_at(l[1], 25.0) - 3.9905).abs() < 1e-4,
        "{}",
        y_at(l[1], 25.0)
    );
    // psi has no value at Omega = 0: mode 2's line must not drop to the ideal 0 there.
    for (x, y) in l[1].xs.iter().zip(&l[1].ys) {
        if x.abs() < 1.0 {
            assert!(y.is_nan() || *y > 2.5, "mode 2 at {x}: {y}");
        }
    }
}

#[test]
fn a_q_mismatch_alone_gets_a_mode_2_line_and_a_title_with_both_qs() {
    let mut cfg = coriolis(&[25.0, 1000.0, 3000.0]);
    cfg.device.q_mode2 = Some(1000.0);
    let fig = figure(&cfg);
    let l = lines(&fig);
    assert_eq!(l.len(), 2, "{:?}", fig.series);
    // The lines are far apart (mode 2's Q is half), each through its mode's theory column.
    let (t1, t2) = (y_at(l[0], 25.0), y_at(l[1], 25.0));
    assert!((t2 - t1).abs() > 0.1 * t1.abs(), "{t1} {t2}");
    assert_eq!([t1, t2], theory_deg(&cfg, 25.0));
    assert!(fig.title.contains("Q1 = 2000") && fig.title.contains("Q2 = 1000"));
    let mut offset = coriolis(&[25.0]);
    offset.device.mode2_f0_offset_hz = 1.0;
    assert!(run_title(&offset).contains("f02 = 15001 Hz"));
}

#[test]
fn an_ideal_device_has_one_theory_line_labelled_for_both_modes() {
    let cfg = coriolis(&[25.0, 100.0, 175.0]);
    let fig = figure(&cfg);
    let l = lines(&fig);
    assert_eq!(l.len(), 1);
    assert_eq!(l[0].name, "exact theory, modes 1 and 2");
    assert_eq!(fig.title, "Coriolis run, f0 = 15000 Hz, Q = 2000");
}

#[test]
fn unequal_drives_draw_each_modes_closed_form_on_both_signs() {
    // Ideal device, F2/F1 = 0.5: theta_k = atan(2 F_other Q lambda Omega / (F_k w0)).
    let mut cfg = coriolis(&[-175.0, 25.0, 175.0]);
    cfg.drive.f2 = Some(0.5);
    let fig = figure(&cfg);
    let l = lines(&fig);
    assert_eq!(l.len(), 2);
    let w0 = 2.0 * PI * 15000.0;
    let theta =
        |ratio: f64, x: f64| (2.0 * ratio * 2000.0 * x * PI / 180.0 / w0).atan() * 180.0 / PI;
    for x in [-175.0, -87.5, 175.0] {
        let i = l[0].xs.iter().position(|&v| (v - x).abs() < 1e-9).unwrap();
        assert!((l[0].ys[i] - theta(0.5, x)).abs() < 1e-9, "mode 1 at {x}");
        assert!((l[1].ys[i] - theta(2.0, x)).abs() < 1e-9, "mode 2 at {x}");
    }
}

#[test]
fn all_negative_rates_get_theory_and_fit_over_their_span() {
    let cfg = rotating(&[-70000.0, -30000.0, -5000.0]);
    let fig = figure(&cfg);
    let drawn: Vec<&Series> = fig
        .series
        .iter()
        .filter(|s| matches!(s.style, SeriesStyle::Line | SeriesStyle::DashedLine))
        .collect();
    assert_eq!(drawn.len(), 2, "theory and fit: {:?}", fig.series);
    for s in drawn {
        let finite: Vec<f64> =
            s.xs.iter()
                .zip(&s.ys)
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|(x, _)| *x)
                .collect();
        let lo = finite.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = finite.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        assert!(lo <= -70000.0 && hi >= -5000.0, "{}: [{lo}, {hi}]", s.name);
    }
    // The theory goes through the ideal psi at each rate.
    let l = lines(&fig);
    for x in [-70000.0, -30000.0, -5000.0] {
        assert!((y_at(l[0], x) - ideal_psi_deg(15000.0, 2000.0, x)).abs() < 1e-9);
    }
}

#[test]
fn mixed_sign_rates_get_the_theory_on_the_negative_side() {
    let cfg = coriolis(&[-175.0, 25.0, 175.0]);
    let fig = figure(&cfg);
    let l = lines(&fig);
    let theta = (2.0 * 2000.0 * (-175.0 * PI / 180.0) / (2.0 * PI * 15000.0)).atan() * 180.0 / PI;
    assert!((y_at(l[0], -175.0) - theta).abs() < 1e-9);
}

#[test]
fn a_rate_table_line_is_labelled_as_the_exact_harmonic_balance() {
    let mut cfg = preset("m2tfg-ratetable").unwrap();
    cfg.experiment.rates_dps = vec![25.0, 175.0];
    let fig = figure(&cfg);
    let l = lines(&fig);
    assert_eq!(l.len(), 1);
    assert!(l[0].name.contains("harmonic balance"), "{}", l[0].name);
    assert!(!l[0].name.contains("small-signal") && !l[0].name.contains("first-order"));
}

#[test]
fn refused_points_are_named_in_the_legend_and_no_nan_is_printed() {
    let cfg = coriolis(&[25.0, 100.0, 175.0]);
    // A dead channel: every phase of both modes refused.
    let dead = result(&cfg, |_| [f64::NAN; 2]);
    let fig = sweep_figure(&cfg, &dead, "t");
    let names: Vec<&str> = fig.series.iter().map(|s| s.name.as_str()).collect();
    assert!(
        names.contains(&"mode 1: no finite phase (refused)"),
        "{names:?}"
    );
    assert!(
        names.contains(&"mode 2: no finite phase (refused)"),
        "{names:?}"
    );
    assert!(names.iter().all(|n| !n.contains("NaN")), "{names:?}");
    // One point of mode 1 refused: the legend counts it.
    let one = result(&cfg, |x| {
        let t = theory_deg(&cfg, x);
        [if x == 100.0 { f64::NAN } else { t[0] }, t[1]]
    });
    let fig = sweep_figure(&cfg, &one, "t");
    assert_eq!(
        fig.series[0].name,
        "mode 1 emulated (1 of 3 points refused: no finite phase)"
    );
    assert_eq!(fig.series[1].name, "mode 2 emulated");
    assert!(fig.series.iter().all(|s| !s.name.contains("NaN")));
}

/// The BAW pair of Fig. 6 (Coriolis rates 300..2100 deg/s, rotating rates lambda times those),
/// each sweep's phases its exact theory, and Fig. 6 drawn from them.
fn baw_fig6(rot_phase: impl Fn(&Config, f64) -> [f64; 2]) -> (SweepResult, SweepResult, Figure) {
    let (cc, rc) = (
        preset("baw-coriolis").unwrap(),
        preset("baw-rotating").unwrap(),
    );
    let cor = result(&cc, |x| theory_deg(&cc, x));
    let rot = result(&rc, |x| rot_phase(&rc, x));
    let fig = fig6(&cc, &cor, &rot);
    (cor, rot, fig)
}

fn dashed(fig: &Figure) -> Vec<&Series> {
    fig.series
        .iter()
        .filter(|s| s.style == SeriesStyle::DashedLine)
        .collect()
}

#[test]
fn fig6_draws_the_best_linear_fit_of_each_series_in_its_own_axes() {
    let (cor, rot, fig) = baw_fig6(theory_deg);
    let d = dashed(&fig);
    assert_eq!(d.len(), 2, "{:?}", fig.series);
    // The fits go after the points and the theory, in the sweep figures' wording.
    assert_eq!(fig.series.len(), 5);
    let lambda = 0.6;
    let cor_x: Vec<f64> = cor.points.iter().map(|p| p.rate_dps).collect();
    let rot_x: Vec<f64> = rot.points.iter().map(|p| p.rate_dps / lambda).collect();
    let phases =
        |r: &SweepResult| -> Vec<f64> { r.points.iter().map(|p| p.phase_deg[0]).collect() };
    // Each line is the least-squares line of its series' points as plotted, computed here
    // afresh (the rotating one against Omega / lambda, not against Omega).
    for (s, who, xs, ys) in [
        (d[0], "Coriolis mode 1", &cor_x, phases(&cor)),
        (d[1], "rotating mode 1", &rot_x, phases(&rot)),
    ] {
        let f = fit_line(xs, &ys);
        assert_eq!(
            s.name,
            format!(
                "best linear fit, {who}: {:.6} deg per deg/s (R^2 = {:.6})",
                f.slope, f.r2
            )
        );
        // From the origin to the farthest rate, as the sweep figures' fits.
        assert_eq!(s.xs.len(), 2);
        assert!(
            s.xs[0] == 0.0 && (s.xs[1] - 2100.0).abs() < 1e-9,
            "{:?}",
            s.xs
        );
        for (x, y) in s.xs.iter().zip(&s.ys) {
            let want = f.intercept + f.slope * x;
            assert!(
                (y - want).abs() < 1e-12 * want.abs().max(1.0),
                "{who} at {x}: {y} vs {want}"
            );
        }
    }
    // The two slopes coincide (Fig. 6's point): the rotating slope against Omega is 1/lambda
    // times the Coriolis one, and 0.000636 deg per deg/s against Omega / lambda.
    let slope = |s: &Series| (s.ys[1] - s.ys[0]) / (s.xs[1] - s.xs[0]);
    assert!(
        (slope(d[1]) / slope(d[0]) - 1.0).abs() < 1e-4,
        "{} {}",
        slope(d[0]),
        slope(d[1])
    );
    assert!((slope(d[0]) - 0.000636).abs() < 5e-7, "{}", slope(d[0]));
}

#[test]
fn fig6_leaves_out_the_fit_of_refused_points_and_prints_no_nan() {
    // One rotating point refused: its fit is NaN, which the points' series explain; the
    // Coriolis fit is still drawn.
    let (_, _, fig) = baw_fig6(|c, x| {
        let t = theory_deg(c, x);
        [if x == 540.0 { f64::NAN } else { t[0] }, t[1]]
    });
    let d = dashed(&fig);
    assert_eq!(d.len(), 1, "{:?}", fig.series);
    assert!(d[0].name.starts_with("best linear fit, Coriolis mode 1: "));
    assert!(fig.series.iter().all(|s| !s.name.contains("NaN")));
}

#[test]
fn a_fit_across_psis_branch_cut_says_its_readings_were_unwrapped() {
    // Readings folded into (-90, 90] (psi of a strongly coupled device crossing -90 deg):
    // the line is fitted to them unwrapped by half turns, so it misses the folded points by a
    // half turn, and its legend says why; a sweep that never wraps keeps the plain legend.
    let cfg = rotating(&[-500.0, 25.0, 175.0, 1000.0]);
    let folded = |x: f64| {
        let y: f64 = 0.0244 * x - 89.0;
        let y = y - 180.0 * (y / 180.0).round();
        [y, y]
    };
    let r = result(&cfg, folded);
    assert!(r.points[0].phase_deg[0] > 45.0, "{:?}", r.points[0]);
    let fig = sweep_figure(&cfg, &r, &run_title(&cfg));
    let label = |fig: &Figure| {
        fig.series
            .iter()
            .find(|s| s.name.starts_with("best linear fit"))
            .map(|s| s.name.clone())
            .unwrap()
    };
    assert!(
        label(&fig).contains("readings unwrapped by 180 deg along rate"),
        "{}",
        label(&fig)
    );
    let plain = sweep_figure(&cfg, &result(&cfg, |x| theory_deg(&cfg, x)), "t");
    assert!(!label(&plain).contains("unwrapped"), "{}", label(&plain));
}
