//! The harness against stages whose truths are closed forms: a correct one-pole passes every
//! check and the measured values are the closed forms; each planted fault is caught by the
//! check meant for it.

use super::*;
use crate::{Complex64, Response, Sample, Stage};
use core::f64::consts::TAU;
use wide::f64x4;

/// What a test stage gets wrong.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fault {
    None,
    /// `process` starts every block from rest.
    BlockStartsAtRest,
    /// `process` writes one output slot past the inputs when there is room.
    WritesPastInput,
    /// `process` consumes every input, also those past the outputs.
    ConsumesExtraInput,
    /// `reset` does nothing.
    ForgetsReset,
    /// Lanes 1 and 2 of the output are swapped.
    SwapsLanes,
    /// `response` returns the conjugate (a phase lead instead of a lag).
    ConjugateResponse,
    /// `latency_samples` is half a sample too long.
    LatencyOffByHalf,
}

/// `y[n] = a y[n-1] + (1 - a) x[n]`: response `(1 - a) / (1 - a e^{-jw})`, DC group delay
/// `a / (1 - a)` samples (closed forms).
#[derive(Clone, Debug)]
struct OnePole<S> {
    a: S,
    y: S,
    a_f64: f64,
    fault: Fault,
}

impl<S: Sample> OnePole<S> {
    fn new(a: f64, fault: Fault) -> Self {
        Self::lanes([a; 4], fault)
    }

    fn lanes(a: [f64; 4], fault: Fault) -> Self {
        Self {
            a: S::from_fn(|i| a[i]),
            y: S::default(),
            a_f64: a[0],
            fault,
        }
    }
}

impl<S: Sample> Stage for OnePole<S> {
    type Input = S;
    type Output = S;

    fn tick(&mut self, x: S) -> S {
        self.y = self.a * self.y + (S::splat(1.0) - self.a) * x;
        if self.fault == Fault::SwapsLanes {
            let y = self.y;
            return S::from_fn(|i| y.lane([0, 2, 1, 3][i]));
        }
        self.y
    }

    fn process(&mut self, input: &[S], output: &mut [S]) {
        if self.fault == Fault::BlockStartsAtRest && !input.is_empty() {
            self.y = S::default();
        }
        let n = input.len().min(output.len());
        for (x, y) in input.iter().zip(output.iter_mut()) {
            *y = self.tick(*x);
        }
        if self.fault == Fault::WritesPastInput && output.len() > n {
            output[n] = S::splat(0.25);
        }
        if self.fault == Fault::ConsumesExtraInput {
            input[n..].iter().for_each(|&x| {
                self.tick(x);
            });
        }
    }

    fn reset(&mut self) {
        if self.fault != Fault::ForgetsReset {
            self.y = S::default();
        }
    }

    fn latency_samples(&self) -> f64 {
        let extra = if self.fault == Fault::LatencyOffByHalf {
            0.5
        } else {
            0.0
        };
        self.a_f64 / (1.0 - self.a_f64) + extra
    }
}

impl<S: Sample> Response for OnePole<S> {
    fn response(&self, f_hz: f64) -> Complex64 {
        let a = self.a_f64;
        let h = (1.0 - a) / (1.0 - a * Complex64::cis(-TAU * f_hz / FS_HZ));
        if self.fault == Fault::ConjugateResponse {
            h.conj()
        } else {
            h
        }
    }
}

const FS_HZ: f64 = 48_000.0;
const A: f64 = 0.9;

fn noise(g: &mut Gen) -> f64 {
    g.uniform(-1.0, 1.0)
}

fn run_one_pole(name: &str, fault: Fault) {
    let st = OnePole::<f64>::new(A, fault);
    tick_vs_process(name, &st, noise, same);
    reset_restores(name, &st, noise, same);
    let mut s = st.clone();
    response_matches_impulse(name, FS_HZ, &st, |x| s.tick(x), 1024, 1e-13);
    let mut s = st.clone();
    latency_matches(name, st.latency_samples(), |x| s.tick(x), 1024, 1e-9);
    latency_matches_response(name, st.latency_samples(), FS_HZ, &st, 1e-9);
}

fn run_lanes(fault: Fault) {
    let a = [0.9, 0.5, -0.3, 0.999];
    let v = OnePole::<f64x4>::lanes(a, fault);
    let s: Vec<OnePole<f64>> = a.iter().map(|&a| OnePole::new(a, Fault::None)).collect();
    lanes_match(
        "one-pole",
        &v,
        &s,
        |g| g.sample(-1.0, 1.0),
        |x, l| x.lane(l),
        |y, l| y.lane(l),
        same,
    );
}

#[test]
fn a_correct_one_pole_passes_and_the_measures_are_its_closed_forms() {
    run_one_pole("one-pole", Fault::None);
    run_lanes(Fault::None);
    let st = OnePole::<f64>::new(A, Fault::None);
    let mut s = st.clone();
    let worst = response_matches_impulse("one-pole", FS_HZ, &st, |x| s.tick(x), 512, 1e-13);
    assert!(worst < 1e-14, "{worst:e}");
    let mut s = st.clone();
    // a / (1 - a) = 9 samples for a = 0.9.
    let tau = latency_matches("one-pole", 9.0, |x| s.tick(x), 1024, 1e-9);
    assert!((tau - 9.0).abs() < 1e-12, "{tau}");
    let slope = latency_matches_response("one-pole", 9.0, FS_HZ, &st, 1e-9);
    assert!((slope - 9.0).abs() < 1e-9, "{slope}");
}

