//! The rate-table demodulator and read-out against planted periodic envelopes: the mixer
//! averaged over whole table periods returns each harmonic, and the phase read-out returns the
//! fundamental of a planted phase modulation exactly, at small and large swings.

use core::f64::consts::TAU;
use gyroemu_core::{Complex64, Stage};
use gyroemu_mixer::{
    phase_fundamental, table_channel, table_reference, Iq, TableMixer, MAX_TABLE_HARMONIC,
};
use rustfft::FftPlanner;

/// A periodic envelope with a planted phase lag `a sin(theta - l) + b sin(2 theta)` and an
/// amplitude modulation `1 + m cos(theta)`.
fn envelope(theta: f64, a: f64, l: f64, b: f64, m: f64) -> Complex64 {
    let lag = a * (theta - l).sin() + b * (2.0 * theta).sin();
    Complex64::from_polar(1.0 + m * theta.cos(), -lag)
}

/// Harmonics -N..=N of the envelope from a 256-point FFT (an independent route to them).
fn harmonics(n: usize, f: impl Fn(f64) -> Complex64) -> Vec<Complex64> {
    const P: usize = 256;
    let mut buf: Vec<Complex64> = (0..P).map(|g| f(TAU * g as f64 / P as f64)).collect();
    FftPlanner::new().plan_fft_forward(P).process(&mut buf);
    (-(n as isize)..=n as isize)
        .map(|k| buf[k.rem_euclid(P as isize) as usize] / P as f64)
        .collect()
}

#[test]
fn phase_fundamental_recovers_planted_swings() {
    for (a_deg, l_deg, b, m) in [
        (0.5, 10.0, 0.0, 0.0),
        (14.0, -30.0, 0.01, 0.2),
        (40.0, 75.0, 0.05, -0.3),
    ] {
        let (a, l) = (f64::to_radians(a_deg), f64::to_radians(l_deg));
        let h = harmonics(MAX_TABLE_HARMONIC, |t| envelope(t, a, l, b, m));
        let got = phase_fundamental(&h);
        // The second-harmonic term and the amplitude modulation do not leak into it.
        let want = Complex64::new(0.0, -a) * Complex64::from_polar(1.0, -l);
        assert!(
            (got - want).norm() < 1e-11 * a.max(1e-3),
            "{a_deg}: {got} vs {want}"
        );
        // Any common complex factor (the chain's constant gain and phase) changes nothing.
        let scaled: Vec<_> = h
            .iter()
            .map(|x| x * Complex64::from_polar(3.0, 1.1))
            .collect();
        assert!((phase_fundamental(&scaled) - want).norm() < 1e-11 * a.max(1e-3));
    }
}

#[test]
fn an_envelope_around_zero_has_no_phase() {
    // e^{j theta} winds once around 0: its phase is not periodic.
    let h = harmonics(2, |t| Complex64::from_polar(1.0, t));
    assert!(phase_fundamental(&h).is_nan());
    // Whatever its starting phase and direction, and with a small tone beside it.
    for phi0 in [-3.0, -1.0, 0.5, 2.0, 3.1] {
        for k in [0usize, 2] {
            let mut h = vec![Complex64::new(0.0, 0.0); 3];
            h[k] = Complex64::from_polar(1.0, phi0);
            h[1] = Complex64::new(0.2, 0.1);
            assert!(phase_fundamental(&h).is_nan(), "phi0 {phi0}, harmonic {k}");
        }
    }
}

