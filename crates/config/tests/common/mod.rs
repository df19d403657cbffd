//! What the config crate's tests share: the board run of a config's points and the psi read
//! from its stage-2 averages (THEORY.md section 6), independently of the crate's read-out.
#![allow(dead_code)]

use gyroemu_board::{unleak_sidebands, ChainResponse, GroupBoard, LaneResult, RunOptions};
use gyroemu_config::Config;
use gyroemu_core::Complex64;

/// Every emulated point of `c` on the board, in the order of `emulated_rates_dps`.
pub fn run(c: &Config) -> (Vec<f64>, Vec<LaneResult>) {
    let rates = c.emulated_rates_dps();
    let points: Vec<_> = rates.iter().map(|&r| c.plan_point(r)).collect();
    let rad: Vec<f64> = points.iter().map(|p| p.rate_rad_s).collect();
    let streams: Vec<u64> = (0..rates.len() as u64).collect();
    let mut board = GroupBoard::new(&c.board_params(), &rad, &streams).unwrap();
    let out = board
        .run(c.n_settle_out(), &points, RunOptions::default(), &|_| {})
        .unwrap();
    (rates, out.lanes)
}

/// psi per point and mode from the board's stage-2 averages, the window's leak removed; the
/// chain's own terms are left in (they cancel between two runs of the same chain).
pub fn raw_psi(c: &Config) -> Vec<[f64; 2]> {
    let (rates, lanes) = run(c);
    let chain = ChainResponse::new(&c.board_params()).unwrap();
    let j = Complex64::new(0.0, 1.0);
    let m = [
        (Complex64::new(1.0, 0.0), Complex64::new(1.0, 0.0)),
        (-j, j),
    ];
    rates
        .iter()
        .zip(&lanes)
        .map(|(&r, l)| {
            let leak = chain
                .stage2_leak(&c.plan_point(r), c.n_settle_out())
                .unwrap();
            [0, 1].map(|k| {
                let (cc, s) = unleak_sidebands(l.c[k], l.s[k], leak);
                let (zp, zm) = ((cc - j * s) / 2.0, (cc + j * s) / 2.0);
                0.5 * ((zm / m[k].1).arg() - (zp / m[k].0).arg())
            })
        })
        .collect()
}