#[test]
fn a_pure_delay_has_its_delay_as_latency_and_a_linear_phase() {
    // y[n] = x[n - 2]: H = e^{-2jw}, DC group delay exactly 2, no tail at all.
    let mut line = [0.0; 2];
    let mut delay = |x: f64| {
        let y = line[1];
        line = [x, line[0]];
        y
    };
    let h = FnResponse(|f: f64| Complex64::cis(-2.0 * TAU * f / FS_HZ));
    assert_eq!(latency_matches("delay", 2.0, &mut delay, 16, 0.0), 2.0);
    assert!(response_matches_impulse("delay", FS_HZ, &h, &mut delay, 16, 1e-15) < 1e-15);
    let slope = latency_matches_response("delay", 2.0, FS_HZ, &h, 1e-9);
    assert!((slope - 2.0).abs() < 1e-10, "{slope}");
}

#[test]
#[should_panic(expected = "one-pole: tick_vs_process: sample 1 (block 2: 1 samples from 1)")]
fn a_process_that_restarts_each_block_is_caught() {
    run_one_pole("one-pole", Fault::BlockStartsAtRest);
}

#[test]
#[should_panic(expected = "past the inputs")]
fn a_process_that_writes_past_its_inputs_is_caught() {
    run_one_pole("one-pole", Fault::WritesPastInput);
}

#[test]
#[should_panic(expected = "one-pole: tick_vs_process: sample")]
fn a_process_that_consumes_inputs_past_its_outputs_is_caught() {
    run_one_pole("one-pole", Fault::ConsumesExtraInput);
}

#[test]
#[should_panic(expected = "one-pole: reset_restores: sample 0 after the reset")]
fn a_reset_that_keeps_the_state_is_caught() {
    run_one_pole("one-pole", Fault::ForgetsReset);
}

#[test]
#[should_panic(expected = "one-pole: lanes_match: lane 1 sample 0")]
fn swapped_lanes_are_caught() {
    run_lanes(Fault::SwapsLanes);
}

#[test]
#[should_panic(expected = "one-pole: response_matches_impulse: at f = ")]
fn a_response_with_the_wrong_phase_sign_is_caught() {
    run_one_pole("one-pole", Fault::ConjugateResponse);
}

#[test]
#[should_panic(expected = "one-pole: latency_matches: latency_samples() = 9.5")]
fn a_latency_off_by_half_a_sample_is_caught_by_the_impulse_response() {
    run_one_pole("one-pole", Fault::LatencyOffByHalf);
}

#[test]
#[should_panic(expected = "one-pole: latency_matches_response: latency_samples() = 9.5")]
fn a_latency_off_by_half_a_sample_is_caught_by_the_phase_slope() {
    let st = OnePole::<f64>::new(A, Fault::LatencyOffByHalf);
    latency_matches_response("one-pole", st.latency_samples(), FS_HZ, &st, 1e-9);
}

#[test]
#[should_panic(expected = "has not decayed within n = 64 samples")]
fn a_truncated_impulse_response_is_refused() {
    // a^64 = 0.94 for a = 0.999: far from decayed.
    let st = OnePole::<f64>::new(0.999, Fault::None);
    let mut s = st.clone();
    response_matches_impulse("one-pole", FS_HZ, &st, |x| s.tick(x), 64, 1e-12);
}

#[test]
#[should_panic(expected = "no DC group delay")]
fn a_path_without_dc_gain_has_no_latency_to_check() {
    let mut prev = 0.0;
    latency_matches(
        "difference",
        0.5,
        |x| {
            let y = x - prev;
            prev = x;
            y
        },
        16,
        1e-9,
    );
}

#[test]
fn bits_tell_apart_signed_zeros_options_and_lanes() {
    assert_ne!(0.0f64.words(), (-0.0f64).words());
    assert_ne!(Some(0.0f64).words(), None::<f64>.words());
    assert_eq!(Some(1.5f64).words(), vec![1, 1.5f64.to_bits()]);
    let v = f64x4::from([1.0, 2.0, 3.0, 4.0]);
    assert_eq!(v.words(), [1.0f64, 2.0, 3.0, 4.0].words());
    assert_eq!(
        (Complex64::new(1.0, -2.0), [3.0f64]).words(),
        vec![1f64.to_bits(), (-2f64).to_bits(), 3f64.to_bits()]
    );
}

#[test]
fn the_generator_is_seeded_and_in_range() {
    let (mut a, mut b) = (Gen::new(7), Gen::new(7));
    for _ in 0..10_000 {
        let x = a.uniform(-2.0, 3.0);
        assert_eq!(x.to_bits(), b.uniform(-2.0, 3.0).to_bits());
        assert!((-2.0..3.0).contains(&x));
        let p = a.phasor();
        b.phasor();
        assert!((p.norm() - 1.0).abs() < 1e-15);
    }
    let v: f64x4 = a.sample(0.0, 1.0);
    assert!(v.to_array().windows(2).all(|w| w[0] != w[1]));
    assert_ne!(Gen::new(8).u64(), Gen::new(7).u64());
}
