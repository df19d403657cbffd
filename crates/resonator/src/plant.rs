//! The sample-by-sample plant: `x[n+1] = Phi x[n] + Gamma u[n]`, with the step expanded to
//! second order in the rate offset when the rate varies.

use crate::discretise::{zoh_expansion, Block};
use crate::{ResonatorParams, STAGE};
use gyroemu_core::error::finite;
use gyroemu_core::{ParamResult, Sample, Stage};

/// What the plant shows at one sample: the state at `t = n Ts` and the motional currents.
#[derive(Clone, Copy, Debug, Default)]
pub struct PlantOutput<S> {
    /// Displacements `[q1, q2]`, m.
    pub q: [S; 2],
    /// Velocities `[v1, v2]`, m/s.
    pub v: [S; 2],
    /// Motional currents `transduction * v`, A.
    pub current: [S; 2],
}

/// The two-mode gyroscope plant, exactly discretised (zero-order hold on the force).
///
/// Output convention: `tick` returns `y[n]`, the state `x[n]` *before* the update, then sets
/// `x[n+1] = Phi x[n] + Gamma u[n]`. So `y[n]` is the exact sample at `t = n Ts` of the
/// continuous plant driven by the held input, and the force applied at `n` first shows at
/// `n + 1`. [`Stage::reset`] zeroes the state (the plant starts at rest).
#[derive(Clone, Debug)]
pub struct Resonator<S> {
    /// `[Phi | Gamma]` at the design rate.
    e0: [[S; 6]; 4],
    /// First rate derivative of `[Phi | Gamma]`, per rad/s.
    e1: [[S; 6]; 4],
    /// Second-order Taylor coefficient, per (rad/s)^2.
    e2: [[S; 6]; 4],
    omega_c: S,
    transduction: S,
    x: [S; 4],
    /// Parameters of lane 0 (the only lane for `f64`).
    params: ResonatorParams,
    omega_c_f64: f64,
}

fn splat_block<S: Sample>(b: &Block) -> [[S; 6]; 4] {
    b.map(|row| row.map(S::splat))
}

impl<S: Sample> Resonator<S> {
    /// Exact ZOH discretisation at the constant rate `omega_z_rad_s` (the rate expansion used
    /// by [`Resonator::tick_with_rate`] is taken about it too). Every lane gets the same plant.
    pub fn new(params: &ResonatorParams, omega_z_rad_s: f64) -> ParamResult<Self> {
        params.validate()?;
        finite(STAGE, "omega_z_rad_s", omega_z_rad_s)?;
        let [e0, e1, e2] = zoh_expansion(params, omega_z_rad_s);
        Ok(Self {
            e0: splat_block(&e0),
            e1: splat_block(&e1),
            e2: splat_block(&e2),
            omega_c: S::splat(omega_z_rad_s),
            transduction: S::splat(params.transduction_a_s_per_m),
            x: [S::default(); 4],
            params: *params,
            omega_c_f64: omega_z_rad_s,
        })
    }

    /// Lane `lane`'s state back to rest, as [`Stage::reset`] leaves every lane; its
    /// coefficients and the other lanes keep their bits (a lane refilled with another
    /// operating point at the same plant rate).
    pub fn reset_lane(&mut self, lane: usize) {
        for x in &mut self.x {
            *x = x.with_lane(lane, 0.0);
        }
    }

    /// Packs scalar plants into lanes: lane `i` takes coefficients and state of `lanes[i]`
    /// (lanes past the end of the slice repeat its last plant). Panics on an empty slice.
    pub fn from_lanes(lanes: &[Resonator<f64>]) -> Self {
        assert!(!lanes.is_empty(), "from_lanes needs at least one plant");
        let pick = |l: usize| &lanes[l.min(lanes.len() - 1)];
        let block = |f: fn(&Resonator<f64>) -> &[[f64; 6]; 4]| {
            core::array::from_fn(|i| core::array::from_fn(|j| S::from_fn(|l| f(pick(l))[i][j])))
        };
        Self {
            e0: block(|r| &r.e0),
            e1: block(|r| &r.e1),
            e2: block(|r| &r.e2),
            omega_c: S::from_fn(|l| pick(l).omega_c),
            transduction: S::from_fn(|l| pick(l).transduction),
            x: core::array::from_fn(|i| S::from_fn(|l| pick(l).x[i])),
            params: lanes[0].params,
            omega_c_f64: lanes[0].omega_c_f64,
        }
    }

    #[inline(always)]
    fn output(&self) -> PlantOutput<S> {
        let x = self.x;
        PlantOutput {
            q: [x[0], x[1]],
            v: [x[2], x[3]],
            current: [self.transduction * x[2], self.transduction * x[3]],
        }
    }

