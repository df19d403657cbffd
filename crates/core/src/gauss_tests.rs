//! The ziggurat's tables against their defining equations, and the generator against a plain
//! scalar ziggurat written from the paper (statistics are in tests/gauss.rs).

use super::*;
use crate::gauss_scalar::{closed0, ln, open0};
use crate::gauss_tables::{F, R, V, WEDGE, X};
use crate::noise::tests::{reference_streams, Reference};

/// f(x) = exp(-x^2 / 2), libm (the tests' own reference, not the generator's polynomial).
fn f(x: f64) -> f64 {
    (-0.5 * x * x).exp()
}

/// The integral of f from `a` to infinity by composite Simpson on [a, a + 12] (f is below
/// 1e-40 beyond), 2^16 panels: far below 1e-15 relative for the smooth f.
fn tail_area(a: f64) -> f64 {
    let n = 1 << 16;
    let h = 12.0 / n as f64;
    let mut s = f(a) + f(a + 12.0);
    for k in 1..n {
        s += f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

#[test]
fn every_layer_has_the_same_area_and_the_base_holds_the_tail() {
    // Layer i >= 1: the rectangle [0, X[i]] x [f(X[i]), f(X[i+1])]. The difference of two
    // f values near 1 loses digits, so the areas agree to about 1e-12 relative.
    for i in 1..N {
        let area = X[i] * (f(X[i + 1]) - f(X[i]));
        assert!((area / V - 1.0).abs() < 1e-11, "layer {i}: {area} vs {V}");
    }
    // The base: r f(r) plus the tail beyond r, and its width X[0] = V / f(r).
    let base = R * f(R) + tail_area(R);
    assert!((base / V - 1.0).abs() < 1e-13, "base {base} vs {V}");
    assert!((X[0] * f(R) / V - 1.0).abs() < 1e-15);
    assert_eq!(X[1], R);
    // The top layer ends at the mode: V / X[N-1] + f(X[N-1]) = f(0) = 1.
    assert_eq!(X[N], 0.0);
    assert!((V / X[N - 1] + f(X[N - 1]) - 1.0).abs() < 1e-13);
    // Widths decrease; F is f at them (libm's exp of the rounded -x^2/2 is good to about
    // (1 + x^2/2) eps relative).
    for i in 0..N {
        assert!(X[i + 1] < X[i]);
    }
    for i in 1..=N {
        let tol = (2.0 + X[i] * X[i]) * f64::EPSILON * F[i];
        assert!((F[i] - f(X[i])).abs() <= tol, "F[{i}]");
    }
}

#[test]
fn the_fast_bound_is_exactly_the_core_of_each_layer() {
    // b < B[i] for b = 1 + m 2^-52 must hold exactly when (b - 1) X[i] < X[i+1]: so
    // (B[i] - 1) X[i] >= X[i+1] and (B[i] - 1 - 2^-52) X[i] < X[i+1], compared exactly
    // through the sign of a fused multiply-add (one rounding keeps the sign).
    let ulp = f64::EPSILON; // 2^-52
    for i in 0..N {
        let [width, bound] = FAST.0[i];
        assert_eq!(width, X[i]);
        let t = bound - 1.0;
        assert!(
            t.mul_add(width, -X[i + 1]) >= 0.0,
            "layer {i}: bound too low"
        );
        assert!(
            (t - ulp).mul_add(width, -X[i + 1]) < 0.0,
            "layer {i}: bound too high"
        );
    }
}

#[test]
fn the_wedge_bounds_hold_on_every_wedge() {
    // lo <= f(x) - c(x) <= hi, c the chord between the wedge's corners, at 257 points of
    // each wedge (the bounds' extremes are interior points, so the sampling must come close
    // to them without crossing: a bound too tight by more than the 1 % margin fails).
    for i in 1..N {
        let [slope, lo, hi] = WEDGE[i];
        assert!(lo <= 0.0 && hi >= 0.0);
        let (a, b) = (X[i + 1], X[i]);
        let mut extreme = (0.0f64, 0.0f64);
        for k in 0..=256 {
            let x = a + (b - a) * k as f64 / 256.0;
            let g = f(x) - (F[i] + (b - x) * slope);
            assert!(lo <= g && g <= hi, "layer {i} x {x}: {lo} <= {g} <= {hi}");
            extreme = (extreme.0.min(g), extreme.1.max(g));
        }
        // Tight: the bounds are the extremes widened by 1 % and the rounding pad only.
        assert!(lo >= 1.02 * extreme.0 - 1e-14, "layer {i}: lo {lo} loose");
        assert!(hi <= 1.02 * extreme.1 + 1e-14, "layer {i}: hi {hi} loose");
    }
}

/// Counts of the plain ziggurat's slow paths.
#[derive(Default)]
struct Paths {
    wedge: u64,
    tail: u64,
}

/// Marsaglia and Tsang's ziggurat written plainly on one reference xoshiro256++ stream: the
/// same bits of each draw for the piece, the sign and the uniform, the core tested exactly
/// as (b - 1) X[i] < X[i+1], every wedge point tested against libm's exp, the tail as in
/// Marsaglia (1964) with the generator's `ln` (so its values can be compared bit for bit).
fn plain_normal(r: &mut Reference, paths: &mut Paths) -> f64 {
    loop {
        let w = r.next();
        let i = (w % N as u64) as usize;
        let negative = (w >> 11) & 1 == 1;
        let u = (w >> 12) as f64 * f64::EPSILON;
        let x = u * X[i];
        let sign = |x: f64| if negative { -x } else { x };
        if u.mul_add(X[i], -X[i + 1]) < 0.0 {
            return sign(x);
        }
        if i == 0 {
            paths.tail += 1;
            loop {
                let a = -ln(open0(r.next())) / R;
                let c = -ln(open0(r.next()));
                if c + c > a * a {
                    return sign(R + a);
                }
            }
        }
        paths.wedge += 1;
        let y = F[i] + closed0(r.next()) * (F[i + 1] - F[i]);
        if y < f(x) {
            return sign(x);
        }
    }
}

#[test]
fn each_stream_is_the_plain_ziggurat_on_its_xoshiro_stream() {
    let seeds = [7, 0, 0x1234_5678_9ABC_DEF0, u64::MAX - 3];
    let mut rng = NoiseRng::new(seeds);
    let mut plain = reference_streams(seeds);
    let mut paths = Paths::default();
    let mut out = vec![f64x4::ZERO; 2 * 4096];
    for _ in 0..256 {
        rng.fill_pairs(&mut out);
        for pair in out.chunks_exact(2) {
            for (h, v) in pair.iter().enumerate() {
                for (l, x) in v.to_array().into_iter().enumerate() {
                    let want = plain_normal(&mut plain[l][h], &mut paths);
                    assert_eq!(x.to_bits(), want.to_bits(), "lane {l} stream {h}");
                }
            }
        }
    }
    // 8.4e6 normals: about 0.23 % reach a wedge and 1 in 30 000 the tail.
    assert!(
        paths.wedge > 10_000 && paths.tail > 100,
        "{} {}",
        paths.wedge,
        paths.tail
    );
}

#[test]
fn the_avx512_path_gives_the_portable_bits() {
    #[cfg(target_arch = "x86_64")]
    if crate::gauss_avx512::available() {
        let sets = |seed: u64| {
            let q = |j: u64| NoiseRng::new(core::array::from_fn(|l| seed + 8 * j + l as u64)).s;
            [q(0), q(1)]
        };
        let bits = |v: &[f64x4]| -> Vec<[u64; 4]> {
            v.iter().map(|x| x.to_array().map(f64::to_bits)).collect()
        };
        let words = |s: &[[u64x4; 4]; 2]| s.map(|h| h.map(|w| w.to_array()));
        for lookup in [Lookup::Loads, Lookup::Gather] {
            let (mut a, mut b) = (sets(1), sets(1));
            let (mut fa, mut fb) = (vec![f64x4::ZERO; 4096], vec![f64x4::ZERO; 4096]);
            for _ in 0..64 {
                // One register pair (stream a and b of four lanes), then two (eight lanes).
                // SAFETY: AVX-512F checked above.
                unsafe {
                    crate::gauss_avx512::fill_one(&mut a[0], &mut fa, lookup == Lookup::Gather)
                };
                fill_one_portable(&mut b[0], &mut fb);
                assert_eq!(bits(&fa), bits(&fb), "{lookup:?}");
                assert_eq!(words(&a[0]), words(&b[0]), "{lookup:?}");
                // SAFETY: as above.
                unsafe { crate::gauss_avx512::fill_two(&mut a, &mut fa, lookup == Lookup::Gather) };
                fill_two_portable(&mut b, &mut fb);
                assert_eq!(bits(&fa), bits(&fb), "{lookup:?}");
                assert_eq!(a.map(|s| words(&s)), b.map(|s| words(&s)), "{lookup:?}");
            }
        }
        return;
    }
    eprintln!("no AVX-512F on this CPU: only the portable path runs");
}

#[test]
fn blocks_pairs_and_fills_give_one_sequence() {
    let seeds = [11, 12, 13, 14];
    let mut pairs = NoiseRng::new(seeds);
    let mut fill = NoiseRng::new(seeds);
    let mut buf = vec![f64x4::ZERO; 2 * 1000];
    fill.fill_pairs(&mut buf);
    let bits = |v: f64x4| v.to_array().map(f64::to_bits);
    // Read through ready / row / advance, in runs of up to 7 samples.
    let mut block = NormalBlock::new(NoiseRng::new(seeds));
    assert_eq!(block.width(), 4);
    let mut k = 0;
    while k < 500 {
        let n = block.ready(7.min(500 - k as u64));
        let base = block.pos();
        for j in 0..n as usize {
            let (a1, b1) = pairs.normal_pair();
            let (a2, b2) = pairs.normal_pair();
            let rows: [f64x4; 4] = core::array::from_fn(|c| {
                f64x4::new(block.row(base + 4 * j + c, 4).try_into().unwrap())
            });
            assert_eq!([a1, b1, a2, b2].map(bits), rows.map(bits), "sample {k}");
            assert_eq!(bits(buf[4 * k]), bits(a1));
            assert_eq!(bits(buf[4 * k + 3]), bits(b2));
            k += 1;
        }
        block.advance(n);
    }
}

#[test]
fn a_wide_block_gives_each_lane_the_rows_of_a_four_lane_block() {
    let seeds: [u64; 8] = [5, 6, 7, 8, 9, 10, 0xFFFF, 3];
    let quad = |q: usize| NoiseRng::new(core::array::from_fn(|l| seeds[4 * q + l]));
    // Each look-up on one side (the same entries either way, so the same normals).
    let mut wide = NormalBlock::wide(quad(0), quad(1)).with_lookup(Lookup::Gather);
    let four = |q| NormalBlock::new(quad(q)).with_lookup(Lookup::Loads);
    let mut four = [four(0), four(1)];
    assert_eq!(wide.width(), 8);
    // 20 000 samples: many refills, and every lane through wedges and tails.
    for _ in 0..20_000 {
        assert_eq!(wide.ready(1), 1);
        let rows: Vec<Vec<u64>> = (0..4)
            .map(|c| {
                wide.row(wide.pos() + c, 8)
                    .iter()
                    .map(|x| x.to_bits())
                    .collect()
            })
            .collect();
        for (q, b) in four.iter_mut().enumerate() {
            assert_eq!(b.ready(1), 1);
            for (c, row) in rows.iter().enumerate() {
                let want: Vec<u64> = b.row(b.pos() + c, 4).iter().map(|x| x.to_bits()).collect();
                assert_eq!(&row[4 * q..4 * q + 4], &want[..], "lanes {}..", 4 * q);
            }
            b.advance(1);
        }
        wide.advance(1);
    }
}

#[test]
fn lanes_do_not_depend_on_their_neighbours() {
    // A stream's normals are the same whatever the other lanes hold (their rare paths draw
    // only from their own streams).
    let solo = |seed: u64| {
        let mut r = NoiseRng::new([seed; 4]);
        let mut out = vec![f64x4::ZERO; 2 * 20_000];
        r.fill_pairs(&mut out);
        out.iter()
            .map(|v| v.to_array()[0].to_bits())
            .collect::<Vec<_>>()
    };
    let seeds = [3, 1, 4, 1_000_003];
    let mut r = NoiseRng::new(seeds);
    let mut out = vec![f64x4::ZERO; 2 * 20_000];
    r.fill_pairs(&mut out);
    for (l, &s) in seeds.iter().enumerate() {
        let mine: Vec<u64> = out.iter().map(|v| v.to_array()[l].to_bits()).collect();
        assert_eq!(mine, solo(s), "lane {l}");
    }
}
