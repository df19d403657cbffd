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
