//! Seeded white noise for the noise sources of the board: one xoshiro256++ stream per lane
//! (one operating point per lane, so a point's noise does not depend on which lane or group
//! runs it), and Gaussian pairs by Box-Muller with `wide`'s polynomial `ln` and `sin_cos`
//! (pure arithmetic, so the same bits on every run and thread count).

use wide::f64x4;

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

/// Four independent xoshiro256++ streams, one per lane, stepped together.
#[derive(Clone, Debug)]
pub struct NoiseRng {
    /// State word `w` of every lane: `s[w][lane]` (lanes side by side so the steps vectorise).
    s: [[u64; 4]; 4],
}

impl NoiseRng {
    /// One stream per lane, each seeded through SplitMix64 from its own 64-bit seed.
    pub fn new(lane_seeds: [u64; 4]) -> Self {
        let mut s = [[0u64; 4]; 4];
        for (lane, &seed) in lane_seeds.iter().enumerate() {
            let mut sm = seed;
            for word in s.iter_mut() {
                word[lane] = splitmix64(&mut sm);
            }
        }
        Self { s }
    }

    /// The next 64-bit output of every lane (xoshiro256++, Blackman and Vigna 2019).
    #[inline(always)]
    pub fn next_u64(&mut self) -> [u64; 4] {
        let [s0, s1, s2, s3] = &mut self.s;
        let mut out = [0u64; 4];
        for l in 0..4 {
            out[l] = s0[l]
                .wrapping_add(s3[l])
                .rotate_left(23)
                .wrapping_add(s0[l]);
            let t = s1[l] << 17;
            s2[l] ^= s0[l];
            s3[l] ^= s1[l];
            s1[l] ^= s2[l];
            s0[l] ^= s3[l];
            s2[l] ^= t;
            s3[l] = s3[l].rotate_left(45);
        }
        out
    }

    /// Uniform in (0, 1]: the top 53 bits, offset by one step so `ln` never sees 0.
    #[inline(always)]
    pub fn uniform_open0(&mut self) -> f64x4 {
        let u = self.next_u64();
        f64x4::new(u.map(|x| ((x >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)))
    }

    /// Uniform in [-1/2, 1/2).
    #[inline(always)]
    pub fn uniform_centered(&mut self) -> f64x4 {
        let u = self.next_u64();
        f64x4::new(u.map(|x| (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64) - 0.5))
    }

    /// Two independent standard normals per lane (Box-Muller).
    #[inline(always)]
    pub fn normal_pair(&mut self) -> (f64x4, f64x4) {
        let u1 = self.uniform_open0();
        let u2 = self.uniform_centered();
        let r = (f64x4::splat(-2.0) * u1.ln()).sqrt();
        let (s, c) = (f64x4::splat(core::f64::consts::TAU) * u2).sin_cos();
        (r * c, r * s)
    }
}

/// Standard deviation per sample of a white sequence held for one sample period (as every
/// source in the chain is: the plant and TIA see zero-order-held inputs) whose one-sided
/// density near `f_hz` is `psd_one_sided` (unit^2/Hz). Held white noise of variance s^2 has
/// one-sided density 2 s^2 / fs * sinc^2(f / fs); the sinc is divided out at the frequency
/// that matters (the carrier), so the density there is exact.
pub fn held_white_sigma(psd_one_sided: f64, fs_hz: f64, f_hz: f64) -> f64 {
    let x = core::f64::consts::PI * f_hz / fs_hz;
    let sinc = if x == 0.0 { 1.0 } else { x.sin() / x };
    (psd_one_sided * fs_hz / 2.0).sqrt() / sinc
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xoshiro256++ written from the reference C code, one u64 state at a time.
    struct Reference([u64; 4]);
    impl Reference {
        fn next(&mut self) -> u64 {
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

    #[test]
    fn each_lane_is_the_reference_stream_of_its_seed() {
        let seeds = [1, 2, 0xDEAD_BEEF, u64::MAX];
        let mut rng = NoiseRng::new(seeds);
        let mut refs: Vec<Reference> = seeds
            .iter()
            .map(|&seed| {
                let mut sm = seed;
                Reference([(); 4].map(|_| splitmix64(&mut sm)))
            })
            .collect();
        for _ in 0..10_000 {
            let v = rng.next_u64();
            for l in 0..4 {
                assert_eq!(v[l], refs[l].next());
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
    fn normals_have_gaussian_moments_and_are_white() {
        // 4 lanes x 2 x 250 000 draws: mean within 5 sigma of 0 (sigma = 1/sqrt(n)), variance
        // within 5 sigma (sqrt(2/n)), kurtosis 3 within 5 sqrt(24/n), lag-1 correlation 0
        // within 5/sqrt(n).
        let mut rng = NoiseRng::new([11, 12, 13, 14]);
        let n_pairs = 250_000;
        let mut xs = Vec::with_capacity(8 * n_pairs);
        for _ in 0..n_pairs {
            let (a, b) = rng.normal_pair();
            xs.extend_from_slice(&a.to_array());
            xs.extend_from_slice(&b.to_array());
        }
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        let kurt = xs.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / n / (var * var);
        let lag1 = xs.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / n;
        assert!(mean.abs() < 5.0 / n.sqrt(), "mean {mean}");
        assert!((var - 1.0).abs() < 5.0 * (2.0 / n).sqrt(), "var {var}");
        assert!(
            (kurt - 3.0).abs() < 5.0 * (24.0 / n).sqrt(),
            "kurtosis {kurt}"
        );
        assert!(lag1.abs() < 5.0 / n.sqrt(), "lag-1 correlation {lag1}");
        // Tail: P(|x| > 3) = 0.0026998 (erfc(3/sqrt 2)); binomial sigma.
        let tail = xs.iter().filter(|x| x.abs() > 3.0).count() as f64 / n;
        let p = 0.002_699_796;
        assert!(
            (tail - p).abs() < 5.0 * (p * (1.0 - p) / n).sqrt(),
            "tail {tail}"
        );
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
