//! Number text for large CSV dumps, byte for byte what [`format_f64`](crate::format_f64) and
//! `{}` write, several times faster: ryu finds the shortest round-trip digits (the same digits
//! Rust's formatter finds), this lays them out the way Rust does.

/// Appends `x` exactly as [`format_f64`](crate::format_f64) would.
pub(crate) fn push_f64(x: f64, out: &mut Vec<u8>) {
    if !x.is_finite() {
        out.extend_from_slice(if x.is_nan() {
            b"NaN"
        } else if x > 0.0 {
            b"inf"
        } else {
            b"-inf"
        });
        return;
    }
    if x == 0.0 {
        out.extend_from_slice(if x.is_sign_negative() { b"-0" } else { b"0" });
        return;
    }
    let mut buf = ryu::Buffer::new();
    let text = buf.format_finite(x).as_bytes();
    // ryu switches to d.ddde-x below 1e-5 and at 1e16 and above, where format_f64 switches to
    // `{:e}`, whose layout is the same; in between it writes integers with a ".0" that `{}`
    // leaves out. Only the digits of an exact tie can differ.
    if ryu_rounded_a_tie_down(x, digits_after_point(text)) {
        let mut s = String::new();
        crate::format_f64(x, &mut s);
        out.extend_from_slice(s.as_bytes());
        return;
    }
    out.extend_from_slice(text.strip_suffix(b".0").unwrap_or(text));
}

/// How many digits of ryu's `text` lie after the decimal point of the value (negative when
/// the last significant digit is left of it: "1200.0" gives -2, "1.5e3" gives -2).
fn digits_after_point(text: &[u8]) -> i32 {
    let (mant, exp) = match text.iter().position(|&b| b == b'e') {
        Some(i) => (&text[..i], parse_exp(&text[i + 1..])),
        None => (text, 0),
    };
    let frac = match mant.iter().position(|&b| b == b'.') {
        Some(i) if &mant[i..] == b".0" => {
            // An integer: its trailing zeros are not significant.
            let int = &mant[..i];
            -(int.iter().rev().take_while(|&&b| b == b'0').count() as i32)
        }
        Some(i) => (mant.len() - i - 1) as i32,
        None => 0,
    };
    frac - exp
}

/// Whether |x| lies exactly halfway between two decimals with `m` digits after the point
/// (`m` < 0: multiples of 10^-m) and ryu, which breaks ties to even, took the lower one.
/// With |x| = M 2^E, M odd: 2 |x| 10^m = M 2^(E+1+m) 5^m is an odd integer Q exactly when
/// E + 1 + m = 0 and (m >= 0 or 5^-m divides M); the lower neighbour (Q - 1)/2 is even, so
/// ryu's choice, when Q = 1 mod 4, and 5^m = 1 mod 4 makes that M = 1 mod 4.
fn ryu_rounded_a_tie_down(x: f64, m: i32) -> bool {
    let bits = x.to_bits();
    let (frac, exp) = (bits & ((1 << 52) - 1), ((bits >> 52) & 0x7ff) as i32);
    let (mant, e2) = if exp == 0 {
        (frac, -1074)
    } else {
        (frac | (1 << 52), exp - 1075)
    };
    let tz = mant.trailing_zeros() as i32;
    let (odd, e2) = (mant >> tz, e2 + tz);
    if e2 + 1 + m != 0 {
        return false;
    }
    if m < 0 {
        // 5^-m must divide a 53-bit odd integer: -m <= 22.
        let Some(p) = 5u64.checked_pow((-m) as u32) else {
            return false;
        };
        if odd % p != 0 {
            return false;
        }
    }
    odd % 4 == 1
}

fn parse_exp(b: &[u8]) -> i32 {
    let (neg, digits) = match b.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, b),
    };
    let v = digits
        .iter()
        .fold(0i32, |acc, &c| acc * 10 + i32::from(c - b'0'));
    if neg {
        -v
    } else {
        v
    }
}

/// Appends `i` in decimal, as `{}` writes it.
pub(crate) fn push_i64(i: i64, out: &mut Vec<u8>) {
    if i < 0 {
        out.push(b'-');
    }
    let mut v = i.unsigned_abs();
    let mut buf = [0u8; 20];
    let mut at = buf.len();
    loop {
        at -= 1;
        buf[at] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    out.extend_from_slice(&buf[at..]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format_f64;

    fn check(x: f64) {
        let mut want = String::new();
        format_f64(x, &mut want);
        let mut got = Vec::new();
        push_f64(x, &mut got);
        assert_eq!(
            String::from_utf8(got).unwrap(),
            want,
            "bits {:#x}",
            x.to_bits()
        );
    }

    #[test]
    fn text_equals_the_std_formatter_on_edge_values() {
        let edges = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.3,
            1e-5,
            9.999999999999999e-6,
            1e-6,
            1.5e-7,
            1e15,
            9.999999999999998e15,
            1e16,
            1e17,
            123456.789,
            1e21,
            1e22,
            1e23,
            5e-324,
            2.2e-308,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            0.000123,
            100.0,
            1234567890123456.0,
            2.5e-300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            15000.0,
            240000.0,
            1.0 / 3.0,
        ];
        for x in edges {
            check(x);
            check(-x);
        }
    }

    #[test]
    fn text_equals_the_std_formatter_on_random_bit_patterns() {
        // xorshift64: random exponents and mantissas over the whole f64 range, plus values of
        // signal-like magnitude.
        let mut s: u64 = 0x2545_F491_4F6C_DD1D;
        for i in 0..400_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            check(f64::from_bits(s));
            check((s >> 11) as f64 / (1u64 << 53) as f64 * 10f64.powi((i % 40) - 20));
        }
    }

    /// The significant digits of a number's text, without sign, point, exponent or padding.
    fn digits(t: &str) -> String {
        let mant = t.split('e').next().unwrap_or("");
        let d: String = mant.chars().filter(|c| c.is_ascii_digit()).collect();
        d.trim_start_matches('0').trim_end_matches('0').to_string()
    }

    #[test]
    fn exact_ties_round_up_like_the_std_formatter() {
        // Numbers with few fraction bits near 2^50..2^64 often sit exactly halfway between two
        // shortest candidates, where ryu's digits (ties to even) differ from std's: count them
        // so the test is known to reach that path.
        let mut ties = 0;
        let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
        for i in 0..100_000u32 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let x = (s >> (i % 14)) as f64 * 2f64.powi(-((i % 5) as i32));
            check(x);
            check(-x);
            let mut b = ryu::Buffer::new();
            if digits(b.format_finite(x)) != digits(&x.to_string()) {
                ties += 1;
            }
        }
        assert!(ties > 100, "only {ties} ties met");
        check(1322592288487445.2);
    }

    #[test]
    fn integers_equal_the_std_formatter() {
        for i in [
            0i64,
            1,
            -1,
            9,
            10,
            99,
            100,
            1 << 40,
            i64::MAX,
            i64::MIN,
            -1234567,
        ] {
            let mut got = Vec::new();
            push_i64(i, &mut got);
            assert_eq!(String::from_utf8(got).unwrap(), i.to_string());
        }
    }
}
