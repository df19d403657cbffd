//! Engineering invariants: block processing on random chunkings equals tick, f64x4 lanes give
//! the scalar bits, reset reproduces the output, bad parameters are refused.

mod common;

use common::carrier;
use gyroemu_core::{f64x4, Complex64, Sample, Stage};
use gyroemu_mixer::{Iq, Stage1Mixer, Stage2Mixer, Stage2Out};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

const N: usize = 3000;

/// Runs `process` over random chunk lengths.
fn chunked<T: Stage>(st: &mut T, input: &[T::Input], rng: &mut ChaCha8Rng) -> Vec<T::Output>
where
    T::Output: Default,
{
    let mut out = vec![T::Output::default(); input.len()];
    let mut k = 0;
    while k < input.len() {
        let len = rng.random_range(0..60).min(input.len() - k);
        st.process(&input[k..k + len], &mut out[k..k + len]);
        k += len;
    }
    out
}

fn iq_bits<S: Sample>(z: Iq<S>, lane: usize) -> [u64; 2] {
    [z.i.lane(lane).to_bits(), z.q.lane(lane).to_bits()]
}

fn s2_bits<S: Sample>(o: Stage2Out<S>, lane: usize) -> [u64; 4] {
    let (a, b) = (iq_bits(o.c, lane), iq_bits(o.s, lane));
    [a[0], a[1], b[0], b[1]]
}

fn noise(rng: &mut ChaCha8Rng) -> f64 {
    rng.random_range(-3.0..3.0)
}

#[test]
fn chunked_process_equals_tick_and_reset_reproduces() {
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let in1: Vec<(f64, Complex64)> = (0..N as u64)
        .map(|n| (noise(&mut rng), carrier(n, 3, 17)))
        .collect();
    let mut st = Stage1Mixer::<f64>::new(0.7).unwrap();
    let ticked: Vec<_> = in1.iter().map(|&x| st.tick(x)).collect();
    st.reset();
    assert_eq!(chunked(&mut st, &in1, &mut rng), ticked);

    let in3: Vec<(Iq<f64>, [f64; 2])> = (0..N)
        .map(|_| {
            (
                Iq::new(noise(&mut rng), noise(&mut rng)),
                [noise(&mut rng), noise(&mut rng)],
            )
        })
        .collect();
    let mut st = Stage2Mixer::<f64>::new();
    let ticked: Vec<_> = in3.iter().map(|&x| s2_bits(st.tick(x), 0)).collect();
    st.reset();
    let got: Vec<_> = chunked(&mut st, &in3, &mut rng)
        .into_iter()
        .map(|o| s2_bits(o, 0))
        .collect();
    assert_eq!(got, ticked);
}

#[test]
fn f64x4_lanes_equal_scalar_bit_for_bit() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let phi = -1.234;
    let mut v1 = Stage1Mixer::<f64x4>::new(phi).unwrap();
    let mut s1 = Stage1Mixer::<f64>::new(phi).unwrap();
    let (mut v3, mut s3) = (Stage2Mixer::<f64x4>::new(), Stage2Mixer::<f64>::new());
    for n in 0..N as u64 {
        let y: [f64; 4] = core::array::from_fn(|_| noise(&mut rng));
        let r: [f64; 4] = core::array::from_fn(|_| noise(&mut rng));
        let q: [f64; 4] = core::array::from_fn(|_| noise(&mut rng));
        let r2: [f64; 4] = core::array::from_fn(|_| noise(&mut rng));
        let vy = f64x4::from_fn(|k| y[k]);
        let vr = f64x4::from_fn(|k| r[k]);
        let vq = f64x4::from_fn(|k| q[k]);
        let vr2 = f64x4::from_fn(|k| r2[k]);
        let p = carrier(n, 5, 37);
        let o1 = v1.tick((vy, p));
        let o3 = v3.tick((Iq::new(vy, vq), [vr, vr2]));
        for k in 0..4 {
            assert_eq!(iq_bits(o1, k), iq_bits(s1.tick((y[k], p)), 0));
            assert_eq!(
                s2_bits(o3, k),
                s2_bits(s3.tick((Iq::new(y[k], q[k]), [r[k], r2[k]])), 0)
            );
        }
    }
}

#[test]
fn non_finite_reference_phase_is_a_param_error() {
    for bad in [f64::NAN, f64::INFINITY, -f64::INFINITY] {
        let e = Stage1Mixer::<f64x4>::new(bad).unwrap_err();
        assert_eq!(e.param, "ref_phase_rad");
        assert!(e.to_string().contains("finite"));
    }
}
