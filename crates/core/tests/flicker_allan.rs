//! The Allan deviation of the flicker source against the analytic one: flat at
//! `sqrt(2 ln 2 h)` for `S(f) = h / f` (IEEE Std 952), both for the design (the exact Allan
//! variance of its exact density) and for a generated record (within the statistical spread
//! of an overlapping Allan deviation of flicker noise).

mod flicker_common;

use flicker_common::{exact_avar, overlapping_avar, Gauss};
use gyroemu_core::flicker::{flicker_adev, Flicker, FlickerDesign, FlickerParams};
use gyroemu_core::{f64x4, Stage};

/// fs = 1 Hz, 1/f from 1e-5 Hz to Nyquist: the Allan deviation is flat (to 1 %) from
/// m = 8 to m = 2048 samples (1/tau from 0.125 fs down to 49 f_lo).
fn params() -> FlickerParams {
    FlickerParams {
        fs_hz: 1.0,
        psd_at_1hz: 3.0e-6,
        f_lo_hz: 1e-5,
        f_hi_hz: 0.5,
    }
}

const MS: [usize; 9] = [8, 16, 32, 64, 128, 256, 512, 1024, 2048];

#[test]
fn exact_allan_deviation_of_the_design_is_the_flicker_floor() {
    // The quadrature, checked on white noise first: S = 2 s^2 / fs gives s^2 / m exactly.
    for m in [1usize, 7, 64, 2048] {
        let v = exact_avar(1.0, m, |_| 2.0);
        assert!((v * m as f64 - 1.0).abs() < 1e-9, "white m = {m}: {v}");
    }
    let p = params();
    let d = FlickerDesign::new(&p).unwrap();
    let ideal = flicker_adev(p.psd_at_1hz);
    for m in MS {
        let adev = exact_avar(p.fs_hz, m, |f| d.psd(f)).sqrt();
        eprintln!(
            "m = {m:5}: exact ADEV / sqrt(2 ln2 h) = {:.5}",
            adev / ideal
        );
        // The band ends show at the ends of the range: at m = 8 the high corner (the density
        // 2 dB above S1/f at fs/2, +0.8 %), at m = 2048 the plateau below f_lo (-0.2 %).
        assert!(
            (adev / ideal - 1.0).abs() < 0.01,
            "m = {m}: {adev} vs {ideal}"
        );
    }
}

#[test]
fn generated_allan_deviation_is_flat_at_the_flicker_floor() {
    let p = params();
    let mut g = Gauss::new([101, 202, 303, 404]);
    let mut f = Flicker::<f64x4>::stationary(&p, || g.next()).unwrap();
    let n = 1usize << 21;
    let mut lanes: [Vec<f64>; 4] = core::array::from_fn(|_| Vec::with_capacity(n));
    for _ in 0..n {
        let y = f.tick(g.next()).to_array();
        for (l, v) in lanes.iter_mut().zip(y) {
            l.push(v);
        }
    }
    let d = f.design().clone();
    let ideal = flicker_adev(p.psd_at_1hz);
    let nf = n as f64;
    for m in MS {
        let avar = lanes.iter().map(|y| overlapping_avar(y, m)).sum::<f64>() / 4.0;
        let adev = avar.sqrt();
        let exact = exact_avar(p.fs_hz, m, |f| d.psd(f)).sqrt();
        // Equivalent degrees of freedom of an overlapping Allan variance of flicker noise
        // (NIST SP 1065, Table 5, alpha = -1): 5 N^2 / (4 m (N + 3 m)), times 4 records;
        // the relative standard error of the deviation is 1 / sqrt(2 edf).
        let edf = 4.0 * 5.0 * nf * nf / (4.0 * m as f64 * (nf + 3.0 * m as f64));
        let se = 1.0 / (2.0 * edf).sqrt();
        eprintln!(
            "m = {m:5}: ADEV / exact = {:.4} ({:+.1} se), / sqrt(2 ln2 h) = {:.4}",
            adev / exact,
            (adev / exact - 1.0) / se,
            adev / ideal
        );
        assert!(
            (adev / exact - 1.0).abs() < 5.0 * se,
            "m = {m}: ADEV {adev}, exact {exact}, 5 se = {}",
            5.0 * se
        );
        // And so against the ideal floor: the design's 1 % plus the statistics.
        assert!((adev / ideal - 1.0).abs() < 0.01 + 5.0 * se, "m = {m}");
    }
}
