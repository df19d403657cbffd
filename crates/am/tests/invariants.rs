//! Stage invariants: f64x4 lanes equal scalar stages bit for bit, process on random chunkings
//! equals tick, reset changes nothing (the stages are memoryless).

use gyroemu_am::{AmInput, AmModulator, Dac, DrivePattern, Quantizer};
use gyroemu_core::{f64x4, Sample, Stage};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_inputs(rng: &mut ChaCha8Rng, n: usize) -> Vec<AmInput<f64x4>> {
    let mut r = || f64x4::from_fn(|_| rng.random_range(-1.0..1.0));
    (0..n)
        .map(|_| AmInput {
            carrier_i: r(),
            carrier_q: r(),
            mod_cos: r(),
            mod_sin: r(),
        })
        .collect()
}

fn lane_of(x: &AmInput<f64x4>, i: usize) -> AmInput<f64> {
    AmInput {
        carrier_i: x.carrier_i.lane(i),
        carrier_q: x.carrier_q.lane(i),
        mod_cos: x.mod_cos.lane(i),
        mod_sin: x.mod_sin.lane(i),
    }
}

#[test]
fn modulator_lanes_equal_scalar_bit_for_bit() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let xs = random_inputs(&mut rng, 5000);
    for pattern in [DrivePattern::Coriolis, DrivePattern::Rotating] {
        let mut scalars: Vec<AmModulator<f64>> = [(1.0, 1.0), (0.3, -2.0), (1e-3, 7.5), (0.0, 1.1)]
            .iter()
            .map(|&(a, b)| AmModulator::new(pattern, a, b).unwrap())
            .collect();
        let mut simd = AmModulator::<f64x4>::from_lanes(&scalars);
        assert_eq!(simd.pattern(), pattern);
        for x in &xs {
            let y = simd.tick(*x);
            for (i, s) in scalars.iter_mut().enumerate() {
                let z = s.tick(lane_of(x, i));
                assert_eq!(y[0].lane(i).to_bits(), z[0].to_bits());
                assert_eq!(y[1].lane(i).to_bits(), z[1].to_bits());
            }
        }
    }
    // Fewer lanes than 4 repeat the last; none gives zero gains.
    let one = [AmModulator::<f64>::new(DrivePattern::Rotating, 2.0, 3.0).unwrap()];
    let (g1, g2) = AmModulator::<f64x4>::from_lanes(&one).gains();
    assert_eq!((g1.to_array(), g2.to_array()), ([2.0; 4], [3.0; 4]));
    let (g1, _) = AmModulator::<f64x4>::from_lanes(&[]).gains();
    assert_eq!(g1.to_array(), [0.0; 4]);
}

#[test]
fn quantizer_lanes_equal_scalar_bit_for_bit() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let q4 = Quantizer::<f64x4>::new(12, 1.3).unwrap();
    let q1 = Quantizer::<f64>::new(12, 1.3).unwrap();
    for _ in 0..20_000 {
        let x = f64x4::from_fn(|_| rng.random_range(-2.0..2.0));
        let y = q4.quantize(x);
        for i in 0..4 {
            assert_eq!(y.lane(i).to_bits(), q1.quantize(x.lane(i)).to_bits());
        }
    }
    // Ties round away from zero in every lane, as in the scalar path.
    let step = q1.step();
    let ties = f64x4::from_fn(|i| [0.5, -0.5, 2.5, -2.5][i] * step);
    let y = q4.quantize(ties);
    for i in 0..4 {
        assert_eq!(y.lane(i), q1.quantize(ties.lane(i)));
    }
}

fn check_chunks<T: Stage + Clone>(stage: &T, input: &[T::Input], rng: &mut ChaCha8Rng)
where
    T::Output: PartialEq + std::fmt::Debug + Default,
{
    let mut a = stage.clone();
    let want: Vec<T::Output> = input.iter().map(|x| a.tick(*x)).collect();
    let mut b = stage.clone();
    let mut got = vec![T::Output::default(); input.len()];
    let mut i = 0;
    while i < input.len() {
        let len = rng.random_range(0..200).min(input.len() - i);
        b.process(&input[i..i + len], &mut got[i..i + len]);
        i += len;
    }
    assert_eq!(want, got);
    a.reset();
    let again: Vec<T::Output> = input.iter().map(|x| a.tick(*x)).collect();
    assert_eq!(want, again);
}

#[test]
fn process_on_random_chunks_equals_tick() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let xs4 = random_inputs(&mut rng, 3000);
    let xs1: Vec<AmInput<f64>> = xs4.iter().map(|x| lane_of(x, 2)).collect();
    for pattern in [DrivePattern::Coriolis, DrivePattern::Rotating] {
        let m = AmModulator::<f64>::new(pattern, 1.5, -0.5).unwrap();
        check_chunks(&m, &xs1, &mut rng);
        let m4 = AmModulator::<f64x4>::new(pattern, 1.5, -0.5).unwrap();
        let mut a = m4;
        let mut b = m4;
        let want: Vec<[[f64; 4]; 2]> = xs4
            .iter()
            .map(|x| a.tick(*x).map(|v| v.to_array()))
            .collect();
        let mut got = vec![[f64x4::splat(0.0); 2]; xs4.len()];
        b.process(&xs4, &mut got);
        let got: Vec<[[f64; 4]; 2]> = got.iter().map(|y| y.map(|v| v.to_array())).collect();
        assert_eq!(want, got);
    }
    let reals: Vec<f64> = xs1.iter().map(|x| 1.2 * x.carrier_i).collect();
    check_chunks(&Quantizer::<f64>::new(10, 1.0).unwrap(), &reals, &mut rng);
    check_chunks(
        &Dac::<f64>::new(1e6, Some((10, 1.0))).unwrap(),
        &reals,
        &mut rng,
    );
    check_chunks(&Dac::<f64>::new(1e6, None).unwrap(), &reals, &mut rng);
}
