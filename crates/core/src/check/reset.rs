//! `reset` against a fresh clone.

use super::{Bits, Gen, SEED};
use crate::Stage;
use core::fmt::Debug;

/// Samples run before the reset, and compared after it.
const RUN: usize = 3000;

/// Checks that [`Stage::reset`] returns a stage to the state it was built in: a clone run on
/// 3000 seeded inputs, reset, then run on 3000 further inputs gives the bits a fresh clone
/// gives on those further inputs; and a reset of a fresh clone changes nothing.
///
/// `stage` must be as built (the state `reset` restores); it is cloned, never advanced.
/// `input` draws one input sample; `view` maps an output to what is compared
/// ([`super::same`] when the output is [`Bits`]). Panics on the first difference.
pub fn reset_restores<T, V>(
    name: &str,
    stage: &T,
    mut input: impl FnMut(&mut Gen) -> T::Input,
    view: impl Fn(&T::Output) -> V,
) where
    T: Stage + Clone,
    V: Bits + Debug,
{
    let mut gen = Gen::new(SEED ^ 1);
    let before: Vec<T::Input> = (0..RUN).map(|_| input(&mut gen)).collect();
    let after: Vec<T::Input> = (0..RUN).map(|_| input(&mut gen)).collect();
    let mut used = stage.clone();
    before.iter().for_each(|&x| {
        used.tick(x);
    });
    used.reset();
    let mut fresh_reset = stage.clone();
    fresh_reset.reset();
    let mut fresh = stage.clone();
    for (i, &x) in after.iter().enumerate() {
        let want = view(&fresh.tick(x));
        for (what, s) in [
            ("a stage reset after running", &mut used),
            ("a fresh stage reset", &mut fresh_reset),
        ] {
            let got = view(&s.tick(x));
            if got.words() != want.words() {
                panic!(
                    "{name}: reset_restores: sample {i} after the reset: a fresh clone gave \
                     {want:?}, {what} gave {got:?}"
                );
            }
        }
    }
}
