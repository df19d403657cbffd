//! The normals of the noise generator against the standard normal distribution: moments,
//! tails against erfc, a chi-square test against the normal CDF, whiteness (lag
//! correlations and an averaged periodogram) and independence across streams and lanes. Each
//! bound is stated in standard errors of the statistic, wide enough (5 sigma or more) that a
//! correct generator fails with a chance of about 1e-6, narrow enough to see a wrong density
//! (a ziggurat with one layer off by 1 % moves the chi-square statistic by thousands).

use gyroemu_core::f64x4;
use gyroemu_core::noise::NoiseRng;
use rustfft::num_complex::Complex64;
use rustfft::FftPlanner;

/// Normals per stream drawn: 2^22, so 2^25 in all (4 lanes, 2 streams each).
const PER_STREAM: usize = 1 << 22;

/// Every stream's sequence, `[lane][stream]`.
fn draw(seeds: [u64; 4]) -> Vec<[Vec<f64>; 2]> {
    let mut rng = NoiseRng::new(seeds);
    let mut out: Vec<[Vec<f64>; 2]> = (0..4)
        .map(|_| {
            [
                Vec::with_capacity(PER_STREAM),
                Vec::with_capacity(PER_STREAM),
            ]
        })
        .collect();
    let mut buf = vec![f64x4::ZERO; 2 * 8192];
    for _ in 0..PER_STREAM / 8192 {
        rng.fill_pairs(&mut buf);
        for pair in buf.chunks_exact(2) {
            for (h, v) in pair.iter().enumerate() {
                for (l, x) in v.to_array().into_iter().enumerate() {
                    out[l][h].push(x);
                }
            }
        }
    }
    out
}

/// The standard normal density.
fn phi(x: f64) -> f64 {
    (-0.5 * x * x).exp() / (2.0 * core::f64::consts::PI).sqrt()
}

