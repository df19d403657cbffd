//! Exact conversion between a frequency ratio and a 64-bit phase word.

/// `(mantissa, exponent)` with `|v| = mantissa * 2^exponent` and the mantissa normalised to
/// 53 significant bits (`2^52 <= mantissa < 2^53`); `None` for zero. `v` must be finite.
fn normalised(v: f64) -> Option<(u64, i32)> {
    let bits = v.abs().to_bits();
    let biased = (bits >> 52) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    let (mut m, mut e) = if biased == 0 {
        (frac, -1074) // subnormal
    } else {
        (frac | (1u64 << 52), biased - 1075)
    };
    if m == 0 {
        return None;
    }
    while m < (1u64 << 52) {
        m <<= 1;
        e -= 1;
    }
    Some((m, e))
}

/// The step word nearest to `num / den * 2^64`, computed exactly (integer arithmetic, ties to
/// even), as a signed value. Why exact: a 10 kHz tone at 1 MS/s rounded through `f/fs` in f64
/// would be off by ~1e-18 turn per step, i.e. 3e-9 rad after 5e8 steps; the exact word is off
/// by at most 2^-65 turn per step (8.5e-11 rad after 5e8 steps).
///
/// Requires finite `num`, finite `den != 0` and `|num / den| < 0.5` (the caller checks).
pub fn ratio_to_word(num: f64, den: f64) -> i64 {
    let (Some((a, ea)), Some((b, eb))) = (normalised(num), normalised(den)) else {
        return 0;
    };
    let negative = (num < 0.0) != (den < 0.0);
    // |ratio| * 2^64 = (a / b) * 2^k with a/b in (1/2, 2).
    let k = ea - eb + 64;
    let (n, d): (u128, u128) = if k > 63 {
        // |ratio| > 1/2: out of contract; saturate instead of overflowing.
        return if negative { i64::MIN } else { i64::MAX };
    } else if k >= 0 {
        ((a as u128) << k, b as u128)
    } else if k >= -2 {
        (a as u128, (b as u128) << (-k))
    } else {
        return 0; // below 2^-2: rounds to zero
    };
    let mut q = n / d;
    let r = n % d;
    if 2 * r > d || (2 * r == d && q & 1 == 1) {
        q += 1;
    }
    let q = q.min(i64::MAX as u128) as i64;
    if negative {
        -q
    } else {
        q
    }
}

/// A phase word as a fraction of a turn in `[0, 1)` (53 significant bits).
#[inline]
pub fn turns_of_word(word: u64) -> f64 {
    (word >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_words_for_dyadic_ratios() {
        assert_eq!(ratio_to_word(1.0, 4.0), 1i64 << 62);
        assert_eq!(ratio_to_word(-1.0, 4.0), -(1i64 << 62));
        assert_eq!(ratio_to_word(983.0 * 15.2587890625, 1e6), 983i64 << 48);
        assert_eq!(ratio_to_word(0.0, 1e6), 0);
        // 1/3 * 2^64 = 6148914691236517205.33.. -> ...205
        assert_eq!(ratio_to_word(1.0, 3.0), 6_148_914_691_236_517_205);
        assert_eq!(ratio_to_word(1e-300, 1.0), 0);
        // 5e-324 (smallest subnormal) over itself times 2^-3: 1/8 turn.
        assert_eq!(ratio_to_word(5e-324, 8.0 * 5e-324), 1i64 << 61);
    }

    #[test]
    fn signs_of_both_operands_count() {
        assert_eq!(ratio_to_word(1.0, -4.0), -(1i64 << 62));
        assert_eq!(ratio_to_word(-1.0, -4.0), 1i64 << 62);
        assert_eq!(ratio_to_word(-3.0, 16.0), -(3i64 << 60));
    }

    #[test]
    fn words_below_one_round_to_nearest_ties_to_even() {
        let p = |e: i32| 2f64.powi(e);
        // ratio x 2^64 = 0.5, 0.75, 1.25, 1.5, 2.5, 0.25: the last steps before 0.
        for (num, den, want) in [
            (1.0, p(65), 0),
            (3.0, p(66), 1),
            (5.0, p(66), 1),
            (3.0, p(65), 2),
            (5.0, p(65), 2),
            (1.0, p(66), 0),
            (-3.0, p(66), -1),
        ] {
            assert_eq!(ratio_to_word(num, den), want, "{num} / {den}");
        }
    }

    /// `x 2^s`, by steps of 2^+-100 (2^s itself is not a double for s < -1074 or > 1023).
    fn scale(mut x: f64, mut s: i32) -> f64 {
        while s != 0 {
            let k = s.clamp(-100, 100);
            x *= 2f64.powi(k);
            s -= k;
        }
        x
    }

    #[test]
    fn scaling_both_operands_by_a_power_of_two_keeps_the_word() {
        // num / den is unchanged, so the word must be too, down into the subnormals (20-bit
        // mantissas stay exact there) and mixing a subnormal with a normal operand.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut checked = 0;
        for _ in 0..2000 {
            let den = ((next() >> 44) | 1) as f64; // up to 2^20
            let below = (0.49 * den).floor().max(1.0); // |num| < den / 2, an integer
            let sign = if next() & 1 == 0 { 1.0 } else { -1.0 };
            let num = sign * ((next() >> 44) as f64 % below);
            let want = ratio_to_word(num, den);
            for s in [-1070, -1060, -1045, -1030, -1000, -500, 300, 900] {
                let (n, d) = (scale(num, s), scale(den, s));
                if scale(n, -s) != num || scale(d, -s) != den || !d.is_finite() {
                    continue;
                }
                assert_eq!(ratio_to_word(n, d), want, "{num} / {den} at 2^{s}");
                checked += 1;
            }
        }
        assert_eq!(checked, 16_000);
    }
}
