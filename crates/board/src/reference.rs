//! The board written plainly, as the test oracle of the fused kernel (what a naive DFT is to an
//! FFT): one operating point in `f64`, every stage called through its own `Stage::tick` on
//! every sample, in chain order, with none of the kernel's shortcuts (no shared carrier
//! factors, no decoupled plant step, no low-pass bank, no skipped shifter). Each shortcut is
//! exact, so the fused board must give every lane these bits.

use crate::board::{
    drive_shifter, modulation_hz, noise_sigmas, pattern, plant_rate, table_harmonics, table_nco,
};
use crate::flicker::FlickerSources;
use crate::health::Health;
use crate::kernel::table_harmonics_of;
use crate::params::{build_adc, build_dac, build_tia, BoardParams, Shape};
use crate::point::{LaneResult, Point};
use gyroemu_am::{AmInput, AmModulator};
use gyroemu_core::noise::{stream_seed, NoiseRng};
use gyroemu_core::{Complex64, ParamResult, Sample, Stage};
use gyroemu_lpf::{Averager, DecimateMode, Decimator};
use gyroemu_mixer::{table_reference, Iq, Stage1Mixer, Stage2Mixer, TableMixer, TABLE_CHANNELS};
use gyroemu_nco::{Nco, RotatingNco};
use gyroemu_resonator::Resonator;