/// P(a < X < b) for a standard normal, by composite Simpson (512 panels: about 1e-14 on
/// the intervals used here).
fn prob(a: f64, b: f64) -> f64 {
    let n = 512;
    let h = (b - a) / n as f64;
    let mut s = phi(a) + phi(b);
    for k in 1..n {
        s += phi(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

/// P(X > a), a >= 0 (the density is below 1e-40 twelve units further out).
fn upper(a: f64) -> f64 {
    prob(a, a + 12.0)
}

fn all(streams: &[[Vec<f64>; 2]]) -> impl Iterator<Item = f64> + '_ {
    streams.iter().flatten().flatten().copied()
}

#[test]
fn moments_are_the_standard_normals() {
    let s = draw([1, 2, 3, 4]);
    let n = (8 * PER_STREAM) as f64;
    let (mut m1, mut m2, mut m3, mut m4) = (0.0, 0.0, 0.0, 0.0);
    for x in all(&s) {
        let x2 = x * x;
        m1 += x;
        m2 += x2;
        m3 += x2 * x;
        m4 += x2 * x2;
    }
    let (m1, m2, m3, m4) = (m1 / n, m2 / n, m3 / n, m4 / n);
    // Standard errors of the sample moments of N(0, 1): mean 1/sqrt(n), second moment
    // sqrt(2/n), third sqrt(15/n), fourth sqrt(96/n).
    assert!(m1.abs() < 5.0 / n.sqrt(), "mean {m1}");
    assert!((m2 - 1.0).abs() < 5.0 * (2.0 / n).sqrt(), "variance {m2}");
    assert!(m3.abs() < 5.0 * (15.0 / n).sqrt(), "third moment {m3}");
    assert!(
        (m4 - 3.0).abs() < 5.0 * (96.0 / n).sqrt(),
        "fourth moment {m4}"
    );
}

#[test]
fn tails_follow_erfc_and_the_tail_path_runs() {
    let s = draw([5, 6, 7, 8]);
    let n = (8 * PER_STREAM) as f64;
    // P(|X| > k) = erfc(k / sqrt 2), from mpmath at 30 digits.
    let erfc = [
        (2.0, 0.045_500_263_896_358_42),
        (3.0, 0.002_699_796_063_260_189),
        (4.0, 6.334_248_366_623_985e-5),
        (5.0, 5.733_031_437_583_878e-7),
        (6.0, 1.973_175_290_075_396e-9),
    ];
    // Beyond r = 4.2164 (the ziggurat's base edge) values come only from its tail
    // algorithm: their count checks that path and its scale.
    let r = 4.216_370_409_511_897;
    let mut cases: Vec<(f64, f64)> = erfc.to_vec();
    cases.push((r, 2.0 * upper(r)));
    for (k, p) in cases {
        let c = all(&s).filter(|x| x.abs() > k).count() as f64;
        // Binomial: mean n p, sd sqrt(n p (1 - p)); 3 events of slack where n p is tiny.
        let sd = (n * p * (1.0 - p)).sqrt();
        assert!(
            (c - n * p).abs() < 5.0 * sd + 3.0,
            "P(|x| > {k}): {c} vs {}",
            n * p
        );
        if k == r {
            assert!(c > 500.0, "the tail path ran {c} times");
        }
    }
}

#[test]
fn the_histogram_fits_the_normal_cdf() {
    let s = draw([9, 10, 11, 12]);
    let n = (8 * PER_STREAM) as f64;
    // 200 bins of 0.05 over [-5, 5] and the two tails beyond.
    let (lo, w, bins) = (-5.0, 0.05, 200usize);
    let mut counts = vec![0u64; bins + 2];
    for x in all(&s) {
        let j = ((x - lo) / w).floor();
        let idx = if j < 0.0 {
            bins
        } else if j >= bins as f64 {
            bins + 1
        } else {
            j as usize
        };
        counts[idx] += 1;
    }
    let mut expected: Vec<f64> = (0..bins)
        .map(|j| n * prob(lo + w * j as f64, lo + w * (j + 1) as f64))
        .collect();
    expected.push(n * upper(5.0));
    expected.push(n * upper(5.0));
    let chi2: f64 = counts
        .iter()
        .zip(&expected)
        .map(|(&o, &e)| (o as f64 - e).powi(2) / e)
        .sum();
    // Chi-square with 201 degrees of freedom: mean 201, sd sqrt(402) = 20.
    let df = (bins + 1) as f64;
    let sd = (2.0 * df).sqrt();
    assert!(
        (chi2 - df).abs() < 5.0 * sd,
        "chi-square {chi2} on {df} dof"
    );
}

#[test]
fn each_stream_is_white_and_the_streams_are_independent() {
    let s = draw([13, 14, 15, 16]);
    let len = PER_STREAM as f64;
    let corr = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>() / len;
    for (l, h) in [(0, 0), (3, 1)] {
        let x = &s[l][h];
        // Lags 1..64: each r_k of white noise is N(0, 1/len); their sum of squares times len
        // is chi-square with 64 dof (mean 64, sd 11.3), and no single one passes 4.5 sigma
        // (for 64 lags that happens with a chance of 4e-4).
        let mut q = 0.0;
        for k in 1..=64 {
            let r = corr(&x[k..], &x[..x.len() - k]);
            assert!(
                r.abs() < 4.5 / len.sqrt(),
                "lane {l} stream {h} lag {k}: {r}"
            );
            q += len * r * r;
        }
        assert!(
            q < 64.0 + 5.0 * 128f64.sqrt(),
            "lane {l} stream {h}: Q = {q}"
        );
        // Averaged periodogram over 4096 segments of 1024: flat at 1 (the variance), each
        // bin's average with relative sd 1/64 (sqrt 2 / 64 at DC and Nyquist, which are
        // real); 6 sd over 1024 bins.
        let seg = 1024;
        let fft = FftPlanner::<f64>::new().plan_fft_forward(seg);
        let mut power = vec![0.0; seg];
        let mut buf = vec![Complex64::default(); seg];
        let segs = x.len() / seg;
        for c in x.chunks_exact(seg) {
            for (b, &v) in buf.iter_mut().zip(c) {
                *b = Complex64::new(v, 0.0);
            }
            fft.process(&mut buf);
            for (p, b) in power.iter_mut().zip(&buf) {
                *p += b.norm_sqr() / seg as f64;
            }
        }
        for (k, p) in power.iter().enumerate() {
            let p = p / segs as f64;
            let sd = if k == 0 || k == seg / 2 {
                2f64.sqrt()
            } else {
                1.0
            } / (segs as f64).sqrt();
            assert!(
                (p - 1.0).abs() < 6.0 * sd,
                "lane {l} stream {h} bin {k}: {p}"
            );
        }
    }
    // Streams a and b of a lane, and the same stream of two lanes: uncorrelated at lag 0.
    for (a, b) in [((0, 0), (0, 1)), ((0, 0), (1, 0)), ((2, 1), (3, 1))] {
        let r = corr(&s[a.0][a.1], &s[b.0][b.1]);
        assert!(r.abs() < 5.0 / len.sqrt(), "{a:?} vs {b:?}: {r}");
    }
}

#[test]
fn same_seeds_same_bits_other_seeds_other_bits() {
    let bits = |seeds| {
        let mut r = NoiseRng::new(seeds);
        let mut buf = vec![f64x4::ZERO; 2 * 4096];
        r.fill_pairs(&mut buf);
        buf.iter()
            .flat_map(|v| v.to_array().map(f64::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits([1, 2, 3, 4]), bits([1, 2, 3, 4]));
    let (a, b) = (bits([1, 2, 3, 4]), bits([1, 2, 3, 5]));
    let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
    // Lanes 0-2 agree; lane 3 differs everywhere (a repeat is a chance of 2^-50 or so).
    assert_eq!(same, 3 * a.len() / 4);
}
