//! Demodulation of a rate-table run at the harmonics of the table frequency, and the exact
//! read-out of the phase response from those harmonics (THEORY.md section 3).
//!
//! With the table at `Omega(t) = A sin(w_t t)` the plant settles to a periodic envelope
//! `V(t) = sum_n V_n e^{j n w_t t}` on the carrier. The low-pass acts on the complex `z`, not on
//! its phase, so each harmonic reaches the read-out as `V_n L(n f_t) H(f_c + n f_t)` (low-pass
//! and TIA). [`TableMixer`] demodulates `z` at every harmonic `n = -N..N`; averaged over whole
//! table periods that gives the harmonics themselves. The read-out divides the chain out of
//! each harmonic and only then takes the phase ([`phase_fundamental`]), which is exact at any
//! swing, where dividing the fundamental of the phase by `L(f_t)` is exact only for small ones.

use crate::Iq;
use core::marker::PhantomData;
use gyroemu_core::detmath::sin_cos_turns;
use gyroemu_core::{Complex64, Sample, Stage};

/// Highest table harmonic a board demodulates.
pub const MAX_TABLE_HARMONIC: usize = 15;

/// Harmonics `-MAX .. MAX`.
pub const TABLE_HARMONICS: usize = 2 * MAX_TABLE_HARMONIC + 1;

/// Real channels of [`TableMixer`]'s output: `(re, im)` of both modes at every harmonic.
pub const TABLE_CHANNELS: usize = 4 * TABLE_HARMONICS;

/// The channel of `(re, im)` of mode `mode` at harmonic `n` (`-N ..= N`) in the output of a
/// [`TableMixer`] of `harmonics` = N: `4 (n + N) + 2 mode`, imaginary part next (so the
/// channels in use come first).
pub const fn table_channel(n: isize, mode: usize, harmonics: usize) -> usize {
    4 * (n + harmonics as isize) as usize + 2 * mode
}

/// `z_k e^{-j n theta}` of both modes at harmonics `n = -N..N`, with `theta` the table phase
/// given as `e^{-j theta}`; channels beyond harmonic `N` stay zero.
#[derive(Clone, Copy, Debug)]
pub struct TableMixer<S> {
    harmonics: usize,
    _s: PhantomData<S>,
}

impl<S: Sample> TableMixer<S> {
    /// A mixer of harmonics `-harmonics ..= harmonics` (at most [`MAX_TABLE_HARMONIC`]).
    pub fn new(harmonics: usize) -> gyroemu_core::ParamResult<Self> {
        if harmonics > MAX_TABLE_HARMONIC {
            return Err(gyroemu_core::ParamError::new(
                "mixer",
                "table_harmonics",
                harmonics,
                format!("must be at most {MAX_TABLE_HARMONIC}"),
            ));
        }
        Ok(Self {
            harmonics,
            _s: PhantomData,
        })
    }

    /// The highest harmonic demodulated.
    pub fn harmonics(&self) -> usize {
        self.harmonics
    }

    /// Real channels in use, `4 (2N + 1)` (the first ones of the output).
    pub fn channels(&self) -> usize {
        4 * (2 * self.harmonics + 1)
    }
}

/// `e^{-j theta}` for the table phase `theta = 2 pi n_in f_t / fs` of input sample `n_in`,
/// by the deterministic sine (the same bits on every platform).
#[inline]
pub fn table_reference(n_in: u64, table_hz: f64, fs_hz: f64) -> Complex64 {
    let (s, c) = sin_cos_turns(n_in as f64 * table_hz / fs_hz);
    Complex64::new(c, -s)
}

impl<S: Sample> Stage for TableMixer<S> {
    /// The low-passed stage-1 outputs of both modes and `e^{-j theta}` as `(re, im)` per lane
    /// (each lane may follow its own table: the bandwidth sweep runs one frequency per lane).
    type Input = ([Iq<S>; 2], (S, S));
    type Output = [S; TABLE_CHANNELS];

