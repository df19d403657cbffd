//! Seeded white noise for the noise sources of the board. Each lane (one operating point, so
//! a point's noise does not depend on which lane or group runs it) has two xoshiro256++
//! streams, `a` and `b`, each a sequence of standard normals (the ziggurat of `gauss`); the
//! lane's normals alternate between them: a, b, a, b, ... (two streams side by side let a
//! 512-bit register step both at once).

use wide::u64x4;

/// Boltzmann constant, J/K (exact in the 2019 SI).
pub const BOLTZMANN_J_PER_K: f64 = 1.380_649e-23;

/// SplitMix64 step: the recommended way to expand one 64-bit seed into xoshiro state, and a
/// good mixer to derive independent stream seeds.
#[inline]
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The seed of stream `stream` (e.g. an operating point's index) under a user seed.
pub fn stream_seed(seed: u64, stream: u64) -> u64 {
    let mut s = seed ^ 0x6A09_E667_F3BC_C908;
    let a = splitmix64(&mut s);
    let mut t = a ^ stream.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    splitmix64(&mut t)
}

/// Two independent xoshiro256++ streams per lane, four lanes, stepped together.
#[derive(Clone, Debug)]
pub struct NoiseRng {
    /// `s[h][w]`: word `w` of stream `h` (0: a, 1: b) of the four lanes side by side, so a
    /// step of four lanes' stream is a handful of vector operations.
    pub(crate) s: [[u64x4; 4]; 2],
}

impl NoiseRng {
    /// Lane `l`'s streams seeded through SplitMix64 from `lane_seeds[l]`: its first four
    /// outputs are stream a's state, the next four stream b's.
    pub fn new(lane_seeds: [u64; 4]) -> Self {
        let mut s = [[u64x4::ZERO; 4]; 2];
        for (lane, &seed) in lane_seeds.iter().enumerate() {
            let mut sm = seed;
            for word in s.iter_mut().flatten() {
                word.as_mut_array()[lane] = splitmix64(&mut sm);
            }
        }
        Self { s }
    }

    /// Uniform in [-1/2, 1/2) on each lane, from the top 53 bits of the next output of its
    /// stream a (a production lot's uniform draws; the board's noise takes normals).
    pub fn uniform_centered(&mut self) -> wide::f64x4 {
        let u = step(&mut self.s[0]).to_array();
        wide::f64x4::new(u.map(|x| (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64) - 0.5))
    }
}

/// One xoshiro256++ step of four lanes' states `s[word]` (Blackman and Vigna 2019): the next
/// 64-bit output of each lane.
#[inline(always)]
pub(crate) fn step(s: &mut [u64x4; 4]) -> u64x4 {
    let [s0, s1, s2, s3] = s;
    let x = *s0 + *s3;
    let out = ((x << 23u32) | (x >> 41u32)) + *s0;
    let t = *s1 << 17u32;
    *s2 ^= *s0;
    *s3 ^= *s1;
    *s1 ^= *s2;
    *s0 ^= *s3;
    *s2 ^= t;
    *s3 = (*s3 << 45u32) | (*s3 >> 19u32);
    out
}

/// Standard deviation per sample of a white sequence whose one-sided density is
/// `psd_one_sided` (unit^2/Hz) at every frequency: `sqrt(psd fs / 2)`. Why: a source added to
/// a sampled signal (the TIA's input current, which the TIA takes sample by sample, without a
/// hold) has the density of its samples, flat.
pub fn white_sigma(psd_one_sided: f64, fs_hz: f64) -> f64 {
    (psd_one_sided * fs_hz / 2.0).sqrt()
}

/// Standard deviation per sample of a white sequence held for one sample period (the force:
/// the plant is discretised with a zero-order hold on its input) whose one-sided density near
/// `f_hz` is `psd_one_sided` (unit^2/Hz). Held white noise of variance s^2 has one-sided
/// density 2 s^2 / fs * sinc^2(f / fs); the sinc is divided out at the frequency that matters
/// (the carrier), so the density there is exact.
pub fn held_white_sigma(psd_one_sided: f64, fs_hz: f64, f_hz: f64) -> f64 {
    let x = core::f64::consts::PI * f_hz / fs_hz;
    let sinc = if x == 0.0 { 1.0 } else { x.sin() / x };
    white_sigma(psd_one_sided, fs_hz) / sinc
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// xoshiro256++ written from the reference C code, one u64 state at a time.
    pub(crate) struct Reference(pub(crate) [u64; 4]);
    impl Reference {
        pub(crate) fn next(&mut self) -> u64 {
            let s = &mut self.0;
            let result = (s[0].wrapping_add(s[3])).rotate_left(23).wrapping_add(s[0]);
            let t = s[1] << 17;
            s[2] ^= s[0];
            s[3] ^= s[1];
            s[1] ^= s[2];
            s[0] ^= s[3];
            s[2] ^= t;
            s[3] = s[3].rotate_left(45);
            result
        }
    }

    #[test]
    fn splitmix64_matches_the_published_first_outputs_for_seed_0() {
        // SplitMix64 reference (Steele, Lea, Flood 2014), seed 0.
        let mut s = 0u64;
        assert_eq!(splitmix64(&mut s), 0xE220_A839_7B1D_CDAF);
        assert_eq!(splitmix64(&mut s), 0x6E78_9E6A_A1B9_65F4);
        assert_eq!(splitmix64(&mut s), 0x06C4_5D18_8009_454F);
    }

    /// Each lane's two reference streams, `[lane][stream]`: SplitMix64 from the lane's seed
    /// gives stream a's four words, then stream b's.
    pub(crate) fn reference_streams(seeds: [u64; 4]) -> Vec<[Reference; 2]> {
        seeds
            .iter()
            .map(|&seed| {
                let mut sm = seed;
                [(); 2].map(|_| Reference([(); 4].map(|_| splitmix64(&mut sm))))
            })
            .collect()
    }

    #[test]
    fn each_stream_of_each_lane_is_the_reference_stream_of_its_seed() {
        let seeds = [1, 2, 0xDEAD_BEEF, u64::MAX];
        let mut rng = NoiseRng::new(seeds);
        let mut refs = reference_streams(seeds);
        for _ in 0..10_000 {
            for (h, st) in rng.s.iter_mut().enumerate() {
                let v = step(st).to_array();
                for (l, r) in refs.iter_mut().enumerate() {
                    assert_eq!(v[l], r[h].next(), "lane {l} stream {h}");
                }
            }
        }
    }

    #[test]
    fn uniforms_are_the_top_53_bits_of_stream_a() {
        let seeds = [3, 5, 7, 11];
        let mut rng = NoiseRng::new(seeds);
        let mut refs = reference_streams(seeds);
        for _ in 0..1000 {
            let u = rng.uniform_centered().to_array();
            for (l, r) in refs.iter_mut().enumerate() {
                let want = (r[0].next() >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                assert_eq!(u[l].to_bits(), want.to_bits());
                assert!((-0.5..0.5).contains(&u[l]));
            }
        }
    }

    #[test]
    fn stream_seeds_differ_across_streams_and_seeds() {
        let mut all: Vec<u64> = (0..64)
            .flat_map(|seed| (0..64).map(move |p| stream_seed(seed, p)))
            .collect();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all.len(), 64 * 64);
    }

    #[test]
    fn held_white_sigma_inverts_the_held_noise_density() {
        // At f -> 0 the density of held white noise is 2 s^2 / fs.
        let s = held_white_sigma(3.0, 1000.0, 0.0);
        assert!((2.0 * s * s / 1000.0 - 3.0).abs() < 1e-12);
        // At fs/4 the sinc is sin(pi/4)/(pi/4).
        let s = held_white_sigma(3.0, 1000.0, 250.0);
        let sinc = core::f64::consts::FRAC_1_SQRT_2 / core::f64::consts::FRAC_PI_4;
        assert!((2.0 * s * s / 1000.0 * sinc * sinc - 3.0).abs() < 1e-12);
    }
}
