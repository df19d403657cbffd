//! The device draws: device `i` of a lot is its standard scores (one per tolerance, drawn from
//! its own random streams, seeded by `(montecarlo.seed, i)` alone) applied to the config's
//! nominal device.

use gyroemu_config::{Config, Distribution, MonteCarloConfig};
use gyroemu_core::noise::{stream_seed, NoiseRng};

/// The tolerances, in the order of [`DeviceDraw::z`].
pub const PARAMETERS: [&str; 6] = [
    "mode_split",
    "q",
    "q_mismatch",
    "drive_gain",
    "phase_shifter",
    "lambda",
];

/// The draws' streams under a device's seed start here, far from the operating points' noise
/// streams (0.., and the analyses' from 2^32), so a noise seed equal to the lot's seed does not
/// correlate the two.
pub const DRAW_STREAM_BASE: u64 = 1 << 48;

/// One device of the lot, before it is applied to the nominal config.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceDraw {
    /// Index of the device in the lot.
    pub index: u64,
    /// Standard scores (zero mean, unit standard deviation) of the tolerances, in
    /// [`PARAMETERS`] order: normal truncated at `truncate_sigma`, or uniform on +-sqrt(3).
    pub z: [f64; 6],
}

/// Draws device `index` of the lot `mc`: the streams of a [`NoiseRng`] whose four lanes are
/// seeded from `stream_seed(stream_seed(seed, index), DRAW_STREAM_BASE + lane)`; tolerance `k`
/// takes lane `k % 4` of the normal pair's member `k / 4` (exact normals, the ziggurat of
/// `gyroemu_core::gauss`) or of uniform draw `k / 4` (uniform). A normal draw with any score beyond `truncate_sigma` is drawn
/// again whole, which leaves the scores independent, each a normal truncated to the box.
pub fn draw_device(mc: &MonteCarloConfig, index: u64) -> DeviceDraw {
    let dev = stream_seed(mc.seed, index);
    let mut rng = NoiseRng::new(core::array::from_fn(|l| {
        stream_seed(dev, DRAW_STREAM_BASE + l as u64)
    }));
    let pick = |a: [f64; 4], b: [f64; 4]| [a[0], a[1], a[2], a[3], b[0], b[1]];
    // A limit below 1 or NaN (refused by validation) must not loop for long: no truncation.
    let limit = if mc.truncate_sigma >= 1.0 {
        mc.truncate_sigma
    } else {
        f64::INFINITY
    };
    let z = match mc.distribution {
        Distribution::Normal => loop {
            let (a, b) = rng.normal_pair();
            let z = pick(a.to_array(), b.to_array());
            if z.iter().all(|x| x.abs() <= limit) {
                break z;
            }
        },
        Distribution::Uniform => {
            // [-1/2, 1/2) scaled to +-sqrt(3): unit standard deviation.
            let s = 2.0 * 3f64.sqrt();
            let a = rng.uniform_centered().to_array().map(|u| u * s);
            let b = rng.uniform_centered().to_array().map(|u| u * s);
            pick(a, b)
        }
    };
    DeviceDraw { index, z }
}

/// The config of device `draw.index` of the lot of `base` (which must hold `[montecarlo]`):
/// the mode split and the phase-shifter error shifted by their spreads, Q (both modes)
/// scaled by `1 + q_sigma_rel z`, mode 2's Q also by `1 + q_mismatch_sigma_rel z`, F2 by
/// `1 + drive_gain_sigma_rel z`, lambda by `1 + lambda_sigma_rel z`; the noise seed replaced
/// by `stream_seed(noise.seed, index)` (the device's own streams). `[montecarlo]`,
/// `[selfcal]` and `[dump]` are left out: `gyroemu selfcal` on this config self-calibrates
/// the device exactly as the lot does. A spread of zero leaves its key's bits unchanged.
pub fn device_config(base: &Config, draw: &DeviceDraw) -> Config {
    let mut c = Config {
        montecarlo: None,
        selfcal: None,
        dump: None,
        ..base.clone()
    };
    let Some(m) = &base.montecarlo else {
        return c;
    };
    let z = draw.z;
    let scale = |sigma: f64, z: f64| 1.0 + sigma * z;
    let d = &base.device;
    c.device.mode2_f0_offset_hz = d.mode2_f0_offset_hz + m.mode_split_sigma_hz * z[0];
    let q_scale = scale(m.q_sigma_rel, z[1]);
    c.device.q = d.q * q_scale;
    c.device.q_mode2 = match d.q_mode2 {
        // Mode 2 follows mode 1's Q unless it has its own or a mismatch is drawn.
        None if m.q_mismatch_sigma_rel == 0.0 => None,
        q2 => Some(q2.unwrap_or(d.q) * q_scale * scale(m.q_mismatch_sigma_rel, z[2])),
    };
    c.drive.f2 = Some(base.f2() * scale(m.drive_gain_sigma_rel, z[3]));
    c.board.phase_shifter_error_deg =
        base.board.phase_shifter_error_deg + m.phase_shifter_sigma_deg * z[4];
    c.device.angular_gain = d.angular_gain * scale(m.lambda_sigma_rel, z[5]);
    if let Some(n) = &mut c.noise {
        n.seed = stream_seed(n.seed, draw.index);
    }
    c
}
