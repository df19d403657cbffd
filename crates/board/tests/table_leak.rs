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

/// `table_leak` as first written: one window sample at a time, each term's phasor the
/// previous one times the sample's conjugate table phasor, added to a compensated sum.
fn table_leak_one_at_a_time(
    chain: &ChainResponse,
    point: &Point,
    n_settle: u64,
    harmonics: usize,
    fs: f64,
    m: u64,
) -> Vec<Complex64> {
    use gyroemu_lpf::KahanSum;
    let top = 2 * harmonics;
    let mut sum = vec![[KahanSum::<f64>::new(), KahanSum::new()]; top + 1];
    let mut wsum = KahanSum::<f64>::new();
    for j in 0..point.window.samples() {
        let w = point.window.weight(j);
        if w == 0.0 {
            continue;
        }
        let n = (n_settle + j) * m + m - 1;
        let e = gyroemu_mixer::table_reference(n, chain.table_hz(), fs).conj();
        let mut p = Complex64::new(w, 0.0);
        for s in sum.iter_mut() {
            s[0].add(p.re);
            s[1].add(p.im);
            p *= e;
        }
        wsum.add(w);
    }
    let k = |d: usize| Complex64::new(sum[d][0].value(), sum[d][1].value()) / wsum.value();
    (0..=2 * top)
        .map(|i| match i.checked_sub(top) {
            Some(d) => k(d),
            None => k(top - i).conj(),
        })
        .collect()
}

#[test]
fn table_leak_has_the_bits_of_one_sample_at_a_time() {
    // The blocked sums against the plain loop, bit for bit: window lengths that leave a
    // partial block (and Hann's zero end weights, which are skipped), harmonic counts up to
    // a rate table's largest, two table frequencies.
    let bits = |k: &[Complex64]| -> Vec<(u64, u64)> {
        k.iter().map(|z| (z.re.to_bits(), z.im.to_bits())).collect()
    };
    for freq_hz in [7.3, 0.05] {
        let p = common::m2tfg(Shape::RateTable { freq_hz });
        let chain = ChainResponse::new(&p).unwrap();
        let (fs, m) = (p.fs_hz(), p.decimation as u64);
        for window in [
            Window::Boxcar { n: 1, frac: 0.0 },
            Window::Boxcar { n: 7, frac: 0.5 },
            Window::Boxcar {
                n: 2001,
                frac: 0.25,
            },
            Window::Hann { n: 9 },
            Window::Hann { n: 1503 },
        ] {
            let point = Point {
                rate_rad_s: 0.1,
                window,
            };
            for (settle, harmonics) in [(0u64, 0usize), (123, 1), (4567, 6), (89, 40)] {
                let got = chain.table_leak(&point, settle, harmonics);
                let want = table_leak_one_at_a_time(&chain, &point, settle, harmonics, fs, m);
                assert_eq!(
                    bits(&got),
                    bits(&want),
                    "{freq_hz} Hz, {window:?}, settle {settle}, {harmonics} harmonics"
                );
            }
        }
    }
}
