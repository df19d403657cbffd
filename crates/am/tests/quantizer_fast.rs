//! The quantiser's division-free path (`quantize_counting_fast`) against its division
//! (`quantize_counting`): the same output bits and the same clip and zero counts, on seeded
//! sweeps that crowd the places a product and a quotient could round apart (half-integers a
//! few ulps away, the zero code, the end codes, values that are not numbers), for designs from
//! 2 to 32 bits and extreme full scales; and the fast path taken where it should be.

use gyroemu_am::Quantizer;
use gyroemu_core::{f64x4, Sample};

fn splitmix(s: &mut u64) -> u64 {
    *s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *s;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform in [0, 1).
fn unit(s: &mut u64) -> f64 {
    (splitmix(s) >> 11) as f64 / (1u64 << 53) as f64
}

/// (bits, full scale): the presets' converters, the smallest and largest widths, and full
/// scales whose step or reciprocal leave the normal range (the fast path must then stand
/// aside).
const DESIGNS: [(u32, f64); 12] = [
    (2, 1.0),
    (3, 1.0),
    (8, 0.7),
    (16, 1.5),
    (16, 0.05),
    (20, 1e-6),
    (24, 3.3),
    (31, 2.0),
    (32, 1.0),
    (32, 1e-300),
    (16, 1e300),
    (2, 1.7e308),
];

/// Inputs for `q`: uniform over 1.3 full scales, half-integer codes and exact levels each
/// moved by -8..=8 ulps, the end codes' edges, and special values.
fn inputs(q: &Quantizer<f64>, seed: u64) -> Vec<f64> {
    let step = q.step();
    let half = (1u64 << (q.bits() - 1)) as f64;
    let mut s = seed;
    let mut v = Vec::new();
    let nudged = |v: &mut Vec<f64>, x: f64| {
        let (mut up, mut down) = (x, x);
        v.push(x);
        for _ in 0..8 {
            up = up.next_up();
            down = down.next_down();
            v.push(up);
            v.push(down);
        }
    };
    for _ in 0..4000 {
        v.push((2.0 * unit(&mut s) - 1.0) * 1.3 * half * step);
    }
    for _ in 0..300 {
        // A code across the whole range, and small ones (where the zero code is near).
        let k = if splitmix(&mut s).is_multiple_of(2) {
            (unit(&mut s) * 2.0 * half).floor() - half
        } else {
            (splitmix(&mut s) % 7) as f64 - 3.0
        };
        nudged(&mut v, (k + 0.5) * step);
        nudged(&mut v, k * step);
    }
    // ... and the fast path's own bounds: its tie margin around the zero code.
    let margin = 0.5 - 1.0 / 65536.0;
    for edge in [
        half - 1.0,
        half - 0.5,
        half,
        -half,
        -half - 0.5,
        0.5,
        -0.5,
        margin,
        -margin,
    ] {
        nudged(&mut v, edge * step);
    }
    v.extend([
        0.0,
        -0.0,
        f64::MIN_POSITIVE,
        -f64::MIN_POSITIVE,
        5e-324,
        -5e-324,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        1e300,
        -1e300,
        f64::MAX,
        f64::MIN,
    ]);
    v
}

#[test]
fn fast_path_equals_the_division_in_scalar_and_four_lanes() {
    for (d, &(bits, fs)) in DESIGNS.iter().enumerate() {
        let q1 = Quantizer::<f64>::new(bits, fs).unwrap();
        let q4 = Quantizer::<f64x4>::new(bits, fs).unwrap();
        let mut xs = inputs(&q1, 0x5EED + d as u64);
        // Scalar: each input alone.
        for &x in &xs {
            let (mut c0, mut z0, mut c1, mut z1) = (0.0, 0.0, 0.0, 0.0);
            let want = q1.quantize_counting(x, &mut c0, &mut z0);
            let got = q1.quantize_counting_fast(x, &mut c1, &mut z1);
            assert_eq!(
                got.to_bits(),
                want.to_bits(),
                "{bits} bits, full scale {fs}: x = {x:e} gave {got:e}, the division {want:e}"
            );
            assert_eq!((c1, z1), (c0, z0), "{bits} bits, {fs}: counts at x = {x:e}");
        }
        // Four lanes: shuffled, so that a lane near an edge shares its group with clear ones.
        let mut s = 0xF00D + d as u64;
        for i in (1..xs.len()).rev() {
            xs.swap(i, (splitmix(&mut s) % (i as u64 + 1)) as usize);
        }
        let (mut c0, mut z0, mut groups) = ([f64x4::ZERO; 2], [f64x4::ZERO; 2], 0);
        for g in xs.chunks_exact(4) {
            let x = f64x4::new(g.try_into().unwrap());
            let want = q4.quantize_counting(x, &mut c0[0], &mut z0[0]);
            let got = q4.quantize_counting_fast(x, &mut c0[1], &mut z0[1]);
            for l in 0..4 {
                assert_eq!(got.lane(l).to_bits(), want.lane(l).to_bits(), "{g:?}");
            }
            groups += 1;
        }
        assert!(groups > 1000, "{groups} groups");
        assert_eq!(
            c0[1].to_array(),
            c0[0].to_array(),
            "{bits} bits: clip counts"
        );
        assert_eq!(
            z0[1].to_array(),
            z0[0].to_array(),
            "{bits} bits: zero counts"
        );
    }
}

#[test]
fn the_product_serves_clear_inputs_and_zeros_and_leaves_edges_to_the_division() {
    let q = Quantizer::<f64>::new(16, 1.5).unwrap();
    let step = q.step();
    // 0.3 V is code 4369.07: clear of every edge, not zero.
    assert_eq!(q.quantize_by_product(0.3), Some((q.quantize(0.3), 0.0)));
    // The zero code stays on the product, flagged, with the sign of zero the division gives.
    for zero in [0.0, -0.0, 0.25 * step, -0.25 * step, 1e-310, -5e-324] {
        let (y, flag) = q.quantize_by_product(zero).expect("a zero code");
        assert_eq!(y.to_bits(), q.quantize(zero).to_bits(), "x = {zero:e}");
        assert_eq!(flag, 1.0, "x = {zero:e}");
    }
    // Ties (of the zero code too), clipped codes and a NaN go to the division.
    for edge in [
        0.5 * step,
        -0.5 * step,
        100.5 * step,
        -7.5 * step,
        2.0,
        -2.0,
        f64::NAN,
    ] {
        assert_eq!(q.quantize_by_product(edge), None, "x = {edge:e}");
    }
    // Almost every input of a 16-bit converter's range takes the product (near-ties 2^-15
    // of them).
    let mut s = 7;
    let n = 100_000;
    let fast = (0..n)
        .filter(|_| {
            q.quantize_by_product((2.0 * unit(&mut s) - 1.0) * 1.4)
                .is_some()
        })
        .count();
    assert!(fast > n * 999 / 1000, "{fast} of {n}");
    // A zero lane is flagged in its own lane; one lane at an edge sends its group to the
    // division.
    let q4 = Quantizer::<f64x4>::new(16, 1.5).unwrap();
    let (_, flags) = q4
        .quantize_by_product(f64x4::new([0.3, -0.7, 0.0, 0.11]))
        .expect("clear and zero lanes");
    assert_eq!(flags.to_array(), [0.0, 0.0, 1.0, 0.0]);
    assert!(q4
        .quantize_by_product(f64x4::new([0.3, -0.7, 7.5 * step, 0.11]))
        .is_none());
    // A step whose reciprocal is not normal (subnormal, or infinite) turns the product off.
    let wide = Quantizer::<f64>::new(2, 1.7e308).unwrap();
    assert_eq!(wide.quantize_by_product(1e308), None);
    assert_eq!(wide.quantize_by_product(0.0), None);
    let tiny = Quantizer::<f64>::new(32, 1e-300).unwrap();
    assert!(tiny.step() < f64::MIN_POSITIVE && (1.0 / tiny.step()).is_infinite());
    assert_eq!(tiny.quantize_by_product(1e-305), None);
    assert_eq!(tiny.quantize_by_product(0.0), None);
}
