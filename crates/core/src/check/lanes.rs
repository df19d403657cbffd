//! Lane-parallel stages against the scalar stage, lane by lane.

use super::{Bits, Gen, SEED};
use crate::Stage;
use core::fmt::Debug;

/// Samples compared per lane.
const RUN: usize = 4000;

/// Checks that lane `l` of the lane-parallel `vector` stage (e.g. `f64x4`) gives, sample for
/// sample, the bits the scalar stage `scalars[l]` gives when fed lane `l` of the input, for
/// every `l < scalars.len()`.
///
/// `input` draws one vector input (lanes independent where the stage allows: a carrier that
/// all lanes share stays shared); `lane_input` takes lane `l` of it; `lane_output` takes lane
/// `l` of a vector output and `scalar_output` maps a scalar output to the same comparable
/// form. Both stages are cloned, never advanced. Panics on the first difference.
pub fn lanes_match<V, L, W>(
    name: &str,
    vector: &V,
    scalars: &[L],
    mut input: impl FnMut(&mut Gen) -> V::Input,
    lane_input: impl Fn(&V::Input, usize) -> L::Input,
    lane_output: impl Fn(&V::Output, usize) -> W,
    scalar_output: impl Fn(&L::Output) -> W,
) where
    V: Stage + Clone,
    L: Stage + Clone,
    W: Bits + Debug,
{
    let mut gen = Gen::new(SEED ^ 2);
    let mut v = vector.clone();
    let mut s: Vec<L> = scalars.to_vec();
    for n in 0..RUN {
        let x = input(&mut gen);
        let y = v.tick(x);
        for (l, sl) in s.iter_mut().enumerate() {
            let want = scalar_output(&sl.tick(lane_input(&x, l)));
            let got = lane_output(&y, l);
            if got.words() != want.words() {
                panic!(
                    "{name}: lanes_match: lane {l} sample {n}: the scalar stage gave {want:?}, \
                     the lane-parallel stage gave {got:?}"
                );
            }
        }
    }
}

/// Checks a lane replaced mid-run (a board's lane refilled with another operating point):
/// `vector` fed [`RUN`] inputs, with `replace` applied to lane `lane` after the first `at`,
/// gives in that lane, from then on, the bits the scalar stage `fresh` gives when fed the
/// lane's inputs from there; and in every other lane of the first `lanes`, at every sample,
/// the bits of `vector` run without the replacement. `input`, `lane_input`, `lane_output`
/// and `scalar_output` as in [`lanes_match`]. Panics on the first difference.
#[allow(clippy::too_many_arguments)] // the harness's closures, as in `lanes_match`
pub fn lane_replaced_matches<V, L, W>(
    name: &str,
    vector: &V,
    (lane, lanes, at): (usize, usize, usize),
    replace: impl Fn(&mut V, usize),
    fresh: &L,
    mut input: impl FnMut(&mut Gen) -> V::Input,
    lane_input: impl Fn(&V::Input, usize) -> L::Input,
    lane_output: impl Fn(&V::Output, usize) -> W,
    scalar_output: impl Fn(&L::Output) -> W,
) where
    V: Stage + Clone,
    L: Stage + Clone,
    W: Bits + Debug,
{
    let mut gen = Gen::new(SEED ^ 3);
    let (mut plain, mut v, mut s) = (vector.clone(), vector.clone(), fresh.clone());
    for n in 0..RUN {
        if n == at {
            replace(&mut v, lane);
        }
        let x = input(&mut gen);
        let (y, y_plain) = (v.tick(x), plain.tick(x));
        for l in 0..lanes {
            let got = lane_output(&y, l);
            let (want, what) = if l == lane && n >= at {
                (
                    scalar_output(&s.tick(lane_input(&x, l))),
                    "the fresh scalar stage",
                )
            } else {
                (
                    lane_output(&y_plain, l),
                    "the stage without the replacement",
                )
            };
            if got.words() != want.words() {
                panic!(
                    "{name}: lane_replaced_matches: lane {l} sample {n} (lane {lane} replaced \
                     at {at}): {what} gave {want:?}, the replaced stage gave {got:?}"
                );
            }
        }
    }
}
