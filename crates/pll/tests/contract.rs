//! The stage contract (gyroemu_core::check) for the PLL: block processing and reset bit for
//! bit (with and without frequency limits, on inputs whose phase errors run the integrator
//! into the limits and out again), and the loop filter's response against the DFT of its
//! impulse response. The PI has an integrator (infinite DC gain, an impulse response that
//! never decays), so the harness sees it through the first difference of its output:
//! `(1 - z^-1) C(z)`, a two-tap FIR whose response is `(1 - e^{-jwT})` times the stage's.

use gyroemu_core::check::{self, FnResponse, Gen};
use gyroemu_core::{Complex64, Response, Stage};
use gyroemu_pll::{Pll, PllParams};

const UPDATE_HZ: f64 = 1000.0;

fn params(limits: bool) -> PllParams {
    let mut p = PllParams::new(15_000.0, UPDATE_HZ, 2.0, 0.7, 0.5);
    p.phase_offset_rad = -2.4;
    p.lock_updates = 5;
    p.lock_threshold_rad = 0.3;
    if limits {
        p.min_hz = Some(14_999.0);
        p.max_hz = Some(15_000.5);
    }
    p
}

/// Phasors of random phase and amplitude, now and then zero or not finite (no signal), with
/// stretches of small phase errors around the offset so the lock detector switches.
fn input(g: &mut Gen) -> Complex64 {
    let pick = g.unit();
    if pick < 0.02 {
        Complex64::new(0.0, 0.0)
    } else if pick < 0.03 {
        Complex64::new(f64::NAN, 1.0)
    } else if pick < 0.6 {
        Complex64::from_polar(g.uniform(0.5, 2.0), -2.4 + g.uniform(-0.2, 0.2))
    } else {
        g.phasor() * g.uniform(0.01, 3.0)
    }
}

#[test]
fn blocks_and_reset_are_bit_exact() {
    for limits in [false, true] {
        let pll = Pll::new(&params(limits)).unwrap();
        check::tick_vs_process("pll", &pll, input, check::same);
        check::reset_restores("pll", &pll, input, check::same);
    }
}

#[test]
fn differenced_response_matches_the_impulse_response() {
    let pll = Pll::new(&params(false)).unwrap();
    let d = *pll.design();
    let mut s = pll.clone();
    let mut prev = s.frequency_hz();
    // The input phase error x (rad) as the phasor e^{j (offset + x)}: the detector returns x
    // to within an ulp or so.
    let offset = pll.params().phase_offset_rad;
    let adapter = |x: f64| {
        let f = s.tick(Complex64::from_polar(1.0, offset + x));
        let y = f - prev;
        prev = f;
        y
    };
    let differenced = FnResponse(|f_hz: f64| {
        if f_hz == 0.0 {
            // The limit of (1 - e^{-jwT}) (Kp + Ki T / (1 - e^{-jwT})) / 2 pi at DC.
            Complex64::new(d.ki_t_per_s / core::f64::consts::TAU, 0.0)
        } else {
            let w = core::f64::consts::TAU * f_hz / UPDATE_HZ;
            (Complex64::new(1.0, 0.0) - Complex64::from_polar(1.0, -w)) * pll.response(f_hz)
        }
    });
    let worst = check::response_matches_impulse("pll", UPDATE_HZ, &differenced, adapter, 64, 1e-12);
    println!("worst |DFT - H| / peak: {worst:e}");
}
