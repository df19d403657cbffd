//! A closed loop built from the real stages: one mode of the resonator driven by the carrier
//! NCO, the TIA, the stage-1 mixer and a low-pass on I and Q, and the PLL steering the NCO once
//! per decimation block, as the board will.

// Each test file uses its own part of this module.
#![allow(dead_code)]

pub mod models;

use gyroemu_core::{Complex64, Response, Stage};
use gyroemu_lpf::{LowPass, LowPassDesign};
use gyroemu_mixer::Stage1Mixer;
use gyroemu_nco::{Nco, RotatingNco};
use gyroemu_pll::{Agc, Pll, PllParams};
use gyroemu_resonator::{Resonator, ResonatorParams};
use gyroemu_tia::{Tia, TiaParams};

/// The drive amplitude (force per unit mass, m/s^2).
pub const FORCE: f64 = 1.0;

/// How the loop is built.
#[derive(Clone, Copy, Debug)]
pub struct Setup {
    pub f0_hz: f64,
    pub q: f64,
    /// Samples per second of the chain (16 f0).
    pub fs_hz: f64,
    /// Decimation: the PLL runs at fs / m.
    pub m: usize,
    pub lpf_order: usize,
    pub lpf_cutoff_hz: f64,
    pub natural_hz: f64,
    pub damping: f64,
}

impl Setup {
    pub fn new(f0_hz: f64, q: f64, natural_hz: f64, damping: f64) -> Self {
        Self {
            f0_hz,
            q,
            fs_hz: 16.0 * f0_hz,
            m: 16,
            lpf_order: 4,
            lpf_cutoff_hz: 0.2 * f0_hz,
            natural_hz,
            damping,
        }
    }

    pub fn update_rate_hz(&self) -> f64 {
        self.fs_hz / self.m as f64
    }

    pub fn tau_s(&self) -> f64 {
        PllParams::tau_s_of(self.f0_hz, self.q)
    }

    /// The resonance half-bandwidth `f0 / (2 Q)`, Hz.
    pub fn half_bandwidth_hz(&self) -> f64 {
        self.f0_hz / (2.0 * self.q)
    }

    pub fn plant(&self, f0_hz: f64) -> Resonator<f64> {
        let p = ResonatorParams::matched(f0_hz, self.q, 1.0, self.fs_hz);
        Resonator::new(&p, 0.0).unwrap()
    }

    pub fn tia(&self) -> Tia<f64> {
        Tia::new(&TiaParams {
            gain_ohm: 1e5,
            pole_hz: Some(4.0 * self.f0_hz),
            inverting: true,
            rail_v: None,
            fs_hz: self.fs_hz,
        })
        .unwrap()
    }

    pub fn lowpass(&self) -> LowPass<f64> {
        let d = LowPassDesign::Butterworth {
            order: self.lpf_order,
            cutoff_hz: self.lpf_cutoff_hz,
        };
        LowPass::new(d, self.fs_hz).unwrap()
    }

    /// The chain's phase at the resonance, as the board would supply it: the plant's sampled
    /// steady state at f0 (the DAC hold included) times the TIA's response (its inversion and
    /// pole); the low-pass has a real unit gain at DC.
    pub fn phase_offset_rad(&self) -> f64 {
        self.z_at_resonance().arg()
    }

    /// The demodulated output at steady state on the resonance, unit gain: the plant's
    /// sampled steady-state velocity times the TIA's response (the low-pass's DC gain is 1).
    pub fn z_at_resonance(&self) -> Complex64 {
        let v = self.plant(self.f0_hz).held_steady_state(
            self.f0_hz,
            [Complex64::new(FORCE, 0.0), Complex64::new(0.0, 0.0)],
        )[2];
        v * self.tia().response(self.f0_hz)
    }

    /// The PLL for this chain with its nominal carrier at `carrier_hz`.
    pub fn pll_params(&self, carrier_hz: f64) -> PllParams {
        let mut p = PllParams::new(
            carrier_hz,
            self.update_rate_hz(),
            self.natural_hz,
            self.damping,
            self.tau_s(),
        );
        p.phase_offset_rad = self.phase_offset_rad();
        p.lowpass_delay_s = self.lowpass().latency_samples() / self.fs_hz;
        p
    }
}

/// The running loop.
pub struct Loop {
    pub plant: Resonator<f64>,
    tia: Tia<f64>,
    nco: RotatingNco<f64>,
    mixer: Stage1Mixer<f64>,
    lpf: [LowPass<f64>; 2],
    pub pll: Pll,
    m: usize,
    /// Whether the PLL steers the NCO (false: open loop, the carrier stays put).
    pub closed: bool,
    /// Feeds the PLL `conj z` instead of `z`: the detector's sign flipped (a wrong loop).
    pub mirrored: bool,
    /// The drive-amplitude loop, when there is one: it sets `gain` once per block.
    pub agc: Option<Agc>,
    /// The factor on the drive amplitude.
    pub gain: f64,
}

impl Loop {
    /// The loop with the carrier NCO at the PLL's nominal carrier and the plant at rest.
    pub fn new(setup: &Setup, pll: &PllParams) -> Self {
        let nco = Nco::new(pll.carrier_hz, setup.fs_hz, 0.0).unwrap();
        Self {
            plant: setup.plant(setup.f0_hz),
            tia: setup.tia(),
            nco: RotatingNco::new(&[nco]),
            mixer: Stage1Mixer::new(0.0).unwrap(),
            lpf: [setup.lowpass(), setup.lowpass()],
            pll: Pll::new(pll).unwrap(),
            m: setup.m,
            closed: true,
            mirrored: false,
            agc: None,
            gain: 1.0,
        }
    }

    /// Puts the plant in its steady state for the carrier at `f_hz` from phase 0 (the NCO's
    /// start phase), so a run can start settled.
    pub fn settle_plant(&mut self, f_hz: f64) {
        let x = self
            .plant
            .held_steady_state(f_hz, [Complex64::new(FORCE, 0.0), Complex64::new(0.0, 0.0)]);
        self.plant.set_state(x.map(|v| v.re));
    }

    /// Steps the resonance to `f0_hz`, keeping the plant's state (displacement and velocity
    /// are continuous through a sudden change of stiffness).
    pub fn step_resonance(&mut self, setup: &Setup, f0_hz: f64) {
        let state = self.plant.state();
        self.plant = setup.plant(f0_hz);
        self.plant.set_state(state);
    }

    /// One decimation block: `m` samples through the chain, then the PLL on the last
    /// low-pass output, whose frequency the NCO takes from the next sample on. Returns the
    /// frequency the PLL commanded and the `z` it saw.
    pub fn block(&mut self) -> (f64, Complex64) {
        let mut z = Complex64::new(0.0, 0.0);
        for _ in 0..self.m {
            let (c, s) = self.nco.tick(());
            let out = self.plant.tick([FORCE * self.gain * c, 0.0]);
            let y = self.tia.tick(out.current[0]);
            let iq = self.mixer.tick((y, Complex64::new(c, s)));
            z = Complex64::new(self.lpf[0].tick(iq.i), self.lpf[1].tick(iq.q));
        }
        let f = self.pll.tick(if self.mirrored { z.conj() } else { z });
        if self.closed {
            self.nco.set_frequency_hz(0, f).unwrap();
        }
        if let Some(agc) = &mut self.agc {
            self.gain = agc.tick(z);
        }
        (f, z)
    }
}
