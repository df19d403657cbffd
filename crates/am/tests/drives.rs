//! The two drive patterns driven by the NCO, against the closed forms of THEORY sections 3
//! and 4, in time and in frequency.

use gyroemu_am::{AmInput, AmModulator, DrivePattern};
use gyroemu_core::Stage;
use gyroemu_nco::{Nco, PhaseShifter};
use num_complex::Complex64;
use rustfft::FftPlanner;
use std::f64::consts::TAU;

const N: usize = 1 << 16;
const FS_HZ: f64 = 1e6;
/// Carrier and modulation on exact bins: f = k fs / N.
const K0: usize = 983; // 14 999.1 Hz
/// 122.1 Hz; even, so the drive is not N/2-periodic and the carrier bin is a real
/// measurement (with k0 and KM both odd every odd bin is exactly zero by symmetry).
const KM: usize = 8;

/// `(sin, cos)` of `2 pi k n / N` with the phase reduced exactly in integers first.
fn sin_cos_bin(k: usize, n: usize) -> (f64, f64) {
    let a = TAU * ((k * n) % N) as f64 / N as f64;
    (a.sin(), a.cos())
}

/// Runs the modulator fed by a carrier NCO (+ the board's quadrature shifter) and a
/// modulation NCO, returning `[f1, f2]` per sample.
/// `alpha_rad`, `beta_rad`: start phases of the carrier and the modulation.
fn run(pattern: DrivePattern, g1: f64, g2: f64, alpha_rad: f64, beta_rad: f64) -> Vec<[f64; 2]> {
    let mut carrier = Nco::new(K0 as f64 * FS_HZ / N as f64, FS_HZ, alpha_rad).unwrap();
    let mut modul = Nco::new(KM as f64 * FS_HZ / N as f64, FS_HZ, beta_rad).unwrap();
    let shifter = PhaseShifter::quadrature();
    let mut am = AmModulator::<f64>::new(pattern, g1, g2).unwrap();
    (0..N)
        .map(|_| {
            let c = carrier.tick(());
            let m = modul.tick(());
            am.tick(AmInput {
                carrier_i: c.re,
                carrier_q: shifter.apply(c).re,
                mod_cos: m.re,
                mod_sin: m.im,
            })
        })
        .collect()
}

#[test]
fn coriolis_pair_is_cos_and_sin() {
    let (f1, f2) = (1.7, 0.6);
    let y = run(DrivePattern::Coriolis, f1, f2, 0.0, 0.0);
    for (n, v) in y.iter().enumerate() {
        let (s, c) = sin_cos_bin(K0, n);
        assert!((v[0] - f1 * c).abs() < 1e-15 * f1, "n = {n}");
        assert!((v[1] - f2 * s).abs() < 1e-15 * f2, "n = {n}");
    }
}

#[test]
fn rotating_pair_matches_eq_4() {
    let f0 = 2.5;
    let y = run(DrivePattern::Rotating, f0, f0, 0.0, 0.0);
    for (n, v) in y.iter().enumerate() {
        let (_, cw) = sin_cos_bin(K0, n);
        let (so, co) = sin_cos_bin(KM, n);
        assert!((v[0] - f0 * co * cw).abs() < 2e-15 * f0, "n = {n}");
        assert!((v[1] - f0 * so * cw).abs() < 2e-15 * f0, "n = {n}");
    }
}

fn spectrum(x: impl Iterator<Item = f64>) -> Vec<Complex64> {
    let mut v: Vec<Complex64> = x.map(|r| Complex64::new(r / N as f64, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(N).process(&mut v);
    v
}

/// Eq. 4 in frequency, with start phases a (carrier) and b (modulation):
/// `F0 cos(Wt+b) cos(w0t+a) = F0/2 [cos((w0+W)t+a+b) + cos((w0-W)t+a-b)]` and
/// `F0 sin(Wt+b) cos(w0t+a) = F0/2 [sin((w0+W)t+a+b) - sin((w0-W)t+a-b)]`. In the two-sided
/// spectrum `X[k]/N` a real cosine of amplitude A and phase p puts `A/2 e^{jp}` at +k, so
/// each sideband bin holds F0/4: mode 1 `F0/4 e^{j(a+b)}` and `F0/4 e^{j(a-b)}`, mode 2
/// `-j F0/4 e^{j(a+b)}` and `+j F0/4 e^{j(a-b)}` (the one-sided amplitude of each sideband
/// is F0/2). Nothing else, not even at the carrier.
#[test]
fn rotating_spectrum_is_two_sidebands() {
    let (g1, g2) = (2.5, 2.0); // a drive gain mismatch is just a different F0 per mode
    let (a, b) = (0.3, 1.1);
    let y = run(DrivePattern::Rotating, g1, g2, a, b);
    let x1 = spectrum(y.iter().map(|v| v[0]));
    let x2 = spectrum(y.iter().map(|v| v[1]));
    let up = K0 + KM;
    let lo = K0 - KM;
    let q = |f0: f64| f0 / 4.0;
    let (ps, pd) = (
        Complex64::from_polar(1.0, a + b),
        Complex64::from_polar(1.0, a - b),
    );
    let j = Complex64::new(0.0, 1.0);
    let expect1 = [(up, ps * q(g1)), (lo, pd * q(g1))];
    let expect2 = [(up, -j * ps * q(g2)), (lo, j * pd * q(g2))];
    for (x, expect, g) in [(&x1, expect1, g1), (&x2, expect2, g2)] {
        let mut rest = x.clone();
        for (k, want) in expect {
            assert!(
                (x[k] - want).norm() < 1e-14 * g,
                "bin {k}: {} vs {want}",
                x[k]
            );
            assert!((x[N - k] - want.conj()).norm() < 1e-14 * g); // real signal mirror
            rest[k] = Complex64::new(0.0, 0.0);
            rest[N - k] = Complex64::new(0.0, 0.0);
        }
        let worst = rest.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let carrier = x[K0].norm().max(x[N - K0].norm());
        let db = |v: f64| 20.0 * (v / q(g)).log10();
        println!(
            "carrier leakage {:.1} dB, worst other bin {:.1} dB (re F0/4)",
            db(carrier),
            db(worst)
        );
        assert!(db(carrier) < -200.0 && db(worst) < -200.0);
    }
}