#[test]
fn whole_period_averages_are_the_harmonics() {
    let (fs, ft, period) = (1000.0, 12.5, 80u64); // 80 samples per table period
    let (a, l) = (0.6, 0.3);
    let f = |t: f64| envelope(t, a, l, 0.02, 0.1);
    let g = |t: f64| envelope(t, 0.2, -0.4, 0.0, 0.0) * Complex64::new(0.0, 2.0);
    let n = 6;
    let mut mix = TableMixer::<f64>::new(n).unwrap();
    let mut acc = [0.0; gyroemu_mixer::TABLE_CHANNELS];
    for k in 0..3 * period {
        let theta = TAU * k as f64 * ft / fs;
        let z = [f(theta), g(theta)].map(|v| Iq::new(v.re, v.im));
        let r = table_reference(k, ft, fs);
        let o = mix.tick((z, (r.re, r.im)));
        for (a, x) in acc.iter_mut().zip(o) {
            *a += x / (3 * period) as f64;
        }
    }
    for (md, want) in [harmonics(n, f), harmonics(n, g)].into_iter().enumerate() {
        for (i, w) in want.iter().enumerate() {
            let ch = table_channel(i as isize - n as isize, md, n);
            let got = Complex64::new(acc[ch], acc[ch + 1]);
            assert!(
                (got - w).norm() < 1e-13,
                "mode {md} harmonic {i}: {got} vs {w}"
            );
        }
    }
    // Channels beyond harmonic n stay zero.
    let ch = table_channel(n as isize + 1, 0, n);
    assert_eq!(&acc[ch..], &vec![0.0; acc.len() - ch][..]);
}

#[test]
fn channels_in_use_are_exactly_those_a_tick_writes() {
    // Each harmonic -N..=N gives I and Q for both modes: 4 (2N + 1) channels, the first ones
    // of the output, and the rest stay 0 (the averager sums only the channels in use).
    let z = [Iq::new(0.3, -0.7), Iq::new(-1.1, 0.4)];
    let b = Complex64::from_polar(1.0, 0.61);
    for n in 0..=MAX_TABLE_HARMONIC {
        let mut mix = TableMixer::<f64>::new(n).unwrap();
        assert_eq!(mix.harmonics(), n);
        let used = mix.channels();
        assert_eq!(used, 4 * (2 * n + 1));
        let out = mix.tick((z, (b.re, b.im)));
        assert!(out[..used].iter().all(|&v| v != 0.0), "harmonics {n}");
        assert!(out[used..].iter().all(|&v| v == 0.0), "harmonics {n}");
    }
}

/// `phase_fundamental` as first written: each grid point's `sin_cos` and Horner on its own.
fn phase_fundamental_one_point_at_a_time(h: &[Complex64]) -> Complex64 {
    const G: usize = 1024;
    let nh = (h.len() / 2) as i32;
    let (mut acc, mut prev, mut unwrapped, mut first) =
        (Complex64::new(0.0, 0.0), f64::NAN, 0.0, 0.0);
    for g in 0..=G {
        let (s, c) = gyroemu_core::detmath::sin_cos_turns(g as f64 / G as f64);
        let base = Complex64::new(c, s);
        let mut v = Complex64::new(0.0, 0.0);
        for x in h.iter().rev() {
            v = v * base + x;
        }
        v *= Complex64::new(c, -s).powi(nh);
        let ph = -v.arg();
        unwrapped = if prev.is_nan() {
            ph
        } else {
            unwrapped + gyroemu_mixer::wrap_pi(ph - prev)
        };
        prev = ph;
        if g == 0 {
            first = unwrapped;
        }
        if g < G {
            acc += unwrapped * Complex64::new(c, -s);
        }
    }
    if (unwrapped - first).abs() > core::f64::consts::PI || !acc.is_finite() {
        return Complex64::new(f64::NAN, f64::NAN);
    }
    acc * (2.0 / G as f64)
}

#[test]
fn phase_fundamental_holds_the_bits_of_one_point_at_a_time() {
    // Every harmonic count a read-out or the theory uses (up to 48), planted swings small and
    // large: the grid points evaluated eight at a time give the same bits.
    for n in [0usize, 1, 3, 6, 11, 24, 48] {
        for (a, l, b, m) in [
            (1e-4, 0.3, 0.0, 0.1),
            (0.7, -1.2, 0.2, 0.5),
            (2.5, 2.0, 0.4, 0.0),
        ] {
            let h = harmonics(n, |t| envelope(t, a, l, b, m));
            let got = phase_fundamental(&h);
            let want = phase_fundamental_one_point_at_a_time(&h);
            assert!(
                got.re.to_bits() == want.re.to_bits() && got.im.to_bits() == want.im.to_bits(),
                "n {n}, swing {a}: {got} vs {want}"
            );
        }
    }
}
