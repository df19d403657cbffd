//! How the lane-parallel noise sources (the board's white noise, the flicker sources) seed
//! their generators: four lanes per generator, each lane on its point's own stream.

use gyroemu_core::noise::{stream_seed, NoiseRng};

/// The generator of lanes `4q .. 4q + 4`, lane `i` on stream `streams[i]` (lanes past the end
/// repeat the last): every lane-parallel noise source draws from four-lane sets like this one,
/// so a lane draws the same numbers in every lane type.
pub(crate) fn lane_set_rng(seed: u64, streams: &[u64], q: usize) -> NoiseRng {
    let last = streams.len() - 1;
    NoiseRng::new(core::array::from_fn(|i| {
        stream_seed(seed, streams[(4 * q + i).min(last)])
    }))
}
