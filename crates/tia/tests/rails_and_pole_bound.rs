//! The rail count the board's health report reads, and the smallest realisable pole the
//! config's validation refuses below: each checked against its definition, not against the
//! code's own output.

use gyroemu_core::Stage;
use gyroemu_tia::{min_pole_hz, pole_coefficient, Tia, TiaParams};

fn params(rail_v: Option<f64>) -> TiaParams {
    TiaParams {
        gain_ohm: 1e6,
        pole_hz: Some(3.0e4),
        inverting: true,
        rail_v,
        fs_hz: 240e3,
    }
}

#[test]
fn rail_flags_count_exactly_the_samples_on_a_rail() {
    let rail = 0.5;
    let mut t = Tia::<f64>::new(&params(Some(rail))).unwrap();
    assert!(t.has_rails());
    // Inverting, 1 MOhm: +-10 uA drives the output far past -+0.5 V; 10 nA stays at 10 mV.
    let mut seen = (0, 0, 0);
    for (n, x) in [1e-5, 1e-5, -1e-5, -1e-5, 1e-8, 0.0, 1e-8, -1e-5]
        .into_iter()
        .cycle()
        .take(4000)
        .enumerate()
    {
        let y = t.tick(x);
        let flag = t.rail_flags(y);
        // The definition: 1 where the clamped output is exactly a rail, else 0.
        let want = if y == rail || y == -rail { 1.0 } else { 0.0 };
        assert_eq!(flag, want, "sample {n}: y = {y}");
        match (y == rail, y == -rail) {
            (true, _) => seen.0 += 1,
            (_, true) => seen.1 += 1,
            _ => seen.2 += 1,
        }
    }
    // Every kind of sample occurred: the upper rail, the lower rail and the linear range.
    assert!(seen.0 > 0 && seen.1 > 0 && seen.2 > 0, "{seen:?}");
}

#[test]
fn without_rails_nothing_is_counted_and_nothing_is_clamped() {
    let mut t = Tia::<f64>::new(&params(None)).unwrap();
    assert!(!t.has_rails());
    let mut peak: f64 = 0.0;
    for _ in 0..2000 {
        let y = t.tick(1e-3);
        peak = peak.max(y.abs());
        assert_eq!(t.rail_flags(y), 0.0);
    }
    // 1 mA through 1 MOhm settles at 1 kV: no rail held it.
    assert!((peak - 1e3).abs() < 1e-6 * 1e3, "peak {peak}");
    // A railed TIA flags a value on its rail; an unrailed one never does, whatever the value.
    let railed = Tia::<f64>::new(&params(Some(2.0))).unwrap();
    assert_eq!(railed.rail_flags(2.0), 1.0);
    assert_eq!(railed.rail_flags(-2.0), 1.0);
    assert_eq!(railed.rail_flags(1.999), 0.0);
    assert_eq!(t.rail_flags(f64::INFINITY), 0.0);
}

/// The next double below a positive `x`.
fn below(x: f64) -> f64 {
    f64::from_bits(x.to_bits() - 1)
}

#[test]
fn min_pole_is_the_first_pole_whose_coefficient_is_below_one() {
    for fs in [1.0, 48e3, 240e3, 1e6, 48e6, 3.3e9] {
        let p = min_pole_hz(fs);
        // The definition: realised at p, rounded to exactly 1 one double lower.
        assert!(pole_coefficient(p, fs) < 1.0, "fs {fs}: a({p}) = 1");
        assert_eq!(
            pole_coefficient(below(p), fs),
            1.0,
            "fs {fs}: not the first"
        );
        // It sits where 2 pi pole / fs crosses half the spacing of doubles below 1.
        let estimate = fs * 2f64.powi(-54) / core::f64::consts::TAU;
        assert!(
            (0.5..=2.0).contains(&(p / estimate)),
            "fs {fs}: {p} against {estimate}"
        );
        // And Tia::new draws its line there.
        let mut q = params(None);
        q.fs_hz = fs;
        q.pole_hz = Some(p);
        assert!(Tia::<f64>::new(&q).is_ok(), "fs {fs}");
        q.pole_hz = Some(below(p));
        assert!(Tia::<f64>::new(&q).is_err(), "fs {fs}");
    }
}

#[test]
fn min_pole_of_an_invalid_rate_is_the_estimate() {
    // Callers validate the rate first; the helper still answers without looping or panicking.
    assert!(min_pole_hz(f64::NAN).is_nan());
    assert_eq!(min_pole_hz(0.0), 0.0);
    assert_eq!(min_pole_hz(f64::INFINITY), f64::INFINITY);
    let neg = min_pole_hz(-240e3);
    assert_eq!(neg, -240e3 * 2f64.powi(-54) / core::f64::consts::TAU);
}
