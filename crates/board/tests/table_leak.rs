//! The rate-table window's leak `K(d)` against its definition, term by term.

mod common;

use gyroemu_board::{ChainResponse, Point, Shape};
use gyroemu_core::Complex64;
use gyroemu_lpf::Window;

#[test]
fn table_leak_matches_its_definition_term_by_term() {
    // K(d) = sum_j w_j e^{j d theta_j} / sum_j w_j for every d, each term's phasor on its own
    // (libm's trigonometry of the table phase at each averaged output), over windows of both
    // kinds and every harmonic count a read-out uses.
    let p = common::m2tfg(Shape::RateTable { freq_hz: 7.3 });
    let chain = ChainResponse::new(&p).unwrap();
    let (ft, fs, m, settle) = (chain.table_hz(), p.fs_hz(), p.decimation as u64, 123u64);
    for window in [
        Window::Boxcar {
            n: 2000,
            frac: 0.25,
        },
        Window::Boxcar { n: 777, frac: 0.0 },
        Window::Hann { n: 1500 },
    ] {
        let point = Point {
            rate_rad_s: 0.1,
            window,
        };
        for harmonics in [0usize, 1, 3, 6] {
            let k = chain.table_leak(&point, settle, harmonics);
            assert_eq!(k.len(), 4 * harmonics + 1);
            for (i, got) in k.iter().enumerate() {
                let d = i as f64 - (2 * harmonics) as f64;
                let (mut num, mut den) = (Complex64::new(0.0, 0.0), 0.0);
                for j in 0..window.samples() {
                    let w = window.weight(j);
                    let n = (settle + j) * m + m - 1;
                    let turns = (n as f64 * ft / fs).fract();
                    num += Complex64::from_polar(w, d * core::f64::consts::TAU * turns);
                    den += w;
                }
                let want = num / den;
                // Each term's phase carries a few ulp of rounding; |K| <= 1.
                assert!(
                    (got - want).norm() < 1e-12,
                    "{window:?}, d {d}: {got} vs {want}"
                );
            }
        }
    }
}
