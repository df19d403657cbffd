//! The stage contract (gyroemu_core::check) for the low-pass family: block processing, reset
//! and f64x4 lanes bit for bit; the bank's channels against one filter each; every response
//! against the DFT of the impulse response; every latency against the impulse response's DC
//! group delay and the response's phase slope. The decimator is checked at every input
//! instant through [`EveryInstant`]; the averager (no `Stage` of its own) through [`Running`].

use gyroemu_core::check::{self, Gen};
use gyroemu_core::{f64x4, Sample, Stage};
use gyroemu_lpf::{Averager, DecimateMode, Decimator, LowPass, LowPassBank, LowPassDesign, Window};

fn bw(order: usize, cutoff_hz: f64) -> LowPassDesign {
    LowPassDesign::Butterworth { order, cutoff_hz }
}

fn lock_in(order: usize, tau_s: f64) -> LowPassDesign {
    LowPassDesign::LockIn { order, tau_s }
}

/// Every order of both kinds, with cutoffs a few hundred samples long at `fs_hz`.
fn designs(fc_over_fs: f64, fs_hz: f64) -> Vec<LowPassDesign> {
    let mut d: Vec<LowPassDesign> = (1..=8).map(|o| bw(o, fc_over_fs * fs_hz)).collect();
    d.extend((1..=8).map(|o| lock_in(o, 0.2 / (fc_over_fs * fs_hz))));
    d
}

fn noise<S: Sample>(g: &mut Gen) -> S {
    g.sample(-1.0, 1.0)
}

fn lane(x: &f64x4, l: usize) -> f64 {
    x.lane(l)
}

#[test]
fn lowpass_blocks_reset_and_lanes_are_bit_exact() {
    for d in designs(0.017, 1e5) {
        let lp = LowPass::<f64>::new(d, 1e5).unwrap();
        let v = LowPass::<f64x4>::new(d, 1e5).unwrap();
        let name = format!("lpf {d:?}");
        check::tick_vs_process(&name, &lp, noise, check::same);
        check::reset_restores(&name, &lp, noise, check::same);
        check::tick_vs_process(&name, &v, noise, check::same);
        let scalars = [lp.clone(), lp.clone(), lp.clone(), lp];
        check::lanes_match(&name, &v, &scalars, noise, lane, lane, check::same);
    }
}

#[test]
fn a_lane_of_the_bank_reset_mid_run_starts_as_a_fresh_bank() {
    // Every channel of the lane back to rest (a board's lane refilled with another point);
    // the other lanes keep their bits.
    let fs = 1000.0;
    for d in designs(0.05, fs) {
        let lp = LowPass::new(d, fs).unwrap();
        check::lane_replaced_matches(
            &format!("lpf bank {d:?}"),
            &LowPassBank::<f64x4, 4>::new(&LowPass::new(d, fs).unwrap()),
            (1, 4, 777),
            LowPassBank::reset_lane,
            &LowPassBank::<f64, 4>::new(&lp),
            |g| core::array::from_fn(|_| noise::<f64x4>(g)),
            |x: &[f64x4; 4], l| x.map(|c| c.lane(l)),
            |y: &[f64x4; 4], l| y.map(|c| c.lane(l)),
            check::same,
        );
    }
}

#[test]
fn lowpass_response_and_latency_match_the_impulse_response() {
    // 8192 samples: the slowest of these decays below 1e-12 well within; the harness checks.
    let fs = 1000.0;
    let mut all = designs(0.05, fs);
    all.extend((1..=8).map(|o| bw(o, 400.0)));
    all.extend((1..=8).map(|o| lock_in(o, 0.01)));
    let mut worst: f64 = 0.0;
    for d in all {
        let lp = LowPass::<f64>::new(d, fs).unwrap();
        let name = format!("lpf {d:?}");
        let mut s = lp.clone();
        let err = check::response_matches_impulse(&name, fs, &lp, |x| s.tick(x), 8192, 1e-12);
        worst = worst.max(err);
        let mut s = lp.clone();
        check::latency_matches(&name, lp.latency_samples(), |x| s.tick(x), 8192, 1e-9);
        check::latency_matches_response(&name, lp.latency_samples(), fs, &lp, 1e-9);
    }
    eprintln!("lowpass: worst |DFT - H| / peak over 32 designs = {worst:e}");
    // Narrow filters (latency up to 5000 samples): the phase slope, within 1e-9 relative.
    for d in [
        bw(1, 100.0),
        bw(4, 1e3),
        bw(7, 5e3),
        bw(8, 2e5),
        lock_in(5, 1e-3),
    ] {
        let lp = LowPass::<f64>::new(d, 1e6).unwrap();
        let lat = lp.latency_samples();
        check::latency_matches_response(&format!("lpf {d:?}"), lat, 1e6, &lp, 1e-9 * lat);
    }
}

#[test]
fn bank_channels_blocks_reset_response_and_latency() {
    for d in designs(0.017, 1e5) {
        let proto = LowPass::<f64x4>::new(d, 1e5).unwrap();
        let bank = LowPassBank::<f64x4, 3>::new(&proto);
        let name = format!("lpf bank {d:?}");
        let input = |g: &mut Gen| [noise(g), noise(g), noise(g)];
        check::tick_vs_process(&name, &bank, input, check::same);
        check::reset_restores(&name, &bank, input, check::same);
        // Channel c of the bank is a filter of its own, fed channel c.
        check::lanes_match(
            &format!("{name} channels"),
            &bank,
            &[proto.clone(), proto.clone(), proto.clone()],
            input,
            |x, c| x[c],
            |y, c| y[c],
            check::same,
        );
    }
    let fs = 1000.0;
    for d in designs(0.05, fs) {
        let bank = LowPassBank::<f64, 3>::new(&LowPass::new(d, fs).unwrap());
        let name = format!("lpf bank {d:?}");
        let mut s = bank.clone();
        let mut mid = |x: f64| s.tick([0.0, x, 0.0])[1];
        check::response_matches_impulse(&name, fs, &bank, &mut mid, 8192, 1e-12);
        let mut s = bank.clone();
        let lat = bank.latency_samples();
        check::latency_matches(&name, lat, |x| s.tick([0.0, x, 0.0])[1], 8192, 1e-9);
        check::latency_matches_response(&name, lat, fs, &bank, 1e-9);
    }
}