    #[inline(always)]
    fn tick(&mut self, (z, (b_re, b_im)): Self::Input) -> Self::Output {
        let mut out = [S::splat(0.0); TABLE_CHANNELS];
        // p = e^{-j n theta} by repeated multiplication (n <= 15 roundings: negligible), lane
        // by lane the arithmetic of `Complex64`'s product.
        let (mut p_re, mut p_im) = (S::splat(1.0), S::splat(0.0));
        for n in 0..=self.harmonics as isize {
            for sign in [1, -1] {
                if n == 0 && sign < 0 {
                    continue;
                }
                let (c, s) = if sign > 0 {
                    (p_re, p_im)
                } else {
                    (p_re, -p_im)
                };
                for (md, zm) in z.iter().enumerate() {
                    let ch = table_channel(sign * n, md, self.harmonics);
                    out[ch] = zm.i * c - zm.q * s;
                    out[ch + 1] = zm.i * s + zm.q * c;
                }
            }
            let re = p_re * b_re - p_im * b_im;
            p_im = p_re * b_im + p_im * b_re;
            p_re = re;
        }
        out
    }

    fn reset(&mut self) {}
}

/// The complex amplitude of the fundamental of the phase lag `phi(theta) = -arg V(theta)` of
/// the periodic envelope `V(theta) = sum_n h[n + N] e^{j n theta}` (`h` holds harmonics
/// `-N..=N`): `(1/pi) int_0^{2 pi} phi e^{-j theta} d theta`, so a lag `a sin(theta - l)`
/// gives `-j a e^{-j l}`. Evaluated on 1024 points (the rectangle rule is exact for a periodic
/// function's harmonics below 512). NaN when `V` winds around 0 (no continuous phase).
pub fn phase_fundamental(h: &[Complex64]) -> Complex64 {
    fundamental_on(h, grid(1024)).0
}

/// The `g + 1` points `(sin, cos)` of `2 pi k / g`, `k = 0 ..= g`, for `g` a power of two from
/// 1024 to 2^18: built once per process (the same bits as computing them here), so a read-out
/// or a theory curve that checks its fundamental on a finer grid does not recompute its sines.
fn grid(g: usize) -> &'static [(f64, f64)] {
    type Grid = std::sync::OnceLock<Box<[(f64, f64)]>>;
    static GRIDS: [Grid; 9] = [const { Grid::new() }; 9];
    debug_assert!(g.is_power_of_two() && (1024..=1 << 18).contains(&g));
    GRIDS[(g.trailing_zeros() - 10) as usize].get_or_init(|| {
        (0..=g)
            .map(|k| sin_cos_turns(k as f64 / g as f64))
            .collect()
    })
}

/// Why [`phase_fundamental_checked`] has no fundamental to give.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoFundamental {
    /// The envelope goes around 0 over the period (on a grid that resolves every phase step).
    Winds,
    /// The envelope passes so close to 0 that its phase turns by nearly a half turn within a
    /// step of the finest grid (2^18 points), or its fundamental never settles there: the
    /// reading is that ill-conditioned.
    Unresolved,
}

/// [`phase_fundamental`] of an envelope of any number of harmonics, on a grid fine enough
/// for its phase: the phase of an envelope that dips near zero turns fast there, and its
/// harmonics reach far beyond the envelope's (a 535-degree swing of 96 envelope harmonics
/// read 534.713 deg on 2048 points and 534.7328 on 8192). The grid doubles from 1024 (or 16
/// points per harmonic) until every phase step between its points is under a quarter turn
/// (so winding is judged right) and the fundamental moves by less than 1e-9 of itself (plus
/// 1e-13 rad), up to 2^18 points. Where 1024 points already hold it, the same bits as
/// [`phase_fundamental`].
///
/// Each finer grid takes the coarser one's points as its even points (the same angles, so
/// the same phases bit for bit) and evaluates only its odd ones: a third less work where two
/// levels settle it, the same bits as evaluating every level whole (tested).
pub fn phase_fundamental_checked(h: &[Complex64]) -> Result<Complex64, NoFundamental> {
    let mut g = first_grid(h);
    // At 1024 points, the value is phase_fundamental's: the same grid, the same bits.
    let mut phases = phases_on(h, grid(g));
    let mut x = fundamental_of(&phases, grid(g));
    while g < MAX_GRID {
        let fine = grid(2 * g);
        // Point 2k of the finer grid is point k of this one: sin_cos_turns of the same
        // argument (2k / 2g and k / g are the same double).
        let odd: Vec<(f64, f64)> = fine.iter().skip(1).step_by(2).copied().collect();
        let odd = phases_on(h, &odd);
        let mut both = Vec::with_capacity(2 * g + 1);
        for (&even, &odd) in phases.iter().zip(&odd) {
            both.extend([even, odd]);
        }
        both.push(phases[g]);
        let finer = fundamental_of(&both, fine);
        if let Some(found) = settled(x, finer) {
            return found;
        }
        (x, g, phases) = (finer, 2 * g, both);
    }
    Err(NoFundamental::Unresolved)
}

