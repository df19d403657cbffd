//! Every number of every preset set, one at a time, to an extreme (zero, negative, tiny,
//! huge, the largest integers, NaN and infinities): validation must refuse or accept it
//! without a panic, and a config it accepts must plan without an integer wrapping (the plan's
//! integer sample counts agree with the same sums done in f64), build, run a few samples of
//! each point and read them out. The cargo-fuzz targets
//! (`fuzz/`, nightly, not in CI) edit one line of a preset; this sweep is deterministic, runs
//! in CI, and also covers a `[dump]` section, which no preset carries.

use gyroemu::analysis::montecarlo::validate_lot;
use gyroemu::analysis::selfcal::{sweep_configs, validate_selfcal};
use gyroemu::analysis::stepped_sine::stepped_sine_work;
use gyroemu::board::{Board, Point, RunOptions};
use gyroemu::config::presets::PRESETS;
use gyroemu::config::{parse_config, Config};
use gyroemu::experiment::pll_params;
use gyroemu::experiment::readout::post_process;
use gyroemu::experiment::{lock_work, sweep_work, MAX_POINT_SAMPLES};
use gyroemu::lpf::Window;
use std::panic::{catch_unwind, AssertUnwindSafe};
use toml::Value;

const FLOATS: [f64; 12] = [
    0.0,
    -0.0,
    -1.0,
    5e-324,
    1e-300,
    1e300,
    -1e300,
    f64::MAX,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    4.5e15,
];
const INTS: [i64; 7] = [0, -1, 1, i64::MAX, i64::MIN, 1 << 32, (1 << 53) + 1];

/// A short dump; its rate and nodes are left to their defaults.
const DUMP: &str = "\n[dump]\nstart_s = 0.5\nduration_s = 0.002\n";

/// Every path to a number (or to an array of numbers) in `v`.
fn numeric_paths(v: &Value, at: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        Value::Integer(_) | Value::Float(_) => out.push(at.clone()),
        Value::Table(t) => {
            for (k, x) in t {
                at.push(k.clone());
                numeric_paths(x, at, out);
                at.pop();
            }
        }
        Value::Array(a) => {
            if a.iter()
                .any(|x| matches!(x, Value::Integer(_) | Value::Float(_)))
            {
                out.push(at.clone());
            }
            for (i, x) in a.iter().enumerate() {
                at.push(i.to_string());
                numeric_paths(x, at, out);
                at.pop();
            }
        }
        _ => {}
    }
}

fn slot<'a>(v: &'a mut Value, path: &[String]) -> &'a mut Value {
    path.iter().fold(v, |v, k| match v {
        Value::Table(t) => t.get_mut(k).expect("path from the same tree"),
        Value::Array(a) => &mut a[k.parse::<usize>().expect("index")],
        _ => unreachable!("paths end at numbers"),
    })
}

/// The replacements tried at a number: every extreme of its own type and one of the other.
fn extremes(v: &Value) -> Vec<Value> {
    let floats = FLOATS.iter().map(|&f| Value::Float(f));
    let ints = INTS.iter().map(|&i| Value::Integer(i));
    match v {
        Value::Integer(_) => ints.chain([Value::Float(1e300)]).collect(),
        Value::Float(_) => floats.chain([Value::Integer(i64::MAX)]).collect(),
        Value::Array(a) => {
            let mut out = vec![Value::Array(vec![])];
            out.extend(floats.map(|f| Value::Array(vec![f])));
            out.extend(a.first().map(|x| Value::Array(vec![x.clone(); 65])));
            out
        }
        _ => vec![],
    }
}

/// Validates `text` as each command that reads it would, then plans an accepted config.
fn check(name: &str, text: &str) {
    let Ok(cfg) = parse_config(text) else {
        return;
    };
    let plain = cfg.validate().is_ok();
    if name == "m2tfg-sweep" && cfg.validate_sweep().is_ok() {
        stepped_sine_plans(&cfg);
    }
    if cfg.selfcal.is_some() && validate_selfcal(&cfg).is_ok() && plain {
        // What `selfcal` runs is what it validated.
        let (rotating, table) = sweep_configs(&cfg);
        for c in [rotating, table] {
            assert!(c.validate().is_ok(), "{:?}", c.validate());
            plans_without_wrapping(&c);
        }
    }
    if cfg.pll.is_some() && plain {
        // The loop is designed from validated keys alone, before its lock runs.
        if let Err(e) = pll_params(&cfg, &cfg) {
            panic!("validated, but the PLL's design refused: {e}");
        }
        lock_plans_without_wrapping(&cfg);
    }
    if cfg.montecarlo.is_some() {
        let _ = validate_lot(&cfg, &[0, 1]);
    }
    if plain {
        plans_without_wrapping(&cfg);
        runs_briefly(&cfg);
    }
}

/// A few output samples of each point of an accepted config's board: built and run without a
/// panic, finite averages when the run completes (a non-finite value stops it with an error),
/// and the read-out (phases, theory, compensation, fits) run on them without a panic.
fn runs_briefly(cfg: &Config) {
    let m = cfg.decimation() as u64;
    if m > 1 << 14 {
        return;
    }
    let rates = cfg.emulated_rates_dps();
    let point = |rate_dps: f64| Point {
        rate_rad_s: rate_dps.to_radians(),
        window: Window::Boxcar { n: 2, frac: 0.0 },
    };
    let mut lanes = Vec::new();
    for (i, &r) in rates.iter().enumerate() {
        let p = point(r);
        let mut board = Board::<f64>::new(&cfg.board_params(), &[p.rate_rad_s], &[i as u64])
            .expect("validated");
        let Ok(out) = board.run(1, &[p], RunOptions::default(), &|_| {}) else {
            return;
        };
        let r = out.lanes[0];
        let mut averages = r.z.iter().chain(&r.c).chain(&r.s);
        assert!(
            averages.all(|v| v.re.is_finite() && v.im.is_finite()),
            "{r:?}"
        );
        lanes.push(r);
    }
    let points: Vec<Point> = rates.iter().map(|&r| point(r)).collect();
    if let Err(e) = post_process(cfg, &rates, &points, &lanes) {
        panic!("validated, built and run, but the read-out refused: {e}");
    }
}

