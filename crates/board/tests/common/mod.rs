//! Boards for the tests, written out as parameters (the M^2-TFG-like board of the presets),
//! and their variants: noise, converters, an imperfect device.
#![allow(dead_code)]

pub mod check;

use gyroemu_board::{BoardParams, Converter, NoiseParams, Point, Shape};
use gyroemu_lpf::{LowPassDesign, Window};
use gyroemu_resonator::{ModeParams, ResonatorParams};
use gyroemu_tia::TiaParams;

/// The M^2-TFG-like board: 15 kHz, Q = 2000, lambda = 1, fs = 240 kHz, TIA pole at 60 kHz,
/// 4th-order 200 Hz low-pass, decimation 100.
pub fn m2tfg(shape: Shape) -> BoardParams {
    let fs = 240_000.0;
    let mode = ModeParams {
        f0_hz: 15_000.0,
        q: 2000.0,
    };
    BoardParams {
        plant: ResonatorParams {
            mode1: mode,
            mode2: mode,
            angular_gain: 1.0,
            quadrature_coupling_rad2_s2: 0.0,
            transduction_a_s_per_m: 1e-6,
            fs_hz: fs,
        },
        carrier_hz: 15_000.0,
        drive: [1.0, 1.0],
        phase_shifter_error_deg: 0.0,
        dac: None,
        tia: TiaParams {
            gain_ohm: 1e6,
            pole_hz: Some(60_000.0),
            inverting: true,
            rail_v: None,
            fs_hz: fs,
        },
        adc: None,
        lowpass: LowPassDesign::Butterworth {
            order: 4,
            cutoff_hz: 200.0,
        },
        decimation: 100,
        noise: None,
        shape,
        table_harmonics: 6,
    }
}

/// `p` with every noise source, a 14-bit ADC and a 16-bit DAC.
pub fn noisy(mut p: BoardParams, seed: u64) -> BoardParams {
    p.noise = Some(NoiseParams {
        seed,
        temperature_k: 300.0,
        effective_mass_kg: Some(1e-9),
        tia_current_noise_a_per_rthz: 1e-13,
        tia_voltage_noise_v_per_rthz: 2e-8,
        tia_voltage_flicker_corner_hz: 0.0,
        drive_amplitude_flicker_per_rthz: 0.0,
        drive_phase_flicker_rad_per_rthz: 0.0,
        carrier_phase_flicker_rad_per_rthz: 0.0,
        flicker_f_lo_hz: 0.0,
    });
    p.adc = Some(Converter {
        bits: 14,
        full_scale: 0.1,
    });
    p.dac = Some(Converter {
        bits: 16,
        full_scale: 1.5,
    });
    p
}

/// `noisy(p, seed)` with every flicker source on (levels far above physical ones, so a
/// mistake in any of them shows).
pub fn flickering(p: BoardParams, seed: u64) -> BoardParams {
    let mut p = noisy(p, seed);
    if let Some(n) = &mut p.noise {
        n.tia_voltage_flicker_corner_hz = 5e4;
        n.drive_amplitude_flicker_per_rthz = 1e-3;
        n.drive_phase_flicker_rad_per_rthz = 2e-3;
        n.carrier_phase_flicker_rad_per_rthz = 3e-3;
        n.flicker_f_lo_hz = 0.01;
    }
    p
}

/// `p` on an imperfect device: mode mismatch, Q mismatch, quadrature coupling, unequal drives
/// and a phase-shifter error.
pub fn imperfect(mut p: BoardParams) -> BoardParams {
    p.plant.mode2.f0_hz += 0.4;
    p.plant.mode2.q *= 0.9;
    p.plant.quadrature_coupling_rad2_s2 = 2e4;
    p.drive = [1.0, 1.01];
    p.phase_shifter_error_deg = 0.3;
    p
}

/// A point of `rate_dps` averaged over `n` decimated samples (boxcar, with a fractional end).
pub fn point(rate_dps: f64, n: u64) -> Point {
    Point {
        rate_rad_s: rate_dps.to_radians(),
        window: Window::Boxcar { n, frac: 0.375 },
    }
}
