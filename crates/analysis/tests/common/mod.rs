//! Records shared by the Allan tests: rate noise of known coefficients on four lanes, pooled
//! as selfcal pools them.
#![allow(dead_code)]

use gyroemu_analysis::allan::{overlapping_adev, AllanPoint};
use gyroemu_core::flicker::{psd_at_1hz_from_bias_instability, Flicker, FlickerParams};
use gyroemu_core::noise::NoiseRng;
use gyroemu_core::{f64x4, Stage};

/// Sample period of every record, s.
pub const TAU0: f64 = 0.01;

/// The four lanes' overlapping Allan curves (8 per decade) pooled: variances averaged,
/// independent differences summed.
pub fn pooled(lanes: &[Vec<f64>; 4]) -> Vec<AllanPoint> {
    let curves: Vec<Vec<AllanPoint>> = lanes.iter().map(|y| overlapping_adev(y, TAU0, 8)).collect();
    (0..curves[0].len())
        .map(|j| AllanPoint {
            tau_s: curves[0][j].tau_s,
            adev: (curves.iter().map(|c| c[j].adev.powi(2)).sum::<f64>() / 4.0).sqrt(),
            n_terms: curves.iter().map(|c| c[j].n_terms).sum(),
        })
        .collect()
}

/// Four lanes of `samples` samples of white rate noise (N = `n_coef`, deg/s*sqrt(s)) plus
/// flicker of bias instability `b_dps` (one-sided B^2 / (pi f) from 1e-4 Hz), both through a
/// first-order low-pass of time constant `t_res` (unit DC gain: a resonator's envelope),
/// pooled. Lane l draws stream `seed_base + 4 seed + l`.
pub fn rolled_off_record(
    n_coef: f64,
    b_dps: f64,
    t_res: f64,
    samples: usize,
    seed_base: u64,
    seed: u64,
) -> Vec<AllanPoint> {
    let p = FlickerParams {
        fs_hz: 1.0 / TAU0,
        psd_at_1hz: psd_at_1hz_from_bias_instability(b_dps),
        f_lo_hz: 1e-4,
        f_hi_hz: 0.5 / TAU0,
    };
    let sigma_white = n_coef / TAU0.sqrt();
    let a = (-TAU0 / t_res).exp();
    let mut rng = NoiseRng::new(core::array::from_fn(|l| seed_base + 4 * seed + l as u64));
    let mut fl = Flicker::<f64x4>::stationary(&p, || rng.normal_pair().0).unwrap();
    let mut state = f64x4::splat(0.0);
    let mut lanes: [Vec<f64>; 4] = core::array::from_fn(|_| Vec::with_capacity(samples));
    // Start the low-pass in its stationary regime: run it 50 time constants first.
    let warm = (50.0 * t_res / TAU0) as usize;
    for i in 0..samples + warm {
        let (w, x) = rng.normal_pair();
        let input = fl.tick(w) + x * f64x4::splat(sigma_white);
        state = state * f64x4::splat(a) + input * f64x4::splat(1.0 - a);
        if i >= warm {
            lanes
                .iter_mut()
                .zip(state.to_array())
                .for_each(|(l, v)| l.push(v));
        }
    }
    pooled(&lanes)
}