/// The finest grid [`phase_fundamental_checked`] takes.
const MAX_GRID: usize = 1 << 18;

/// The grid [`phase_fundamental_checked`] starts on: 16 points per harmonic of `h`, at least
/// 1024 (where it is [`phase_fundamental`]'s).
fn first_grid(h: &[Complex64]) -> usize {
    (16 * (h.len() / 2))
        .next_power_of_two()
        .clamp(1024, MAX_GRID)
}

/// What two successive grids' fundamentals (value, largest phase step, turned) say: winding
/// where both resolve every step and both turned, the coarser value where both resolve, neither
/// turned and they agree to 1e-9 of the value (plus 1e-13 rad), else nothing yet.
fn settled(
    x: (Complex64, f64, bool),
    finer: (Complex64, f64, bool),
) -> Option<Result<Complex64, NoFundamental>> {
    let resolved = x.1 < core::f64::consts::FRAC_PI_2 && finer.1 < core::f64::consts::FRAC_PI_2;
    if resolved && x.2 && finer.2 {
        return Some(Err(NoFundamental::Winds));
    }
    if resolved && !x.2 && !finer.2 && (finer.0 - x.0).norm() <= 1e-9 * finer.0.norm() + 1e-13 {
        return Some(Ok(x.0));
    }
    None
}

/// [`phase_fundamental_checked`], NaN where it has none.
pub fn phase_fundamental_fine(h: &[Complex64]) -> Complex64 {
    phase_fundamental_checked(h).unwrap_or(Complex64::new(f64::NAN, f64::NAN))
}

/// The fundamental on `grid`, `G + 1` points `(sin, cos)` of `2 pi g / G` (the last closes the
/// period, for the winding test), NaN where the phase turns a whole turn over the period;
/// with the largest phase step between neighbouring points and whether it turned.
fn fundamental_on(h: &[Complex64], grid: &[(f64, f64)]) -> (Complex64, f64, bool) {
    fundamental_of(&phases_on(h, grid), grid)
}

/// The phase lag `-arg V(theta)` at each point `(sin, cos)` of `theta` in `grid`.
fn phases_on(h: &[Complex64], grid: &[(f64, f64)]) -> Vec<f64> {
    let nh = (h.len() / 2) as i32;
    let values = envelope_on_grid(h, grid);
    grid.iter()
        .zip(&values)
        .map(|(&(s, c), &v)| -(v * Complex64::new(c, -s).powi(nh)).arg())
        .collect()
}

/// [`fundamental_on`] from the phases at the grid's points.
fn fundamental_of(phases: &[f64], grid: &[(f64, f64)]) -> (Complex64, f64, bool) {
    let g_len = grid.len() - 1;
    let mut acc = Complex64::new(0.0, 0.0);
    let mut prev = f64::NAN;
    let mut unwrapped = 0.0;
    let mut first = 0.0;
    let mut step: f64 = 0.0;
    for (g, (&(s, c), &ph)) in grid.iter().zip(phases).enumerate() {
        unwrapped = if prev.is_nan() {
            ph
        } else {
            let d = crate::wrap_pi(ph - prev);
            step = step.max(d.abs());
            unwrapped + d
        };
        prev = ph;
        if g == 0 {
            first = unwrapped;
        }
        if g < g_len {
            acc += unwrapped * Complex64::new(c, -s);
        }
    }
    // A whole turn of the phase over the period: V went around 0.
    let turned = (unwrapped - first).abs() > core::f64::consts::PI;
    if turned || !acc.is_finite() {
        return (Complex64::new(f64::NAN, f64::NAN), step, turned);
    }
    (acc * (2.0 / g_len as f64), step, false)
}

