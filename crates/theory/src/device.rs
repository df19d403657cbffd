//! The exact theory of what each experiment measures, for a device driven as the board drives
//! it, ideal or not: the closed forms for an ideal device, else the continuous-time steady
//! state of the imperfect plant read as THEORY.md section 6 reads it.

use crate::closed_form::{coriolis_theta_rad, rotating_psi_rad};
use gyroemu_core::Complex64;
use gyroemu_mixer::phase_fundamental_fine;
use gyroemu_resonator::{
    continuous_steady_state, held_table_steady_state, rate_table_steady_state, Resonator,
    ResonatorParams,
};

const DEG: f64 = core::f64::consts::PI / 180.0;

/// A device and the drive the board gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrivenDevice {
    /// The plant (its `fs_hz` is not used: the theory is continuous-time).
    pub plant: ResonatorParams,
    /// Drive amplitudes F1, F2.
    pub drive: [f64; 2],
    /// Error of the board's 90-degree phase shifter, degrees.
    pub phase_shifter_error_deg: f64,
    /// Frequency of the drive's carrier, Hz (the resonance of mode 1 unless detuned).
    pub carrier_hz: f64,
}

/// Phase lag of `x` behind the reference `x0`, in (-pi, pi]: `arg(x0 / x)` (the branch of
/// the read-out's own `phase_lag_rad`).
fn lag_rad(x: Complex64, x0: Complex64) -> f64 {
    let a = (x0 * x.conj()).arg();
    if a <= -core::f64::consts::PI {
        core::f64::consts::PI
    } else {
        a
    }
}

impl DrivenDevice {
    /// Matched modes, equal Q, no quadrature coupling, an exact phase shifter and a carrier at
    /// the resonance: the closed forms apply.
    pub fn is_ideal(&self) -> bool {
        let p = &self.plant;
        self.carrier_hz == p.mode1.f0_hz
            && p.mode2.f0_hz == p.mode1.f0_hz
            && p.mode2.q == p.mode1.q
            && p.quadrature_coupling_rad2_s2 == 0.0
            && self.phase_shifter_error_deg == 0.0
    }

    fn f0(&self) -> f64 {
        self.plant.mode1.f0_hz
    }

    /// Coriolis phase shift per mode at the constant rate `omega` (rad/s) against zero rate
    /// (each mode against its own drive): eqs. 2-3, or the steady state of the imperfect plant.
    pub fn coriolis_phase_rad(&self, omega: f64) -> [f64; 2] {
        let p = &self.plant;
        let [f1, f2] = self.drive;
        if self.is_ideal() {
            return coriolis_theta_rad(self.f0(), p.mode1.q, p.angular_gain, f1, f2, omega);
        }
        let force = self.coriolis_force();
        let v = |w: f64| continuous_steady_state(p, w, self.carrier_hz, force);
        let (x0, x) = (v(0.0), v(omega));
        [lag_rad(x[2], x0[2]), lag_rad(x[3], x0[3])]
    }

    /// Rotating-excitation psi per mode at excitation rate `omega` (rad/s): the closed form
    /// for an ideal device; otherwise the major-axis estimator applied to the continuous-time
    /// velocity phasors of the imperfect plant at the two sidebands w0 +- Omega (drive
    /// sidebands F1/2, F1/2 on mode 1 and -j F2/2, +j F2/2 on mode 2), psi_k = (arg(V_k(-)/M-)
    /// - arg(V_k(+)/M+))/2 as in THEORY.md section 6. A phase-shifter error eps makes the
    ///   mode-2 modulation sin(Omega t - eps), which turns its sidebands by e^{-+j eps}.
    pub fn rotating_psi_rad(&self, omega: f64) -> [f64; 2] {
        let p = &self.plant;
        if self.is_ideal() || omega == 0.0 {
            return [rotating_psi_rad(self.f0(), p.mode1.q, omega); 2];
        }
        let fm = omega / core::f64::consts::TAU;
        let j = Complex64::new(0.0, 1.0);
        let v = |sign: f64| {
            continuous_steady_state(
                p,
                0.0,
                self.carrier_hz + sign * fm,
                self.sideband_force(sign),
            )
        };
        let (vp, vm) = (v(1.0), v(-1.0));
        let m = [
            (Complex64::new(1.0, 0.0), Complex64::new(1.0, 0.0)),
            (-j, j),
        ];
        [0, 1].map(|k| {
            let (mp, mm) = m[k];
            0.5 * ((vm[2 + k] / mm).arg() - (vp[2 + k] / mp).arg())
        })
    }

    /// What a board with a zero-order-hold DAC at `self.plant.fs_hz` measures of the Coriolis
    /// phase: the lag, against zero rate, of the sampled velocity's exact steady state under the
    /// held drive (the exactly discretised plant's `held_steady_state`). It departs from
    /// [`DrivenDevice::coriolis_phase_rad`] by the hold's images: negligibly at 16 samples per
    /// carrier period, by whole degrees as fs nears 2 f0. NaN if the plant cannot be built.
    pub fn held_coriolis_phase_rad(&self, omega: f64) -> [f64; 2] {
        let force = self.coriolis_force();
        let v = |w: f64| {
            Resonator::<f64>::new(&self.plant, w)
                .map(|r| r.held_steady_state(self.carrier_hz, force))
                .unwrap_or([Complex64::new(f64::NAN, f64::NAN); 4])
        };
        let (x0, x) = (v(0.0), v(omega));
        [lag_rad(x[2], x0[2]), lag_rad(x[3], x0[3])]
    }

