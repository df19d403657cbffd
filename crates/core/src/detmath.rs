//! Sine and cosine from plain IEEE arithmetic, so the signal path gives the same bits on
//! every platform (Rust's `f64::sin`/`cos` call the platform libm, which differs).
//!
//! Cody-Waite reduction by pi/2 with a three-part constant, then the fdlibm minimax
//! polynomials on [-pi/4, pi/4] (about 1.3 ulp at worst, no tail correction). Accurate to about 2e-16 for
//! |x| <= 1e6; beyond that the reduction loses bits, so callers reduce phases themselves
//! (the NCO keeps its phase as a 64-bit integer and never passes a large angle).

const PIO2_1: f64 = 1.570_796_326_734_125_6; // first 33 bits of pi/2
const PIO2_2: f64 = 6.077_100_506_303_966e-11; // next 33 bits
const PIO2_3: f64 = 2.022_266_248_711_166_5e-21; // next bits
const TWO_OVER_PI: f64 = core::f64::consts::FRAC_2_PI;

const S1: f64 = -1.666_666_666_666_663_2e-1;
const S2: f64 = 8.333_333_333_322_49e-3;
const S3: f64 = -1.984_126_982_985_795e-4;
const S4: f64 = 2.755_731_370_707_006_8e-6;
const S5: f64 = -2.505_076_025_340_686_3e-8;
const S6: f64 = 1.589_690_995_211_55e-10;

const C1: f64 = 4.166_666_666_666_66e-2;
const C2: f64 = -1.388_888_888_887_411e-3;
const C3: f64 = 2.480_158_728_947_673e-5;
const C4: f64 = -2.755_731_435_139_066_3e-7;
const C5: f64 = 2.087_572_321_298_175e-9;
const C6: f64 = -1.135_964_755_778_819_5e-11;

#[inline(always)]
fn kernel(r: f64) -> (f64, f64) {
    let z = r * r;
    let s = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let c = 1.0 - 0.5 * z + z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    (s, c)
}

/// `(sin x, cos x)`, bit-identical on every IEEE-754 platform.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let k = (x * TWO_OVER_PI).round();
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let (s, c) = kernel(r);
    // k is an exact small integer here; the quadrant picks signs and swaps.
    match (k as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// `(sin, cos)` of `2 pi * turns`, for a phase given in turns.
#[inline]
pub fn sin_cos_turns(turns: f64) -> (f64, f64) {
    // Reduce in turns first (exact for the fractional part), then to radians.
    let frac = turns - turns.round();
    sin_cos(frac * core::f64::consts::TAU)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agrees_with_libm_to_a_few_ulp() {
        let mut worst: f64 = 0.0;
        let mut x = -1000.0_f64;
        while x < 1000.0 {
            let (s, c) = sin_cos(x);
            worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
            x += 0.012_345_678_9;
        }
        assert!(worst < 4e-16, "worst abs error {worst}");
    }

    #[test]
    fn exact_at_quadrant_points_and_pythagoras() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos_turns(0.25);
        assert!((s - 1.0).abs() < 1e-16 && c.abs() < 1e-16);
        for i in 0..1000 {
            let (s, c) = sin_cos(i as f64 * 0.731);
            assert!((s * s + c * c - 1.0).abs() < 4e-16);
        }
    }
}
