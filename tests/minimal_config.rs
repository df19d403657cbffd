//! Issue 12 point 1: a config holding only the physics runs. Required are [device] f0_hz, q,
//! angular_gain; [drive] f1; [experiment] kind, rates_dps, average_s; the rest is derived
//! (fs_hz = 16 f0, f2 = f1, the carrier at f0, the low-pass cutoff from the rates, the
//! decimation) and the results are as exact as the presets'.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use gyroemu::config::parse_config;

fn minimal(kind: &str, f0: f64, q: f64, rates: &[f64], average_s: f64, board: &str) -> String {
    format!(
        "[device]\nf0_hz = {f0}\nq = {q}\nangular_gain = 1.0\n[drive]\nf1 = 1.0\n{board}\n\
         [experiment]\nkind = \"{kind}\"\nrates_dps = {rates:?}\naverage_s = {average_s}\n"
    )
}

#[test]
fn the_physics_alone_runs_every_kind_exactly() {
    for board in ["", "[board]\nfs_hz = 240000.0"] {
        for (kind, avg) in [("coriolis", 1.0), ("rotating", 8.0)] {
            let text = minimal(kind, 15e3, 2000.0, &[25.0, 100.0, 175.0], avg, board);
            let cfg = parse_config(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert!(cfg.validate().unwrap().is_empty(), "{text}");
            assert_eq!(cfg.fs_hz(), 240e3);
            assert_eq!(cfg.carrier_hz(), 15e3);
            let r = run(&cfg);
            assert!(r.problems.is_empty() && r.warnings.is_empty(), "{r:?}");
            for k in 0..2 {
                assert!(r.max_abs_error_mdeg(k) < 1e-3, "{kind}: {r:?}");
            }
        }
    }
}

/// Where the decimated output rate puts the 2 f_c mixer product, as a fraction of the output
/// rate from DC (0 .. 1/2).
fn alias_distance(fs: f64, fc: f64, m: usize) -> f64 {
    let a = (2.0 * fc * m as f64 / fs).rem_euclid(1.0);
    a.min(1.0 - a)
}

#[test]
fn the_derived_decimation_keeps_the_mixer_product_off_dc() {
    for f0 in [1e3, 15e3, 3e6] {
        for rate in [10.0, 360.0, 7200.0, 30_000.0] {
            let text = minimal("rotating", f0, 100.0, &[rate], 1.0, "");
            let cfg = parse_config(&text).unwrap();
            let m = cfg.decimation();
            let m_max = (cfg.fs_hz() / (20.0 * cfg.lpf_cutoff_hz())).floor() as usize;
            assert!(m <= m_max && 2 * m >= m_max, "{f0} {rate}: {m} of {m_max}");
            // At 16 samples per period the best spot, the output Nyquist, is always in reach.
            let d = alias_distance(cfg.fs_hz(), f0, m);
            assert!(d > 0.49 || m_max < 8, "{f0} {rate}: M = {m}: {d}");
        }
    }
}

#[test]
fn the_derived_decimation_is_the_farthest_alias_of_its_search_window() {
    // A plain scan of every M the rule allows, against `decimation()`. Up to 2^17 the search
    // covers M_max/2 ..= M_max; beyond, its top DECIMATION_CANDIDATES, and a 1e-4 of the
    // output rate at most is given away against the whole range (checked to M_max = 1e7).
    use gyroemu::config::DECIMATION_CANDIDATES;
    for fs in [240e3, 250_003.141_592_653_6, 241_234.5] {
        for m_max in [
            1usize, 7, 100, 4097, 131_071, 131_072, 1_000_003, 10_000_000,
        ] {
            let cutoff = fs / (20.0 * m_max as f64 + 0.5);
            let board = format!("[board]\nfs_hz = {fs:?}\nlpf_cutoff_hz = {cutoff:?}");
            let cfg =
                parse_config(&minimal("rotating", 15e3, 2000.0, &[100.0], 1.0, &board)).unwrap();
            assert_eq!((fs / (20.0 * cutoff)).floor() as usize, m_max);
            let m = cfg.decimation();
            let d = |m: usize| alias_distance(fs, 15e3, m);
            let all = (m_max.div_ceil(2)..=m_max).map(d).fold(0.0, f64::max);
            let (lo, slack) = if m_max < 131_072 {
                (m_max.div_ceil(2), 1e-12)
            } else {
                (m_max + 1 - DECIMATION_CANDIDATES, 1e-4)
            };
            assert!(lo <= m && m <= m_max, "{fs} {m_max}: M = {m}");
            assert!(
                d(m) >= all - slack,
                "{fs} {m_max}: M = {m}: {} < {all}",
                d(m)
            );
        }
    }
}

#[test]
fn a_second_order_low_pass_with_the_derived_decimation_reads_psi_exactly() {
    // 1 kHz, Q = 100, rotating at 1800 deg/s, order 2: the low-pass leaves 2e-5 of the 2 f0
    // product. With M = 16 the output rate divides 2 f0 and that residue sits on DC, biasing
    // psi by 2 mdeg; the derived M folds it to the output Nyquist, where the average all but
    // removes it (0.04 mdeg left).
    let text = minimal(
        "rotating",
        1e3,
        100.0,
        &[1800.0],
        2.0,
        "[board]\nlpf_order = 2",
    );
    let cfg = parse_config(&text).unwrap();
    assert_ne!(cfg.decimation() % 8, 0);
    let r = run(&cfg);
    let exact = r.max_abs_error_mdeg(0).max(r.max_abs_error_mdeg(1));
    // What stays is the weak filter's leak of the folded product over a finite window.
    assert!(
        exact < 0.1,
        "derived M = {}: {exact} mdeg",
        cfg.decimation()
    );
    let mut aliased = cfg.clone();
    aliased.board.decimation = Some(16);
    aliased.validate().unwrap();
    let r = run(&aliased);
    let biased = r.max_abs_error_mdeg(0).max(r.max_abs_error_mdeg(1));
    assert!(
        biased > 1.0 && biased > 20.0 * exact,
        "M = 16: {biased} mdeg"
    );
}