    /// What a board with a zero-order-hold DAC measures of the rotating psi once the read-out
    /// has removed the hold's delay (pi fm / fs, sign of Omega): the sideband estimator on the
    /// held-drive steady states at f0 +- fm.
    pub fn held_rotating_psi_rad(&self, omega: f64) -> [f64; 2] {
        if omega == 0.0 {
            return [0.0; 2];
        }
        let fm = omega / core::f64::consts::TAU;
        let j = Complex64::new(0.0, 1.0);
        let Ok(plant) = Resonator::<f64>::new(&self.plant, 0.0) else {
            return [f64::NAN; 2];
        };
        let v = |sign: f64| {
            plant.held_steady_state(self.carrier_hz + sign * fm, self.sideband_force(sign))
        };
        let (vp, vm) = (v(1.0), v(-1.0));
        let m = [
            (Complex64::new(1.0, 0.0), Complex64::new(1.0, 0.0)),
            (-j, j),
        ];
        let hold = core::f64::consts::PI * fm / self.plant.fs_hz;
        [0, 1].map(|k| {
            let (mp, mm) = m[k];
            0.5 * ((vm[2 + k] / mm).arg() - (vp[2 + k] / mp).arg()) - hold
        })
    }

    /// The force phasors of the Coriolis drives: `F1` on mode 1, `F2` after the phase shifter.
    pub fn coriolis_force(&self) -> [Complex64; 2] {
        let [f1, f2] = self.drive;
        let shift = (90.0 + self.phase_shifter_error_deg) * DEG;
        [Complex64::new(f1, 0.0), Complex64::from_polar(f2, -shift)]
    }

    /// The force phasors of the rotating drive's sideband `sign` (+1 upper, -1 lower):
    /// `F1/2` on mode 1 and `-+j F2/2` on mode 2, turned by the phase shifter's error
    /// (THEORY.md section 4).
    pub fn sideband_force(&self, sign: f64) -> [Complex64; 2] {
        let [f1, f2] = self.drive;
        let turn = Complex64::from_polar(1.0, -sign * self.phase_shifter_error_deg * DEG);
        let j = Complex64::new(0.0, 1.0);
        [Complex64::new(0.5 * f1, 0.0), -j * sign * 0.5 * f2 * turn]
    }

    /// The velocity envelopes of both modes on the rate table `amplitude sin(2 pi table_hz t)`
    /// (rad/s), driven at the carrier: harmonics `-harmonics ..= harmonics` of `V_k(t)` in
    /// `v_k = Re{V_k(t) e^{j w_c t}}`, from the plant's exact periodic steady state (harmonic
    /// balance, THEORY.md section 3).
    pub fn rate_table_envelopes(
        &self,
        amplitude_rad_s: f64,
        table_hz: f64,
        harmonics: usize,
    ) -> [Vec<Complex64>; 2] {
        let x = rate_table_steady_state(
            &self.plant,
            amplitude_rad_s,
            table_hz,
            self.carrier_hz,
            self.coriolis_force(),
            harmonics,
        );
        [0, 1].map(|k| x.iter().map(|xn| xn[2 + k]).collect())
    }

    /// The smallest `N` such that every envelope harmonic beyond `N` is below `rel` of the
    /// largest (both modes), searched up to `max`; `None` when even `max` leaves more.
    pub fn rate_table_harmonics_needed(
        &self,
        amplitude_rad_s: f64,
        table_hz: f64,
        rel: f64,
        max: usize,
    ) -> Option<usize> {
        // The converged balance (a truncated one misjudges a large swing's outer harmonics),
        // with at least eight beyond `max`.
        let env = converged_envelopes(|m| {
            self.rate_table_envelopes(amplitude_rad_s, table_hz, m.max(max + 8))
        })?;
        let n = env[0].len() / 2;
        let peak = env.iter().flatten().map(|v| v.norm()).fold(0.0, f64::max);
        let beyond = |k: usize| {
            env.iter()
                .flat_map(|h| [h[n - k], h[n + k]])
                .map(|v| v.norm())
                .fold(0.0, f64::max)
        };
        (0..=max).find(|&m| (m + 1..=n).all(|k| beyond(k) <= rel * peak))
    }

