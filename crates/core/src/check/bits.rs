//! Outputs as words of bits, so the checks compare them exactly (`-0.0` is not `0.0`, and a
//! NaN's payload counts), whatever the stage's output type.

use num_complex::Complex64;
use wide::f64x4;

/// A value as a fixed sequence of 64-bit words: every `f64` by its `to_bits`, every lane of an
/// `f64x4`, an `Option` as a tag word (0 for `None`, 1 for `Some`) followed by its content.
pub trait Bits {
    /// Calls `f` with every word, in a fixed order.
    fn visit(&self, f: &mut dyn FnMut(u64));

    /// All words, in order.
    fn words(&self) -> Vec<u64> {
        let mut w = Vec::new();
        self.visit(&mut |x| w.push(x));
        w
    }
}

/// The view of an output that already is [`Bits`]: the output itself.
pub fn same<T: Copy>(y: &T) -> T {
    *y
}

impl Bits for f64 {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        f(self.to_bits());
    }
}

impl Bits for f64x4 {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        self.to_array().iter().for_each(|v| f(v.to_bits()));
    }
}

impl Bits for Complex64 {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        f(self.re.to_bits());
        f(self.im.to_bits());
    }
}

impl Bits for () {
    fn visit(&self, _f: &mut dyn FnMut(u64)) {}
}

impl Bits for bool {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        f(u64::from(*self));
    }
}

impl Bits for u64 {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        f(*self);
    }
}

impl Bits for usize {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        f(*self as u64);
    }
}

impl<T: Bits + ?Sized> Bits for &T {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        (**self).visit(f);
    }
}

impl<T: Bits, const N: usize> Bits for [T; N] {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        self.iter().for_each(|x| x.visit(f));
    }
}

impl<T: Bits> Bits for [T] {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        self.iter().for_each(|x| x.visit(f));
    }
}

impl<T: Bits> Bits for Option<T> {
    fn visit(&self, f: &mut dyn FnMut(u64)) {
        match self {
            None => f(0),
            Some(x) => {
                f(1);
                x.visit(f);
            }
        }
    }
}

macro_rules! tuple_bits {
    ($($t:ident $i:tt),+) => {
        impl<$($t: Bits),+> Bits for ($($t,)+) {
            fn visit(&self, f: &mut dyn FnMut(u64)) {
                $(self.$i.visit(f);)+
            }
        }
    };
}
tuple_bits!(A 0);
tuple_bits!(A 0, B 1);
tuple_bits!(A 0, B 1, C 2);
tuple_bits!(A 0, B 1, C 2, D 3);
