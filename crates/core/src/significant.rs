//! Numbers written for people: three significant figures, for the printed rates and times of
//! the plan and the closing lines, the spectrum figures' notes and the noise fits, so a small
//! value never reads as `0` (a rate of 0.13 M point-samples/s under an emulated CPU was once
//! printed as `0 M`).

/// `v` with three significant figures: plainly written from 1e-3 to below 1e5 (`2.12`,
/// `0.0123`, `1234`: whole numbers keep their digits), else as `1.50e-6`; zero and non-finite
/// values as Rust writes them.
pub fn sig3(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    if (-3..5).contains(&e) {
        format!("{:.*}", (2 - e).max(0) as usize, v)
    } else {
        format!("{v:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::sig3;

    #[test]
    fn three_figures_plainly_in_the_middle_and_as_exponents_outside() {
        assert_eq!(sig3(2.1234), "2.12");
        assert_eq!(sig3(95.76), "95.8");
        assert_eq!(sig3(0.0123456), "0.0123");
        assert_eq!(sig3(0.131), "0.131");
        assert_eq!(sig3(0.001), "0.00100");
        assert_eq!(sig3(1234.5), "1234");
        assert_eq!(sig3(-7.0), "-7.00");
        assert_eq!(sig3(99999.0), "99999");
        assert_eq!(sig3(1.5e-6), "1.50e-6");
        assert_eq!(sig3(123456.0), "1.23e5");
        assert_eq!(sig3(0.0), "0");
        assert_eq!(sig3(f64::NAN), "NaN");
        assert_eq!(sig3(f64::NEG_INFINITY), "-inf");
    }

    /// Over seeded magnitudes from 1e-9 to 1e9: the text reads back within half a unit of its
    /// last written digit, and that digit is at least the third significant one.
    #[test]
    fn the_text_reads_back_to_three_figures_or_better() {
        let mut x = 0x9E37_79B9_7F4A_7C15_u64;
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            let v = 10f64.powf(18.0 * u - 9.0) * if x & 1 == 0 { 1.0 } else { -1.0 };
            let s = sig3(v);
            let back: f64 = s.parse().unwrap_or_else(|_| panic!("{s} does not parse"));
            let e = v.abs().log10().floor();
            let unit = 10f64.powf(e - 2.0);
            assert!((back - v).abs() <= 0.5 * unit * (1.0 + 1e-9), "{v} -> {s}");
            if s.contains('e') {
                assert!(!(1e-3..1e5).contains(&v.abs()), "{v} -> {s}");
            }
        }
    }
}