/// Runs one operating point (`rate_rad_s`, noise stream `stream`) for `n_settle` decimated
/// samples of settling and then `point`'s averaging window; returns its averages.
pub fn run_reference(
    p: &BoardParams,
    rate_rad_s: f64,
    stream: u64,
    n_settle: u64,
    point: &Point,
) -> ParamResult<LaneResult> {
    p.validate()?;
    let fs = p.fs_hz();
    let m = p.decimation;
    let mut carrier = RotatingNco::<f64>::new(&[Nco::new(p.carrier_hz, fs, 0.0)?]);
    let mut shift = drive_shifter(p)?;
    let mut modulation =
        RotatingNco::<f64>::new(&[Nco::new(modulation_hz(p.shape, rate_rad_s), fs, 0.0)?]);
    let table = table_nco(p)?;
    let table_f_hz = table.f_hz();
    let mut table = RotatingNco::<f64>::new(&[table]);
    let mut am = AmModulator::<f64>::new(pattern(p.shape), p.drive[0], p.drive[1])?;
    let mut dac = [build_dac::<f64>(p)?, build_dac::<f64>(p)?];
    let mut plant = Resonator::<f64>::new(&p.plant, plant_rate(p.shape, rate_rad_s))?;
    let mut tia = [build_tia::<f64>(p)?, build_tia::<f64>(p)?];
    let mut adc = build_adc::<f64>(p)?.map(|q| [q, q]);
    let mut mix1 = [Stage1Mixer::<f64>::new(0.0)?, Stage1Mixer::<f64>::new(0.0)?];
    let design = DecimateMode::Filter(p.lowpass);
    let mut dec: [Decimator<f64>; 4] = [
        Decimator::new(design, m, fs)?,
        Decimator::new(design, m, fs)?,
        Decimator::new(design, m, fs)?,
        Decimator::new(design, m, fs)?,
    ];
    let mut mix2 = Stage2Mixer::<f64>::new();
    let mut table_mix = TableMixer::<f64>::new(table_harmonics(p))?;
    let mut table_avg =
        Averager::<f64, TABLE_CHANNELS>::new(&[point.window], table_mix.channels())?;
    let channels = if p.shape.is_rotating() { 8 } else { 4 };
    let mut avg = Averager::<f64, 8>::new(&[point.window], channels)?;
    let seed = p.noise.map_or(0, |n| n.seed);
    let mut rng = NoiseRng::new([stream_seed(seed, stream); 4]);
    let (sigma_force, sigma_current) = noise_sigmas(p);
    let mut flicker = FlickerSources::<f64>::per_sample(p, &[stream])?;
    let eps = p.phase_shifter_error_deg.to_radians();
    let (ce, se) = (eps.cos(), eps.sin());
    let n_out = n_settle + point.window.samples();
    let mut health = Health {
        samples: n_out * m as u64,
        ..Default::default()
    };
    for n in 0..n_out * m as u64 {
        if n % m as u64 == 0 {
            if let Some(f) = &mut flicker {
                f.next_block();
            }
        }
        let (c_re, c_im) = carrier.tick(());
        let cq = shift.tick(Complex64::new(c_re, c_im)).re;
        let (mod_cos, mod_sin) = modulation.tick(());
        let drive_sin = if p.shape.is_rotating() && eps != 0.0 {
            mod_sin * ce - mod_cos * se
        } else {
            mod_sin
        };
        let input = |ci: f64, cq: f64| AmInput {
            carrier_i: ci,
            carrier_q: cq,
            mod_cos,
            mod_sin: drive_sin,
        };
        let drive = match flicker.as_ref().map(|f| f.block) {
            None => am.tick(input(c_re, cq)),
            // Each drive's carrier turned by the carrier's and its own flicker phase, its
            // amplitude scaled.
            Some(b) => {
                let c = Complex64::new(c_re, c_im);
                let turned = |(co, si): (f64, f64)| c * Complex64::new(co, si);
                let (c1, c2) = (turned(b.drive_rot[0]), turned(b.drive_rot[1]));
                let d = if p.shape.is_rotating() {
                    [am.tick(input(c1.re, 0.0))[0], am.tick(input(c2.re, 0.0))[1]]
                } else {
                    am.tick(input(c1.re, shift.tick(c2).re))
                };
                [d[0] * b.amplitude[0], d[1] * b.amplitude[1]]
            }
        };
        let mut u = [dac[0].tick(drive[0]), dac[1].tick(drive[1])];
        for md in 0..2 {
            if let Some(q) = dac[md].quantizer() {
                let (mut clip, mut zero) = (0.0, 0.0);
                q.quantize_counting(drive[md], &mut clip, &mut zero);
                health.dac_clipped[md] += clip as u64;
                health.dac_zero[md] += zero as u64;
            }
        }
        if p.noise.is_some() {
            let (a, b) = rng.normal_pair();
            u[0] = Sample::mul_add(a.to_array()[0], sigma_force[0], u[0]);
            u[1] = Sample::mul_add(b.to_array()[0], sigma_force[1], u[1]);
        }
        let (_, sin_t) = table.tick(());
        let mut out = match p.shape {
            Shape::RateTable { .. } => plant.tick_with_rate(u, rate_rad_s * sin_t),
            _ => plant.tick(u),
        };
        if p.noise.is_some() {
            let (a, b) = rng.normal_pair();
            out.current[0] = Sample::mul_add(a.to_array()[0], sigma_current[0], out.current[0]);
            out.current[1] = Sample::mul_add(b.to_array()[0], sigma_current[1], out.current[1]);
        }
        if let Some(f) = &mut flicker {
            let t = f.tia_current();
            out.current[0] += t[0];
            out.current[1] += t[1];
        }
        let mut y = [tia[0].tick(out.current[0]), tia[1].tick(out.current[1])];
        for md in 0..2 {
            health.tia_railed[md] += tia[md].rail_flags(y[md]) as u64;
        }
        if let Some(q) = &mut adc {
            for md in 0..2 {
                let (mut clip, mut zero) = (0.0, 0.0);
                q[md].quantize_counting(y[md], &mut clip, &mut zero);
                health.adc_clipped[md] += clip as u64;
                health.adc_zero[md] += zero as u64;
            }
            y = [q[0].tick(y[0]), q[1].tick(y[1])];
        }
        let carrier_phasor = match flicker.as_ref().map(|f| f.block.carrier_rot) {
            // The carrier's flicker phase turns the demodulation too.
            Some((co, si)) => Complex64::new(c_re, c_im) * Complex64::new(co, si),
            None => Complex64::new(c_re, c_im),
        };
        let z = [
            mix1[0].tick((y[0], carrier_phasor)),
            mix1[1].tick((y[1], carrier_phasor)),
        ];
        let lp = [z[0].i, z[0].q, z[1].i, z[1].q];
        let decimated: [Option<f64>; 4] = core::array::from_fn(|c| dec[c].tick(lp[c]));
        let [Some(i1), Some(q1), Some(i2), Some(q2)] = decimated else {
            continue;
        };
        let k = n / m as u64;
        let zk = [Complex64::new(i1, q1), Complex64::new(i2, q2)];
        if k < n_settle {
            continue;
        }
        let mut x = [0.0f64; 8];
        match p.shape {
            Shape::Coriolis => {
                x[..4].copy_from_slice(&[i1, q1, i2, q2]);
            }
            Shape::RateTable { .. } => {
                let z = zk.map(|v| Iq::new(v.re, v.im));
                let r = table_reference(n, table_f_hz, fs);
                table_avg.push(&table_mix.tick((z, (r.re, r.im))));
            }
            Shape::Rotating => {
                for (md, zm) in zk.iter().enumerate() {
                    let o = mix2.tick((Iq::new(zm.re, zm.im), [mod_cos, mod_sin]));
                    x[4 * md..4 * md + 4].copy_from_slice(&[o.c.i, o.c.q, o.s.i, o.s.q]);
                }
            }
        }
        avg.push(&x);
    }
    let v = avg.mean(0);
    let ph = |c: usize| Complex64::new(v[c], v[c + 1]);
    let result = match p.shape {
        Shape::Coriolis => LaneResult {
            z: [ph(0), ph(2)],
            ..Default::default()
        },
        Shape::RateTable { .. } => LaneResult {
            table_z: table_harmonics_of(&table_avg.mean(0), table_mix.harmonics()),
            ..Default::default()
        },
        Shape::Rotating => LaneResult {
            c: [ph(0), ph(4)],
            s: [ph(2), ph(6)],
            ..Default::default()
        },
    };
    Ok(LaneResult { health, ..result })
}