/// A stepped-sine sweep's plan: ascending finite frequencies, and its sample counts agree
/// with the same products in f64.
fn stepped_sine_plans(cfg: &Config) {
    let f = cfg.sweep_frequencies_hz();
    assert!(
        !f.is_empty() && f.iter().all(|x| x.is_finite() && *x > 0.0),
        "{f:?}"
    );
    assert!(f.windows(2).all(|w| w[0] < w[1]), "{f:?}");
    let (settle, point) = cfg.sweep_point();
    let per_run = (settle as f64 + point.window.samples() as f64) * cfg.decimation() as f64;
    assert!(
        per_run <= 2f64.powi(53),
        "{per_run} input samples in one run"
    );
    let w = stepped_sine_work(cfg);
    let want = 2.0 * f.len() as f64 * per_run;
    assert!(
        (w.point_samples as f64 - want).abs() <= 1e-9 * want,
        "{w:?} against {want}"
    );
}

/// The lock run's input samples (whole decimation blocks covering pll.lock_s) agree with the
/// same product in f64, saturated at the largest count, and the cap weighs them: a lock of
/// 2^40 s had planned nothing, run for hours and grown without bound.
fn lock_plans_without_wrapping(cfg: &Config) {
    let want = (cfg.pll_lock_s().unwrap() * cfg.fs_out_hz()).ceil() * cfg.decimation() as f64;
    let got = lock_work(cfg).lock_samples;
    if want >= u64::MAX as f64 {
        assert_eq!(got, u64::MAX, "{want}");
    } else {
        assert!(
            (got as f64 - want).abs() <= 1e-9 * want,
            "{got} against {want}"
        );
    }
    let w = sweep_work(cfg).plus(lock_work(cfg));
    let above = w.point_samples as f64 + want > MAX_POINT_SAMPLES as f64;
    assert_eq!(w.check_cap(false).is_err(), above, "{w:?}");
}

/// The sweep's integer sample counts agree with the same sums in f64 (a wrapped sum would be
/// far off); validation bounds a point's run at 2^53 input samples.
fn plans_without_wrapping(cfg: &Config) {
    let w = sweep_work(cfg);
    let longest = cfg
        .emulated_rates_dps()
        .iter()
        .map(|&r| cfg.plan_point(r).window.samples() as f64)
        .fold(1.0, f64::max);
    let want = (cfg.n_settle_out() as f64 + longest) * cfg.decimation() as f64;
    assert!(
        want <= 2f64.powi(53),
        "{want} input samples in one point's run"
    );
    assert!(
        (w.longest_samples as f64 - want).abs() <= 1e-9 * want,
        "longest run {} samples, {want} in f64",
        w.longest_samples
    );
    assert!(w.point_samples as f64 >= want, "{w:?} against {want}");
    if let Some(d) = cfg.dump_resolved() {
        let (start, duration) = (d.start_s.unwrap(), d.duration_s.unwrap());
        assert!(start.is_finite() && duration.is_finite(), "{d:?}");
    }
}

#[test]
fn no_extreme_number_panics_validation_or_wraps_a_plan() {
    let mut failures = Vec::new();
    let mut tried = 0;
    for (name, _, text) in PRESETS {
        // The [pll] preset's lock_s is commented out: a variant sets it, so its extremes
        // are tried too.
        let lock = text.contains("\n[pll]").then(|| {
            let at = text.find("\n[pll]").unwrap() + 1;
            let line_end = at + text[at..].find('\n').unwrap() + 1;
            format!("{}lock_s = 5.0\n{}", &text[..line_end], &text[line_end..])
        });
        let variants = [(text.to_string(), ""), (text.to_string(), DUMP)]
            .into_iter()
            .chain(lock.map(|t| (t, "")));
        for (text, extra) in variants {
            let text = format!("{text}{extra}");
            let tree: Value = toml::from_str(&text).expect("presets parse");
            let mut paths = Vec::new();
            numeric_paths(&tree, &mut Vec::new(), &mut paths);
            for path in &paths {
                for x in extremes(slot(&mut tree.clone(), path)) {
                    let mut edited = tree.clone();
                    *slot(&mut edited, path) = x.clone();
                    let edited = toml::to_string(&edited).expect("serialises");
                    tried += 1;
                    if let Err(e) = catch_unwind(AssertUnwindSafe(|| check(name, &edited))) {
                        let msg = e
                            .downcast_ref::<String>()
                            .cloned()
                            .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                            .unwrap_or_default();
                        let x = match x {
                            Value::Float(f) => format!("{f:e}"),
                            x => x.to_string().chars().take(60).collect(),
                        };
                        failures.push(format!("{name}: {} = {x}: {msg}", path.join(".")));
                    }
                }
            }
        }
    }
    assert!(tried > 1000, "only {tried} edits");
    assert!(
        failures.is_empty(),
        "{} of {tried}:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