/// `sum_n h[n] e^{j n theta}` at each grid point `(sin, cos)` of `theta`, by Horner from the
/// highest harmonic. Eight grid points at a time, each with the operations of its own
/// Horner (the same bits): one point's Horner is a chain of dependent products, and a
/// theory curve's read-outs (49 harmonics, 1025 points each) waited on it.
fn envelope_on_grid(h: &[Complex64], grid: &[(f64, f64)]) -> Vec<Complex64> {
    const W: usize = 8;
    let zero = Complex64::new(0.0, 0.0);
    let mut out = Vec::with_capacity(grid.len());
    for chunk in grid.chunks(W) {
        let base: [Complex64; W] =
            core::array::from_fn(|k| chunk.get(k).map_or(zero, |&(s, c)| Complex64::new(c, s)));
        let mut v = [zero; W];
        for x in h.iter().rev() {
            for k in 0..W {
                v[k] = v[k] * base[k] + x;
            }
        }
        out.extend_from_slice(&v[..chunk.len()]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`phase_fundamental_checked`] as it was first written: every level evaluated whole
    /// (the same grids and decision between levels, [`first_grid`] and [`settled`]).
    fn checked_level_by_level(h: &[Complex64]) -> Result<Complex64, NoFundamental> {
        let on = |g: usize| fundamental_on(h, grid(g));
        let mut g = first_grid(h);
        let mut x = on(g);
        while g < MAX_GRID {
            let finer = on(2 * g);
            if let Some(found) = settled(x, finer) {
                return found;
            }
            (x, g) = (finer, 2 * g);
        }
        Err(NoFundamental::Unresolved)
    }

    fn bits(r: Result<Complex64, NoFundamental>) -> Result<(u64, u64), NoFundamental> {
        r.map(|z| (z.re.to_bits(), z.im.to_bits()))
    }

    /// The identity the reuse rests on: each finer grid's phases are the coarser grid's at its
    /// even points and its own odd points' in between, bit for bit.
    #[test]
    fn a_finer_grid_holds_the_coarser_grids_phases_at_its_even_points() {
        for (nh, base) in [(1, 1.001), (5, 3.0), (24, 1.05), (96, 0.98)] {
            let mut h = vec![Complex64::new(0.0, 0.0); 2 * nh + 1];
            for (i, x) in h.iter_mut().enumerate() {
                let n = i as f64 - nh as f64;
                *x = Complex64::new((1.3 * n).sin(), (0.7 * n).cos()) * 1e-3 / (1.0 + n * n);
            }
            h[nh] += base;
            h[nh + 1] += 1.0;
            for g in [1024, 2048, 8192, 1 << 17] {
                let coarse = phases_on(&h, grid(g));
                let fine = phases_on(&h, grid(2 * g));
                let odd: Vec<(f64, f64)> = grid(2 * g).iter().skip(1).step_by(2).copied().collect();
                let odd = phases_on(&h, &odd);
                for k in 0..=2 * g {
                    let want = if k % 2 == 0 {
                        coarse[k / 2]
                    } else {
                        odd[k / 2]
                    };
                    assert_eq!(fine[k].to_bits(), want.to_bits(), "{nh} {g} {k}");
                }
            }
        }
    }

    #[test]
    fn reusing_the_coarser_grid_gives_the_bits_of_every_level_whole() {
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut uniform = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (mut levels, mut winds, mut unresolved) = (0, 0, 0);
        for case in 0..60 {
            let nh = [1, 2, 5, 24, 49, 96][case % 6];
            // `base + e^{j theta}` plus small decaying harmonics: a base just above 1 dips
            // near zero (the phase turns fast: finer grids), one below 1 winds.
            let base = [3.0, 1.05, 1.001, 0.98, 0.5][case % 5];
            let mut h: Vec<Complex64> = (0..2 * nh + 1)
                .map(|i| {
                    let n = i as f64 - nh as f64;
                    Complex64::new(uniform(), uniform()) * 1e-3 / (1.0 + n * n)
                })
                .collect();
            h[nh] += base;
            h[nh + 1] += 1.0;
            let want = checked_level_by_level(&h);
            assert_eq!(
                bits(phase_fundamental_checked(&h)),
                bits(want),
                "case {case}"
            );
            match want {
                Ok(_) if fundamental_on(&h, grid(1024)).1 > 0.1 => levels += 1,
                Err(NoFundamental::Winds) => winds += 1,
                Err(NoFundamental::Unresolved) => unresolved += 1,
                _ => {}
            }
        }
        // The sweep reaches the cases that matter: fast-turning phases, and winding.
        assert!(levels > 0 && winds > 0, "{levels} {winds} {unresolved}");
    }
}
