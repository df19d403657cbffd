//! Minimal double-double arithmetic (error-free transformations, no FMA), used once to build
//! the NCO's phasor table to about 1e-32, so the stored `hi + lo` pair is exact to f64 rounding.

/// A value `hi + lo` with `|lo| <= ulp(hi) / 2`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Dd {
    pub hi: f64,
    pub lo: f64,
}

fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    Dd { hi: s, lo: e }
}

fn quick_two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    Dd {
        hi: s,
        lo: b - (s - a),
    }
}

/// Dekker's split: `a = hi + lo` with 26-bit halves.
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let hi = c - (c - a);
    (hi, a - hi)
}

fn two_prod(a: f64, b: f64) -> Dd {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    let e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    Dd { hi: p, lo: e }
}

impl Dd {
    pub(crate) const fn new(hi: f64, lo: f64) -> Self {
        Self { hi, lo }
    }

    pub(crate) fn add(self, o: Dd) -> Dd {
        let s = two_sum(self.hi, o.hi);
        let t = two_sum(self.lo, o.lo);
        let u = quick_two_sum(s.hi, s.lo + t.hi);
        quick_two_sum(u.hi, u.lo + t.lo)
    }

    pub(crate) fn mul(self, o: Dd) -> Dd {
        let p = two_prod(self.hi, o.hi);
        quick_two_sum(p.hi, p.lo + (self.hi * o.lo + self.lo * o.hi))
    }

    pub(crate) fn scale(self, f: f64) -> Dd {
        self.mul(Dd::new(f, 0.0))
    }

    pub(crate) fn div_f(self, d: f64) -> Dd {
        let q1 = self.hi / d;
        let p = two_prod(q1, d);
        let r = ((self.hi - p.hi) - p.lo + self.lo) / d;
        quick_two_sum(q1, r)
    }

    pub(crate) fn neg(self) -> Dd {
        Dd::new(-self.hi, -self.lo)
    }
}

/// pi as a double-double.
pub(crate) const PI: Dd = Dd::new(core::f64::consts::PI, 1.224_646_799_147_353_2e-16);

/// `(cos x, sin x)` by Taylor series, for `0 <= x <= pi/4`, to about 1e-32.
pub(crate) fn cos_sin(x: Dd) -> (Dd, Dd) {
    let x2 = x.mul(x);
    let mut s = x;
    let mut c = Dd::new(1.0, 0.0);
    let mut ts = x; // x^(2n+1) / (2n+1)!
    let mut tc = Dd::new(1.0, 0.0); // x^(2n) / (2n)!
    for n in 1..20 {
        let n = n as f64;
        tc = tc.mul(x2).div_f((2.0 * n - 1.0) * (2.0 * n)).neg();
        ts = ts.mul(x2).div_f((2.0 * n) * (2.0 * n + 1.0)).neg();
        c = c.add(tc);
        s = s.add(ts);
    }
    (c, s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // sqrt(1/2) = 0.70710678118654752440084436210484903928...
        let (c, s) = cos_sin(PI.scale(0.25));
        let hi = core::f64::consts::FRAC_1_SQRT_2;
        assert_eq!(c.hi, hi);
        assert_eq!(s.hi, hi);
        // sqrt(1/2) - f64(sqrt(1/2)) = -4.833646656726457e-17 (mpmath)
        assert!((c.lo + 4.833_646_656_726_457e-17).abs() < 1e-31);
        assert!((s.lo - c.lo).abs() < 1e-31);
        // pi/6: sin = 1/2 exactly.
        let (_, s) = cos_sin(PI.div_f(6.0));
        assert!(((s.hi - 0.5) + s.lo).abs() < 1e-30);
    }

    /// `x` in units of 2^-90, exactly (every value below is on that grid).
    fn units(x: f64) -> i128 {
        let u = x * 2f64.powi(90);
        assert_eq!(u, u.trunc(), "{x} is off the 2^-90 grid");
        u as i128
    }

    #[test]
    fn add_is_the_exact_sum_to_about_2_to_the_minus_104() {
        // Integers as the reference: hi on a 2^-20 grid, lo a fraction of hi's ulp on a 2^-90
        // grid, so both sums are exact in i128 (below 2^122).
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |bits: u32| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> (64 - bits)) as i64
        };
        let mut dd = || {
            let hi = (next(50) - (1 << 49)) as f64 * 2f64.powi(-20);
            let lo = (next(40) - (1 << 39)) as f64 * 2f64.powi(-90);
            let r = quick_two_sum(hi, lo);
            (r, units(hi) + units(lo))
        };
        for _ in 0..20_000 {
            let ((a, ea), (b, eb)) = (dd(), dd());
            let r = a.add(b);
            let (got, want) = (units(r.hi) + units(r.lo), ea + eb);
            assert!(
                (got - want).abs() <= (want.abs() >> 100) + 1,
                "{a:?} + {b:?} = {r:?}: {got} against {want}"
            );
            // Normalised: lo is below half an ulp of hi.
            assert_eq!(r.hi + r.lo, r.hi, "{r:?}");
        }
    }
}
