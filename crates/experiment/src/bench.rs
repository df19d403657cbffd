//! Throughput measurement of the emulated board: the whole chain (noiseless, with noise, with
//! noise and flicker) in each lane type on one thread and on all threads, the noisy chain's
//! normal generator alone, and each stage alone. Used by `gyroemu bench` and the
//! criterion-free benchmark; timing lives here, never in tests.

use gyroemu_board::{max_lanes, max_lanes_for, GroupBoard, Point, RunOptions};
use gyroemu_config::Config;
use gyroemu_core::gauss::NormalBlock;
use gyroemu_core::noise::NoiseRng;
use gyroemu_core::{f64x4, Sample, Stage};
use gyroemu_lpf::Window;
use rayon::prelude::*;
use std::hint::black_box;
use std::time::Instant;

/// One measured figure, over repeated runs.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Throughput {
    /// What was measured.
    pub name: String,
    /// Threads used.
    pub threads: usize,
    /// Operating-point samples per second, best run (the machine undisturbed).
    pub point_samples_per_s: f64,
    /// The same, median run (what a run on a shared machine typically gets).
    pub median_point_samples_per_s: f64,
}

/// Best and median of `repeats` (at least 1) measurements.
fn best_and_median(repeats: usize, mut measure: impl FnMut() -> f64) -> (f64, f64) {
    let mut v: Vec<f64> = (0..repeats.max(1)).map(|_| measure()).collect();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let median = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    (v[n - 1], median)
}

/// The sample type of a lane group of `width` lanes, as the bench rows name it.
pub fn lane_type(width: usize) -> &'static str {
    if width == 8 {
        "f64x8"
    } else {
        "f64x4"
    }
}

/// `lanes` operating points of `cfg` (its first rates, repeated) for one lane group.
fn lane_rates(cfg: &Config, lanes: usize) -> Vec<f64> {
    (0..lanes)
        .map(|i| cfg.experiment.rates_dps[i % cfg.experiment.rates_dps.len()].to_radians())
        .collect()
}

/// `cfg` with every noise source on (seed 1, 300 K, a 1e-9 kg modal mass, a TIA of 5e-14
/// A/sqrt(Hz) and 2e-8 V/sqrt(Hz)) and a 16-bit DAC and ADC: the chain a self-calibration
/// study with noise runs, measured beside the noiseless one.
pub fn with_noise(cfg: &Config) -> Config {
    let mut c = cfg.clone();
    c.noise = Some(gyroemu_config::NoiseConfig {
        seed: 1,
        temperature_k: 300.0,
        effective_mass_kg: Some(1e-9),
        tia_current_noise_a_per_rthz: 5e-14,
        tia_voltage_noise_v_per_rthz: 2e-8,
        ..Default::default()
    });
    c.board.dac_bits = Some(16);
    c.board.dac_full_scale = 1.5;
    c.board.adc_bits = Some(16);
    c.board.adc_full_scale_v = 0.05;
    c
}

/// [`with_noise`] plus every flicker source at the levels of the `m2tfg-selfcal` preset (read
/// from it; the low corner by the config's rule): the chain a self-calibration study runs.
pub fn with_flicker(cfg: &Config) -> Config {
    let mut c = with_noise(cfg);
    let sc = gyroemu_config::presets::preset("m2tfg-selfcal")
        .expect("the embedded preset parses")
        .noise
        .expect("the selfcal preset has noise");
    if let Some(n) = c.noise.as_mut() {
        n.tia_voltage_flicker_corner_hz = sc.tia_voltage_flicker_corner_hz;
        n.drive_amplitude_flicker_per_rthz = sc.drive_amplitude_flicker_per_rthz;
        n.drive_phase_flicker_rad_per_rthz = sc.drive_phase_flicker_rad_per_rthz;
        n.carrier_phase_flicker_rad_per_rthz = sc.carrier_phase_flicker_rad_per_rthz;
    }
    c
}