    /// What a noiseless board with ideal converters reads on the rate table `amplitude sin(2 pi
    /// table_hz t)` (rad/s): [`DrivenDevice::rate_table_response`] of the periodic steady state
    /// of its own recursion (the drive held over each sample at `self.plant.fs_hz`, the step
    /// expanded to second order in the rate: [`held_table_steady_state`]) instead of the
    /// continuous plant's. NaN if the plant cannot be built or the envelope winds.
    pub fn held_rate_table_response(
        &self,
        amplitude_rad_s: f64,
        table_hz: f64,
    ) -> ([f64; 2], [f64; 2]) {
        let nan = ([f64::NAN; 2], [f64::NAN; 2]);
        let Ok(plant) = Resonator::<f64>::new(&self.plant, 0.0) else {
            return nan;
        };
        let env = |n: usize| {
            let x = held_table_steady_state(
                &plant,
                amplitude_rad_s,
                table_hz,
                self.carrier_hz,
                self.coriolis_force(),
                n,
            );
            [0, 1].map(|k| x.iter().map(|xn| xn[2 + k]).collect::<Vec<_>>())
        };
        fundamental_of(env)
    }

    /// The exact phase response of each mode to the rate table `amplitude sin(2 pi table_hz
    /// t)` (rad/s) with the drive at the carrier: the fundamental of the phase lag of the velocity's
    /// periodic steady state (harmonic balance, at any swing), as `(amplitude rad, lag rad)`
    /// per mode, a lag `a sin(w_t t - l)` read as `(a, l)`. NaN when the envelope passes
    /// through 0 (no continuous phase).
    ///
    /// Remembered (the last [`MEMO_LEN`] answers, process-wide): a run asks it of the same
    /// device and table in several rules of its validation and again in its read-out, and each
    /// answer solves the harmonic balance and reads the phase on grids of up to 2^18 points.
    pub fn rate_table_response(&self, amplitude_rad_s: f64, table_hz: f64) -> ([f64; 2], [f64; 2]) {
        // Keyed by the device's `Debug` text, which writes every field, each f64 so that it
        // reads back to the same bits (so -0 and 0 are told apart, as `==` would not).
        let key = (
            format!("{self:?}"),
            amplitude_rad_s.to_bits(),
            table_hz.to_bits(),
        );
        let memo = || RESPONSES.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, found)) = memo().iter().find(|(k, _)| *k == key) {
            return *found;
        }
        let found = self.rate_table_response_solved(amplitude_rad_s, table_hz);
        let mut kept = memo();
        if kept.len() >= MEMO_LEN {
            kept.remove(0);
        }
        kept.push((key, found));
        found
    }

    /// [`DrivenDevice::rate_table_response`], solved (not remembered).
    pub fn rate_table_response_solved(
        &self,
        amplitude_rad_s: f64,
        table_hz: f64,
    ) -> ([f64; 2], [f64; 2]) {
        fundamental_of(|n| self.rate_table_envelopes(amplitude_rad_s, table_hz, n))
    }
}

/// A rate-table response's key (the device's `Debug` text, the amplitude's and the table
/// frequency's bits) and its answer.
type Remembered = ((String, u64, u64), ([f64; 2], [f64; 2]));

/// The answers [`DrivenDevice::rate_table_response`] remembers, oldest first.
static RESPONSES: std::sync::Mutex<Vec<Remembered>> = std::sync::Mutex::new(Vec::new());

/// How many rate-table responses are remembered (a `reproduce` asks those of its 16 rate-table
/// points: 7 rates and 9 bandwidth frequencies, some for two devices).
pub const MEMO_LEN: usize = 64;

/// The most envelope harmonics a rate table's theory takes (a swing of 785 degrees needs
/// about 150); a swing that needs more has no theory here (NaN).
pub const MAX_THEORY_HARMONICS: usize = 384;

/// The envelopes `env(n)` (harmonics `-n ..= n`) with enough harmonics that the outermost two
/// hold no more than f64's resolution of the envelope: 24 for swings up to tens of degrees,
/// doubled as the swing needs, up to [`MAX_THEORY_HARMONICS`]; `None` beyond. Stopping at 48
/// whatever the swing had left a 785-degree swing read as 336 (a truncated balance).
pub fn converged_envelopes(
    env: impl Fn(usize) -> [Vec<Complex64>; 2],
) -> Option<[Vec<Complex64>; 2]> {
    let mut n = 24;
    loop {
        let e = env(n);
        let peak = e.iter().flatten().map(|v| v.norm()).fold(0.0, f64::max);
        let last = e[0].len() - 1;
        if !e
            .iter()
            .any(|h| h[2].norm().max(h[last - 2].norm()) > 1e-17 * peak)
        {
            return Some(e);
        }
        if n >= MAX_THEORY_HARMONICS {
            return None;
        }
        n *= 2;
    }
}

/// Each mode's phase fundamental `(amplitude rad, lag rad)` of the converged envelopes
/// ([`converged_envelopes`]); NaN where they do not converge.
fn fundamental_of(env: impl Fn(usize) -> [Vec<Complex64>; 2]) -> ([f64; 2], [f64; 2]) {
    let Some(e) = converged_envelopes(env) else {
        return ([f64::NAN; 2], [f64::NAN; 2]);
    };
    let x = e.map(|h| phase_fundamental_fine(&h));
    let amp = x.map(|x| x.norm());
    let lag = x.map(|x| -(x * Complex64::new(0.0, 1.0)).arg());
    (amp, lag)
}