const FS: f64 = 1e5;

fn modes() -> [DecimateMode; 4] {
    let b = bw(5, 2e3);
    [
        DecimateMode::Filter(b),
        DecimateMode::IntegrateDump,
        DecimateMode::FilterThenDump(b),
        DecimateMode::FilterThenDump(lock_in(3, 1e-4)),
    ]
}

#[test]
fn decimator_blocks_reset_and_lanes_are_bit_exact() {
    for mode in modes() {
        for m in [1usize, 7, 64] {
            let d = Decimator::<f64>::new(mode, m, FS).unwrap();
            let v = Decimator::<f64x4>::new(mode, m, FS).unwrap();
            let name = format!("decimator {mode:?} M = {m}");
            check::tick_vs_process(&name, &d, noise, check::same);
            check::reset_restores(&name, &d, noise, check::same);
            check::tick_vs_process(&name, &v, noise, check::same);
            let scalars = [d.clone(), d.clone(), d.clone(), d];
            let out = |y: &Option<f64x4>, l: usize| y.map(|v| v.lane(l));
            check::lanes_match(&name, &v, &scalars, noise, lane, out, check::same);
        }
    }
}

/// A decimator's linear part at every input instant: M clones, clone `k` first fed `k`
/// zeros (which leave a linear stage at rest but shift its block phase), so on each input
/// exactly one clone ends a block, and its output is the undecimated `(h * x)[n]` whose DTFT
/// [`Decimator`]'s `Response` states (time origin at the output instant).
struct EveryInstant(Vec<Decimator<f64>>);

impl EveryInstant {
    fn new(d: &Decimator<f64>) -> Self {
        let clone_at = |k: usize| {
            let mut c = d.clone();
            (0..k).for_each(|_| assert!(c.tick(0.0).is_none()));
            c
        };
        Self((0..d.factor()).map(clone_at).collect())
    }

    fn tick(&mut self, x: f64) -> f64 {
        let mut outs = self.0.iter_mut().filter_map(|c| c.tick(x));
        let y = outs.next().expect("one clone ends a block on every input");
        assert!(outs.next().is_none(), "two clones ended a block together");
        y
    }
}

#[test]
fn decimator_response_and_latency_at_every_input_instant() {
    for mode in modes() {
        for m in [1usize, 7, 64] {
            let d = Decimator::<f64>::new(mode, m, FS).unwrap();
            let name = format!("decimator {mode:?} M = {m}");
            let mut every = EveryInstant::new(&d);
            let err =
                check::response_matches_impulse(&name, FS, &d, |x| every.tick(x), 4096, 1e-12);
            eprintln!("{name}: worst |DFT - H| / peak = {err:e}");
            let mut every = EveryInstant::new(&d);
            let lat = d.latency_samples();
            check::latency_matches(&name, lat, |x| every.tick(x), 4096, 1e-9);
            check::latency_matches_response(&name, lat, FS, &d, 1e-9);
        }
    }
}

/// The averager as a stage: push a sample of two channels, read the running weighted mean of
/// lane 0 (or of every lane, through `lanes_match`). `Averager` has no `Stage` of its own
/// (`push`, `mean`, `reset`), so its reset and lanes are checked through this.
#[derive(Clone, Debug)]
struct Running<S>(Averager<S, 2>);

impl<S: Sample> Stage for Running<S> {
    type Input = S;
    type Output = [f64; 2];

    fn tick(&mut self, x: S) -> [f64; 2] {
        self.0.push(&[x, x * x]);
        self.0.mean(0)
    }

    fn reset(&mut self) {
        self.0.reset();
    }
}

/// The same with every lane's mean (for the lane check).
#[derive(Clone, Debug)]
struct RunningLanes<S>(Averager<S, 2>);

impl<S: Sample> Stage for RunningLanes<S> {
    type Input = S;
    type Output = [[f64; 2]; 4];

    fn tick(&mut self, x: S) -> [[f64; 2]; 4] {
        self.0.push(&[x, x * x]);
        core::array::from_fn(|l| self.0.mean(l.min(S::LANES - 1)))
    }

    fn reset(&mut self) {
        self.0.reset();
    }
}

#[test]
fn averager_reset_and_lanes_are_bit_exact() {
    // Windows shorter than the harness's run: their weights end in zeros, as the board's do.
    let windows = [
        Window::Boxcar { n: 700, frac: 0.25 },
        Window::Hann { n: 900 },
        Window::Boxcar { n: 1500, frac: 0.0 },
        Window::Hann { n: 333 },
    ];
    for w in windows {
        let a = Running(Averager::<f64, 2>::new(&[w], 2).unwrap());
        check::reset_restores(&format!("averager {w:?}"), &a, noise, check::same);
    }
    let v = RunningLanes(Averager::<f64x4, 2>::new(&windows, 2).unwrap());
    check::reset_restores("averager f64x4", &v, noise, check::same);
    let scalars: [RunningLanes<f64>; 4] = core::array::from_fn(|l| {
        RunningLanes(Averager::<f64, 2>::new(&windows[l..=l], 2).unwrap())
    });
    check::lanes_match("averager", &v, &scalars, noise, lane, |y, l| y[l], |y| y[0]);
}