/// The chains the bench measures whole, with their rows' labels: `cfg`'s, [`with_noise`] and
/// [`with_flicker`], in the order of the rows (and of `gyroemu bench`'s header).
pub fn chains(cfg: &Config) -> [(&'static str, Config); 3] {
    [
        ("whole chain", cfg.clone()),
        ("whole chain with noise", with_noise(cfg)),
        ("whole chain with noise and flicker", with_flicker(cfg)),
    ]
}

/// Runs `groups` lane groups of `n_in` input samples each, spread over the rayon pool, in the
/// lanes this CPU runs `cfg`'s chain in ([`max_lanes_for`]); returns point-samples per second.
pub fn chain(cfg: &Config, n_in: u64, groups: usize) -> f64 {
    chain_in(max_lanes_for(&cfg.board_params()), cfg, n_in, groups)
}

/// [`chain`] in groups of `width` lanes (4, or 8 on a CPU with AVX-512), every lane in use.
pub fn chain_in(width: usize, cfg: &Config, n_in: u64, groups: usize) -> f64 {
    let rates = lane_rates(cfg, width);
    let params = cfg.board_params();
    let m = cfg.decimation() as u64;
    let n_out = n_in / m;
    let points: Vec<Point> = rates
        .iter()
        .map(|&r| Point {
            rate_rad_s: r,
            window: Window::Boxcar {
                n: n_out / 2,
                frac: 0.0,
            },
        })
        .collect();
    let n_settle = n_out - n_out / 2 - 1;
    let streams: Vec<u64> = (0..width as u64).collect();
    let mut boards: Vec<GroupBoard> = (0..groups)
        .map(|_| {
            GroupBoard::with_width(width, &params, &rates, &streams).expect("bench config is valid")
        })
        .collect();
    let t = Instant::now();
    boards.par_iter_mut().for_each(|b| {
        black_box(
            b.run(n_settle, &points, RunOptions::default(), &|_| {})
                .ok(),
        );
    });
    let s = t.elapsed().as_secs_f64();
    (n_out * m * (width * groups) as u64) as f64 / s
}

/// Times `n` ticks of a copy of `st` fed by `input(i)` on each of `threads` threads; returns
/// point-samples per second over all of them (`lanes` operating points per tick).
fn stage<T: Stage + Clone + Send + Sync>(
    st: &T,
    n: u64,
    lanes: usize,
    threads: usize,
    input: impl Fn(u64) -> T::Input + Sync,
) -> f64 {
    let one = |_| {
        let mut st = st.clone();
        for i in 0..n {
            black_box(st.tick(black_box(input(i))));
        }
    };
    on_threads(threads, n * lanes as u64, one)
}

/// Runs `one(t)` on each of `threads` threads (`t` = 0, 1, ...; on the calling thread alone
/// for one) and returns `items` (point-samples per thread) times `threads` per second.
fn on_threads(threads: usize, items: u64, one: impl Fn(usize) + Sync + Send) -> f64 {
    let t = Instant::now();
    if threads == 1 {
        one(0);
    } else {
        (0..threads).into_par_iter().for_each(one);
    }
    (items as f64 * threads as f64) / t.elapsed().as_secs_f64()
}

/// Draws the normals of `n` input samples of one lane group of `width` lanes (four rows of a
/// [`NormalBlock`] per sample, read as the noisy chain's loop reads them) on each of
/// `threads` threads; returns point-samples per second over all of them. A noisy sample's
/// time is the noiseless chain's, these normals' and the rest of the noise's work (the block
/// refills between runs of the loop, so little of it overlaps): the bound the generator puts
/// on the noisy chain.
fn normals(width: usize, n: u64, threads: usize) -> f64 {
    let one = |t: usize| {
        // Streams of their own per thread, as each lane group has.
        let rng = |seed: u64| NoiseRng::new(core::array::from_fn(|l| seed + l as u64));
        let base = 16 * t as u64;
        let mut block = if width == 8 {
            NormalBlock::wide(rng(base), rng(base + 4))
        } else {
            NormalBlock::new(rng(base))
        };
        let (mut left, mut acc) = (n, 0.0);
        while left > 0 {
            let run = block.ready(left);
            acc += block.row(block.pos(), width)[0];
            block.advance(run);
            left -= run;
        }
        black_box(acc);
    };
    on_threads(threads, n * width as u64, one)
}

/// A plant driven through its decoupled step (what the board runs when the modes are
/// uncoupled), as a stage.
#[derive(Clone)]
struct DecoupledPlant(gyroemu_resonator::Resonator<f64x4>);

impl Stage for DecoupledPlant {
    type Input = [f64x4; 2];
    type Output = gyroemu_resonator::PlantOutput<f64x4>;
    #[inline]
    fn tick(&mut self, force: [f64x4; 2]) -> Self::Output {
        self.0.tick_decoupled(force)
    }
    fn reset(&mut self) {
        self.0.reset();
    }
}

/// Every figure, each the best and the median of `repeats` runs, on 1 thread and on all
/// threads: the chain, noiseless, with noise and with noise and flicker, each in the lanes this
/// CPU runs it in (rows `whole chain`, `whole chain with noise`, `whole chain with noise and
/// flicker`), then in each lane type it can run (the same rows with `(f64x4)` or `(f64x8)`),
/// then the noisy chain's normal generator alone, in that chain's lanes, then each stage.
pub fn all(cfg: &Config, n_in: u64, repeats: usize) -> Vec<Throughput> {
    use gyroemu_am::{AmInput, AmModulator, DrivePattern};
    use gyroemu_lpf::{LowPass, LowPassBank, LowPassDesign};
    use gyroemu_mixer::{Iq, Stage1Mixer, Stage2Mixer};
    use gyroemu_nco::{Nco, PhaseShifter, RotatingNco};
    use gyroemu_resonator::Resonator;
    use gyroemu_tia::Tia;
    let threads = rayon::current_num_threads();
    let row = |name: &str, threads: usize, measure: &mut dyn FnMut() -> f64| {
        let (best, median) = best_and_median(repeats, measure);
        Throughput {
            name: name.into(),
            threads,
            point_samples_per_s: best,
            median_point_samples_per_s: median,
        }
    };
    // The chain in every lane type this CPU runs; the rows without a lane type repeat the
    // figures of the type a run of that chain uses here ([`max_lanes_for`]).
    let chains = chains(cfg);
    let mut widths = vec![4];
    if max_lanes() == 8 {
        widths.push(8);
    }
    let mut typed = Vec::new();
    for &w in &widths {
        for (label, c) in &chains {
            let name = format!("{label} ({})", lane_type(w));
            typed.push(row(&name, 1, &mut || chain_in(w, c, n_in, 1)));
            if threads > 1 {
                typed.push(row(&name, threads, &mut || chain_in(w, c, n_in, threads)));
            }
        }
    }
    let mut out = Vec::new();
    for (label, c) in &chains {
        let name = format!("{label} ({})", lane_type(max_lanes_for(&c.board_params())));
        out.extend(typed.iter().filter(|r| r.name == name).map(|r| Throughput {
            name: (*label).into(),
            ..r.clone()
        }));
    }
    out.extend(typed);
    let mut push_n = |name: &str, threads: usize, measure: &mut dyn FnMut() -> f64| {
        out.push(row(name, threads, measure));
    };
    // The noisy chain's normals alone, in its lanes: with its row, the bound its generator
    // puts on it (docs/performance.md, issue 15's first goal).
    let noisy_width = max_lanes_for(&with_noise(cfg).board_params());
    let name = format!(
        "normal generator (4 per point-sample, {})",
        lane_type(noisy_width)
    );
    push_n(&name, 1, &mut || normals(noisy_width, n_in, 1));
    if threads > 1 {
        push_n(&name, threads, &mut || normals(noisy_width, n_in, threads));
    }
    let x = |i: u64| f64x4::splat((i & 1023) as f64 * 1e-3);
    let fs = cfg.fs_hz();
    let mut push = |name: &str, measure: Box<dyn Fn(usize) -> f64 + '_>| {
        push_n(name, 1, &mut || measure(1));
        if threads > 1 {
            push_n(name, threads, &mut || measure(threads));
        }
    };
    let nco = Nco::new(cfg.device.f0_hz, fs, 0.0).expect("valid");
    let carrier = RotatingNco::<f64>::new(std::slice::from_ref(&nco));
    push(
        "carrier RotatingNco (scalar, 4 lanes share it)",
        Box::new(|t| stage(&carrier, n_in, 4, t, |_| ())),
    );
    let mods: Vec<Nco> = lane_rates(cfg, 4)
        .iter()
        .map(|r| Nco::new(r / std::f64::consts::TAU, fs, 0.0).expect("valid"))
        .collect();
    let modulation = RotatingNco::<f64x4>::new(&mods);
    push(
        "modulation RotatingNco (f64x4)",
        Box::new(|t| stage(&modulation, n_in, 4, t, |_| ())),
    );
    push(
        "table Nco (exact re-sets only)",
        Box::new(|t| stage(&nco, n_in, 4, t, |_| ())),
    );
    let c = |i: u64| gyroemu_core::Complex64::new(x(i).lane(0), 0.5);
    push(
        "phase shifter (scalar)",
        Box::new(|t| stage(&PhaseShifter::quadrature(), n_in, 4, t, c)),
    );
    let am = AmModulator::<f64x4>::new(DrivePattern::Rotating, 1.0, 1.0).expect("valid");
    push(
        "am modulator",
        Box::new(|t| {
            stage(&am, n_in, 4, t, |i| AmInput {
                carrier_i: x(i),
                carrier_q: x(i + 1),
                mod_cos: x(i + 2),
                mod_sin: x(i + 3),
            })
        }),
    );
    let params = cfg.resonator_params();
    let scalar: Vec<Resonator<f64>> = lane_rates(cfg, 4)
        .iter()
        .map(|&r| Resonator::new(&params, r).expect("valid"))
        .collect();
    let plant = Resonator::<f64x4>::from_lanes(&scalar);
    let force = |i: u64| [x(i), x(i + 7)];
    push(
        "resonator (full 4x6 step)",
        Box::new(|t| stage(&plant, n_in, 4, t, force)),
    );
    // Uncoupled modes at rest (a rotating run without k12): the decoupled step.
    let mut uncoupled = params;
    uncoupled.quadrature_coupling_rad2_s2 = 0.0;
    let rest = DecoupledPlant(Resonator::<f64x4>::new(&uncoupled, 0.0).expect("valid"));
    push(
        "resonator (decoupled step)",
        Box::new(|t| stage(&rest, n_in, 4, t, force)),
    );
    let tia = Tia::<f64x4>::new(&cfg.board_params().tia).expect("valid");
    push("tia", Box::new(|t| stage(&tia, n_in, 4, t, x)));
    let mix = Stage1Mixer::<f64x4>::new(0.0).expect("valid");
    let c = gyroemu_core::Complex64::new(0.6, 0.8);
    push(
        "stage-1 mixer",
        Box::new(|t| stage(&mix, n_in, 4, t, |i| (x(i), c))),
    );
    let design = LowPassDesign::Butterworth {
        order: cfg.board.lpf_order,
        cutoff_hz: cfg.lpf_cutoff_hz(),
    };
    let lp = LowPass::<f64x4>::new(design, fs).expect("valid");
    push(
        "low-pass (one channel)",
        Box::new(|t| stage(&lp, n_in, 4, t, x)),
    );
    // What the board runs: I1, Q1, I2, Q2 of each point through one bank.
    let bank = LowPassBank::<f64x4, 4>::new(&lp);
    push(
        "low-pass bank (I1, Q1, I2, Q2)",
        Box::new(|t| stage(&bank, n_in, 4, t, |i| [x(i), x(i + 1), x(i + 2), x(i + 3)])),
    );
    push(
        "stage-2 mixer (per decimated sample)",
        Box::new(|t| {
            stage(&Stage2Mixer::<f64x4>::default(), n_in, 4, t, |i| {
                (Iq::new(x(i), x(i + 1)), [x(i + 2), x(i + 3)])
            })
        }),
    );
    out
}

#[cfg(test)]
mod tests {
    use super::best_and_median;

    #[test]
    fn best_is_the_largest_and_median_the_middle_run() {
        let runs = |v: &[f64]| {
            let mut it = v.iter().copied();
            best_and_median(v.len(), move || it.next().unwrap())
        };
        assert_eq!(runs(&[3.0, 1.0, 2.0]), (3.0, 2.0));
        assert_eq!(runs(&[4.0, 1.0, 2.0, 8.0]), (8.0, 3.0));
        assert_eq!(runs(&[5.0]), (5.0, 5.0));
    }
}