    #[inline(always)]
    fn row(e: &[S; 6], z: &[S; 6]) -> S {
        // The force terms first (they do not wait for the state), then two independent
        // multiply-add chains over the state, so the recursion through x stays short.
        let f = e[4].mul_add(z[4], e[5] * z[5]);
        let a = e[0].mul_add(z[0], e[1].mul_add(z[1], f));
        let b = e[2].mul_add(z[2], e[3] * z[3]);
        a + b
    }

    /// One step with a time-varying rate (rad/s, per lane): the step matrix is
    /// `E0 + d E1 + d^2 E2`, `d = omega - omega_design`, error `O((d Ts)^3)`. The rate is
    /// taken constant over the step `[n Ts, (n+1) Ts)`; for a continuously varying rate pass
    /// its value at the midpoint `(n + 1/2) Ts`, which makes the step second-order accurate.
    /// At `omega == omega_design` this is bit-identical to [`Stage::tick`].
    #[inline(always)]
    pub fn tick_with_rate(&mut self, force: [S; 2], omega_z_rad_s: S) -> PlantOutput<S> {
        let y = self.output();
        let d = omega_z_rad_s - self.omega_c;
        let x = self.x;
        let z = [x[0], x[1], x[2], x[3], force[0], force[1]];
        for i in 0..4 {
            let a = Self::row(&self.e0[i], &z);
            let b = Self::row(&self.e1[i], &z);
            let c = Self::row(&self.e2[i], &z);
            self.x[i] = a + d * (b + d * c);
        }
        y
    }

    /// Whether the rate expansion splits by mode in every lane: `E0` and `E2` with exact zeros
    /// across the modes, `E1` with exact zeros within them. So it is for a plant without
    /// quadrature coupling expanded about zero rate (an ideal device on a rate table): the
    /// Coriolis term couples the modes, so odd powers of the rate are cross-mode and even ones
    /// within a mode, and the matrix exponential keeps the structural zeros exact. Then
    /// [`Resonator::tick_with_rate_split`] applies.
    pub fn rate_split_by_mode(&self) -> bool {
        let mode = |j: usize| j % 2;
        let zero =
            |b: &[[S; 6]; 4], i: usize, j: usize| (0..S::LANES).all(|l| b[i][j].lane(l) == 0.0);
        (0..4).all(|i| {
            (0..6).all(|j| {
                if mode(j) == mode(i) {
                    zero(&self.e1, i, j)
                } else {
                    zero(&self.e0, i, j) && zero(&self.e2, i, j)
                }
            })
        })
    }

    /// [`Resonator::tick_with_rate`] of a plant that [`Resonator::rate_split_by_mode`]: the same
    /// multiply-adds in the same order with the products by exact zeros left out (nine per row
    /// instead of eighteen), so the result is bit-identical but for the sign of an exact zero.
    #[inline(always)]
    pub fn tick_with_rate_split(&mut self, force: [S; 2], omega_z_rad_s: S) -> PlantOutput<S> {
        debug_assert!(self.rate_split_by_mode());
        let y = self.output();
        let d = omega_z_rad_s - self.omega_c;
        let x = self.x;
        // `row` with only the entries of mode `m` (states m, 2 + m, force 4 + m) non-zero.
        let row = |e: &[S; 6], m: usize| {
            let f = e[4 + m] * force[m];
            let a = e[m].mul_add(x[m], f);
            a + e[2 + m] * x[2 + m]
        };
        for i in 0..4 {
            let m = i % 2;
            let a = row(&self.e0[i], m);
            let b = row(&self.e1[i], 1 - m);
            let c = row(&self.e2[i], m);
            self.x[i] = a + d * (b + d * c);
        }
        y
    }

    /// Whether every cross-mode entry of `[Phi | Gamma]` is exactly zero in every lane (no
    /// Coriolis term and no quadrature coupling): the two modes are then independent
    /// two-state plants and [`Resonator::tick_decoupled`] applies.
    pub fn decoupled(&self) -> bool {
        // Mode 1 is state 0, 2 and force 4; mode 2 is state 1, 3 and force 5.
        let mode = |j: usize| j % 2;
        (0..4).all(|i| {
            (0..6)
                .filter(|&j| mode(j) != mode(i))
                .all(|j| (0..S::LANES).all(|l| self.e0[i][j].lane(l) == 0.0))
        })
    }

    /// [`Stage::tick`] of a [`Resonator::decoupled`] plant: the same multiply-adds in the
    /// same order with the products by exact zeros left out (three per row instead of six),
    /// so the result is bit-identical but for the sign of an exact zero.
    #[inline(always)]
    pub fn tick_decoupled(&mut self, force: [S; 2]) -> PlantOutput<S> {
        debug_assert!(self.decoupled());
        let y = self.output();
        let x = self.x;
        for i in 0..4 {
            let (m, e) = (i % 2, &self.e0[i]);
            // `row` with e[1 - m], e[3 - m], e[5 - m] zero: f = e[4+m] u[m]; a = fma(e[m],
            // x[m], f); b = e[2+m] x[2+m]; a + b.
            let f = e[4 + m] * force[m];
            let a = e[m].mul_add(x[m], f);
            self.x[i] = a + e[2 + m] * x[2 + m];
        }
        y
    }

    /// The current state `[q1, q2, v1, v2]` (m, m/s).
    pub fn state(&self) -> [S; 4] {
        self.x
    }

    /// Overwrites the state `[q1, q2, v1, v2]` (m, m/s), e.g. for a ring-down.
    pub fn set_state(&mut self, x: [S; 4]) {
        self.x = x;
    }
}

impl<S: Sample> Stage for Resonator<S> {
    /// Held forces per unit mass `[f1, f2]`, m/s^2.
    type Input = [S; 2];
    type Output = PlantOutput<S>;

    /// One step at the design rate (state before the update, see the type docs).
    #[inline(always)]
    fn tick(&mut self, force: [S; 2]) -> PlantOutput<S> {
        let y = self.output();
        let x = self.x;
        let z = [x[0], x[1], x[2], x[3], force[0], force[1]];
        for i in 0..4 {
            self.x[i] = Self::row(&self.e0[i], &z);
        }
        y
    }

    fn reset(&mut self) {
        self.x = [S::default(); 4];
    }
}

impl Resonator<f64> {
    /// The parameters the plant was built from.
    pub fn params(&self) -> &ResonatorParams {
        &self.params
    }

    /// The design rate (rad/s) of the exact discretisation.
    pub fn omega_z_rad_s(&self) -> f64 {
        self.omega_c_f64
    }

    /// State transition `Phi = exp(A Ts)` at the design rate.
    pub fn phi(&self) -> [[f64; 4]; 4] {
        self.e0.map(|r| [r[0], r[1], r[2], r[3]])
    }

    /// Held-input matrix `Gamma = int_0^Ts exp(A s) ds B` at the design rate.
    pub fn gamma(&self) -> [[f64; 2]; 4] {
        self.e0.map(|r| [r[4], r[5]])
    }

    /// The three expansion blocks `[E0, E1, E2]` (4x6 each, physical units).
    pub(crate) fn expansion(&self) -> [Block; 3] {
        [self.e0, self.e1, self.e2]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// E1 and E2 are the first two Taylor coefficients in the rate: compare with central
    /// differences of exact discretisations built at neighbouring rates.
    #[test]
    fn expansion_matches_finite_differences_of_exact_steps() {
        let mut p = ResonatorParams::matched(1e3, 300.0, 0.7, 16e3);
        p.mode2.f0_hz = 1.01e3;
        p.quadrature_coupling_rad2_s2 = 3e4;
        let (wc, h) = (2.0, 5.0);
        let r0 = Resonator::<f64>::new(&p, wc).unwrap();
        let rp = Resonator::<f64>::new(&p, wc + h).unwrap();
        let rm = Resonator::<f64>::new(&p, wc - h).unwrap();
        let [e0, e1, e2] = r0.expansion();
        let [ep, em] = [rp.expansion()[0], rm.expansion()[0]];
        let s = crate::discretise::scales(&p);
        let (mut err1, mut err2, mut n1, mut n2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for i in 0..4 {
            for j in 0..6 {
                let b = s[i] / s[j];
                let d1 = (ep[i][j] - em[i][j]) / (2.0 * h);
                let d2 = (ep[i][j] - 2.0 * e0[i][j] + em[i][j]) / (2.0 * h * h);
                err1 = err1.max(b * (d1 - e1[i][j]).abs());
                err2 = err2.max(b * (d2 - e2[i][j]).abs());
                n1 = n1.max(b * e1[i][j].abs());
                n2 = n2.max(b * e2[i][j].abs());
            }
        }
        // Truncation of the differences is O((h Ts)^2) relative.
        eprintln!("E1 rel {:e} E2 rel {:e}", err1 / n1, err2 / n2);
        assert!(err1 / n1 < 1e-7, "E1 rel err {}", err1 / n1);
        assert!(err2 / n2 < 1e-6, "E2 rel err {}", err2 / n2);
    }
}
