//! The DAC's rounding of the two drives: how far it can move the measured phase. A carrier
//! whose sample pattern repeats within a few thousand samples rounds the same way every
//! period (its effect is exact); any other carrier drifts through every offset against the
//! samples, and the rounding with it (a worst case over the drift).

use crate::config::Config;
use crate::plan::DEG;
use crate::validate_regime::{half_turn_mdeg, WARN_HOLD_ERROR_MDEG};
use gyroemu_board::{ChainResponse, Shape};
use gyroemu_core::Complex64;

/// The DAC's code of `u` (step `lsb`, `half` = 2^(bits - 1) codes a side): mid-tread, ties
/// away from zero, clipped to [-half, half - 1], as `gyroemu_am::Quantizer::quantize` rounds.
pub(crate) fn dac_code(u: f64, lsb: f64, half: f64) -> f64 {
    (u / lsb).round().clamp(-half, half - 1.0)
}

impl Config {
    /// The DAC rounds the cos and the sin drive sequences differently whenever the drives
    /// differ or the carrier's period is not a multiple of 4 samples (only then is the sin
    /// sequence a shifted copy of the cos one): the fundamentals the plant responds to change
    /// in ratio and relative phase, which moves the Coriolis phase like a drive mismatch (250
    /// mdeg at 4 bits, 1.85 mdeg at 12 bits, fs = 250 kHz, with no warning before).
    ///
    /// A carrier whose sample pattern repeats exactly within 4096 samples rounds the same
    /// way every period: the exact quantised fundamentals, through the theory's phase.
    /// Any other carrier (slightly detuned, PLL-locked) has a pattern whose offset against
    /// the samples drifts slowly through every value, and the rounding, hence both drives'
    /// fundamentals, changes with it: 1074 mdeg (4 bits) and 22 mdeg (8 bits) on a rate table
    /// at 15000.01 Hz had no warning. There: the worst over the drift offset (see
    /// [`drift_gains`]) of the theory's phase change, through the bounding box of the
    /// ratio's and relative phase's values. Rotating runs: see
    /// [`Config::rotating_dac_drift_rad`] (an exact pattern cannot move psi).
    ///
    /// `locked` (a PLL's expected lock): the carrier ends within the loop's error of this one,
    /// so its pattern drifts too slowly to average over a window, from an offset no rule can
    /// know: the pattern is judged as drifting (every offset) even where this carrier repeats.
    pub(crate) fn validate_dac_rounding(&self, warnings: &mut Vec<String>, locked: bool) {
        let Some(bits) = self.board.dac_bits else {
            return;
        };
        let Some(pattern) = self.dac_pattern(bits, locked) else {
            return;
        };
        if self.shape() == Shape::Rotating {
            let DacPattern::Drifting { q, beat, .. } = pattern else {
                // Each drive's fundamental is then its envelope through one fixed describing
                // function: both sidebands of a drive scale alike and psi does not move
                // (measured: below 2e-7 mdeg at 4 bits). A lock's carrier sits near such a
                // pattern and drifts through it slowly: that slow change is bounded apart.
                let worst = if locked {
                    self.rotating_lock_dynamics_mdeg(bits)
                } else {
                    0.0
                };
                if worst > WARN_HOLD_ERROR_MDEG {
                    warnings.push(format!(
                        "board.dac_bits = {bits}: a PLL's lock ends near, not on, a carrier whose samples repeat, so the DAC's rounding of each rotating drive drifts slowly with the carrier's offset against the samples, and the plant follows that change with a lag that differs between the two sidebands, which moves psi by up to {worst:.3e} mdeg at these rates (a bound, the rounding's share of each sideband taken at its largest, 4 LSB over the drive); raise board.dac_bits"
                    ));
                }
                return;
            };
            let worst = self.rotating_dac_drift_rad(bits, q, beat) / DEG * 1e3;
            if worst > WARN_HOLD_ERROR_MDEG {
                warnings.push(format!(
                    "board.dac_bits = {bits}: the carrier's sample pattern does not repeat (it drifts against the samples, nearest {q}-sample pattern), so the DAC's rounding of each rotating drive changes slowly with the drift and with the envelope's level, which moves psi by up to {worst:.3e} mdeg at these rates (a bound from the rounding's harmonics over the drift and the envelope, each at its full weight: measured 20 to 2500 times above the real change, which can vanish when the beat is a whole multiple of the modulation); raise board.dac_bits, or use a carrier that repeats in a few samples"
                ));
            }
            return;
        }
        let mut dynamic = 0.0;
        let (ratios, exact_ratio, drift) = match pattern {
            DacPattern::Exact([p1, p2], [q1, q2]) => {
                (vec![(q2 / q1) / (p2 / p1)], (p2 / p1).norm(), None)
            }
            DacPattern::Drifting {
                q,
                ratios,
                phase_span,
                envelope,
                ..
            } => {
                dynamic = self.drift_dynamics_mdeg(envelope);
                (ratios, self.f2() / self.drive.f1, Some((q, phase_span)))
            }
        };
        let dev = self.driven_device();
        // Common gains and phases cancel in every phase the board reads (each against zero
        // rate, or against the table's own swing): only the ratio and the relative phase
        // count. A drifting pattern: the corners of the box around every ratio it takes (the
        // phase change is near-linear in so small a change, so its extremes lie there).
        let (mut r_lo, mut r_hi, mut t_lo, mut t_hi) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for g in &ratios {
            (r_lo, r_hi) = (r_lo.min(g.norm()), r_hi.max(g.norm()));
            (t_lo, t_hi) = (t_lo.min(g.arg()), t_hi.max(g.arg()));
        }
        let corners: Vec<(f64, f64)> = if drift.is_some() {
            vec![(r_lo, t_lo), (r_lo, t_hi), (r_hi, t_lo), (r_hi, t_hi)]
        } else {
            vec![(r_lo, t_lo)]
        };
        // The device driven by the rounded drives: their ratio r and relative turn (rad).
        let quantised_at = |r: f64, turn: f64| gyroemu_theory::DrivenDevice {
            drive: [dev.drive[0], dev.drive[1] * r],
            phase_shifter_error_deg: dev.phase_shifter_error_deg - turn / DEG,
            ..dev
        };
        let mut worst: f64 = 0.0;
        for &(r, turn) in &corners {
            let quantised = quantised_at(r, turn);
            for &rate in &self.experiment.rates_dps {
                let omega = rate * DEG;
                let pairs: Vec<([f64; 2], [f64; 2])> = match self.shape() {
                    Shape::RateTable { freq_hz } => {
                        let (a, l) = dev.rate_table_response(omega, freq_hz);
                        let (qa, ql) = quantised.rate_table_response(omega, freq_hz);
                        vec![(a, qa), (l, ql)]
                    }
                    _ => vec![(
                        dev.coriolis_phase_rad(omega),
                        quantised.coriolis_phase_rad(omega),
                    )],
                };
                for (exact, q) in pairs {
                    for k in 0..2 {
                        let e = half_turn_mdeg(q[k], exact[k]);
                        if e.is_finite() {
                            worst = worst.max(e);
                        }
                    }
                }
            }
        }
        if let (Some((_, span)), Shape::RateTable { freq_hz }) = (drift, self.shape()) {
            // A rate table reads the fundamental of each mode's phase at f_t, and the drift
            // moves that phase at the beat's harmonics, some near f_t: its own drive's phase
            // (half its range about the middle) and the ratio's effect at the peak rate
            // (the Coriolis phase's change at the corners), at every instant; the
            // fundamental of what is bounded by x is at most 4x/pi. (The table's own theory
            // at the corners missed 1074 mdeg at 4 bits, 15000.01 Hz.)
            let mut ratio_part: f64 = 0.0;
            for &(r, turn) in &corners {
                let quantised = quantised_at(r, turn);
                for &rate in &self.experiment.rates_dps {
                    let (a, b) = (
                        dev.coriolis_phase_rad(rate * DEG),
                        quantised.coriolis_phase_rad(rate * DEG),
                    );
                    for k in 0..2 {
                        let e = half_turn_mdeg(b[k], a[k]);
                        if e.is_finite() {
                            ratio_part = ratio_part.max(e);
                        }
                    }
                }
            }
            let pointwise = span / DEG * 1e3 + ratio_part;
            let moved = 4.0 / core::f64::consts::PI * pointwise;
            worst = worst.max(moved);
            // The lag is the fundamental's angle: a change of `moved` against the response's
            // amplitude A turns it by up to asin(moved / A), and by anything once it reaches
            // A (it was stated as if it were the lag: 1248 mdeg where 5 deg/s moved the lag
            // 12 875 mdeg, at 6 bits and 15000.01 Hz).
            for &rate in &self.experiment.rates_dps {
                let (amplitude, _) = dev.rate_table_response(rate * DEG, freq_hz);
                for a in amplitude.map(|a| a.abs() / DEG * 1e3) {
                    let lag = if moved < a {
                        (moved / a).asin()
                    } else {
                        core::f64::consts::PI
                    };
                    if lag.is_finite() {
                        worst = worst.max(lag / DEG * 1e3);
                    }
                }
            }
        }
        worst = worst.max(dynamic);
        if worst > WARN_HOLD_ERROR_MDEG {
            let what = match drift {
                None => format!(
                    "the DAC rounds the two drives differently (their fundamentals' ratio F2/F1 becomes {:.6e} instead of {exact_ratio:.6e}, their phase difference moves by {:.3e} deg)",
                    exact_ratio * r_lo,
                    -t_lo / DEG
                ),
                Some((q, span)) => format!(
                    "the carrier's sample pattern does not repeat (it drifts against the samples, nearest {q}-sample pattern), so the DAC's rounding of the two drives changes with the drift: their fundamentals' ratio F2/F1 ranges over {:.6e} ..= {:.6e} (unrounded {exact_ratio:.6e}), their phase difference moves by {:.3e} ..= {:.3e} deg and each drive's own phase stays within +-{:.3e} deg (over every drift offset){}",
                    exact_ratio * r_lo,
                    exact_ratio * r_hi,
                    -t_hi / DEG,
                    -t_lo / DEG,
                    span / DEG,
                    if dynamic > 0.0 {
                        format!(", and the plant follows the drives' slow change with a lag that differs with the rate (up to {dynamic:.3e} mdeg of what follows, a bound)")
                    } else {
                        String::new()
                    }
                ),
            };
            warnings.push(format!(
                "board.dac_bits = {bits}: {what}, which moves the measured phase from the theory by up to {worst:.3e} mdeg at these rates, as a drive mismatch would; raise board.dac_bits (equal drives at a whole multiple of 4 samples per carrier period round alike)"
            ));
        }
    }

    /// What the drift's slow change of the drives' fundamentals does through the plant's
    /// dynamics in a Coriolis run, mdeg (0 for other runs). A fundamental `G(t)` that changes
    /// slowly against the mechanical time constant reaches each mode as `R G + R' dG/dt /
    /// (2 pi j)` (`R` the mode's response at the carrier, `R'` its frequency derivative), and
    /// the window's average of `dG/dt` is `(G(T) - G(0)) / T`: the rate's lane and the
    /// zero-rate reference read the same `G`, so their phases differ from the theory by at
    /// most `|R'/R (rate) - R'/R (0)| |dG| / (2 pi T |G|)`, with `|dG|/|G|` at most
    /// `envelope`. Twice that covers a code step within a time constant of the window's
    /// ends; a Hann window's weights double it again. The quasi-static terms (the ratio's
    /// box) miss it: two drives that are shifted copies (a quadrature pair at 16 samples per
    /// period) keep their ratio at every offset, yet a 6-bit DAC on a PLL's lock moved the
    /// phase 0.55 mdeg at 175 deg/s (this bound: see the test).
    fn drift_dynamics_mdeg(&self, envelope: f64) -> f64 {
        if self.shape() != Shape::Coriolis || envelope.is_nan() || envelope <= 0.0 {
            return 0.0;
        }
        let dev = self.driven_device();
        let force = dev.coriolis_force();
        let slope = |w: f64, m: usize| log_slope(&dev.plant, w, dev.carrier_hz, force, m);
        let window_s = self
            .experiment
            .rates_dps
            .iter()
            .map(|&r| self.plan_point(r).window.span() / self.fs_out_hz())
            .fold(f64::INFINITY, f64::min);
        let mut worst: f64 = 0.0;
        for m in 0..2 {
            let at_zero = slope(0.0, m);
            for &rate in &self.experiment.rates_dps {
                let e = (slope(rate * DEG, m) - at_zero).norm();
                if e.is_finite() {
                    worst = worst.max(e);
                }
            }
        }
        self.window_ends() * worst * envelope / (core::f64::consts::TAU * window_s) / DEG * 1e3
    }

    /// What the drift bounds of [`Config::drift_dynamics_mdeg`] allow for the window's ends:
    /// twice the first-order term covers a code step within a time constant of them, and a
    /// Hann window's weights double it again.
    fn window_ends(&self) -> f64 {
        match self.experiment.window {
            crate::config::WindowKind::Hann => 4.0,
            _ => 2.0,
        }
    }

    /// The slow drift of a PLL-locked rotating run's DAC rounding seen through the plant's
    /// dynamics, mdeg. At a fixed offset both sidebands of a drive scale alike and psi does
    /// not move; as the offset drifts, each sideband's share of the rounding changes slowly
    /// (by at most 4 LSB over the drive's amplitude: the rounding's fundamental is within
    /// LSB/a of a sample pattern of amplitude a, so each sideband within 2 LSB of its A/2),
    /// and each sideband's response follows as `R G + R' dG/dt / (2 pi j)` (see
    /// [`Config::drift_dynamics_mdeg`]): psi, half the difference of the two sidebands'
    /// phases, moves by at most `|R'/R(fc - fm) - R'/R(fc + fm)| / 2` times that change over
    /// `2 pi T` and over what is left of the gain, twice for a code step near the window's
    /// ends, twice again for Hann. An 8-bit DAC on a lock moved psi 0.15 mdeg, unwarned.
    fn rotating_lock_dynamics_mdeg(&self, bits: u32) -> f64 {
        let half = (1u64 << (bits - 1)) as f64;
        let lsb = self.board.dac_full_scale / half;
        let change = (4.0 * lsb / self.drive.f1.min(self.f2())).min(2.0);
        let dev = self.driven_device();
        // R'/R of mode k's velocity at the sideband `sign` of modulation fm, 1/Hz.
        let slope = |sign: f64, fm: f64, k: usize| {
            let f = dev.carrier_hz + sign * fm;
            log_slope(&dev.plant, 0.0, f, dev.sideband_force(sign), k)
        };
        let ends = self.window_ends();
        // Each sideband's gain stays within 2 LSB/F of 1, so the change is relative to at
        // least 1 - change/2 of it (a 4-bit DAC: 0.63); none left past that.
        let left = 1.0 - 0.5 * change;
        if left <= 0.0 {
            return 180.0e3;
        }
        let mut worst: f64 = 0.0;
        for &rate in self.experiment.rates_dps.iter().filter(|r| **r != 0.0) {
            let fm = rate.abs() / 360.0;
            let window_s = self.plan_point(rate).window.span() / self.fs_out_hz();
            for k in 0..2 {
                let e = 0.5 * (slope(-1.0, fm, k) - slope(1.0, fm, k)).norm() * change * ends
                    / (core::f64::consts::TAU * window_s * left);
                if e.is_finite() {
                    worst = worst.max(e);
                }
            }
        }
        worst / DEG * 1e3
    }

    /// What a drifting carrier pattern's rounding can do to a rotating run's psi (rad). Each
    /// drive `A_k c_k(t) cos(phi)` (c_1 = cos Omega t, c_2 = sin) reaches the plant as
    /// `a N(a, psi)` at the carrier, `a = A_k c_k`, `N` the quantiser's describing function
    /// over the `q`-sample pattern at drift offset `psi` (which turns at the beat
    /// `f_b = |q f_c - p fs|`). Split `N = Nbar(a) + dN` with `Nbar` its mean over psi: the
    /// `Nbar` part gives both sidebands of a drive one common factor, which psi cancels (so an
    /// exact carrier, whose psi is fixed, moves nothing). `a dN` is a function of the two
    /// phases `Omega t` and `q psi`, sampled on a grid and expanded in their harmonics
    /// `(m, n)`, `n != 0`: each is a tone at `f_c + m f_m + n f_b` that reaches a sideband's
    /// reading through the plant, the low-pass and the window's response at its distance from
    /// `+-f_m`, against the sideband itself; psi moves by at most half the two sidebands'
    /// relative errors. A bound given the sampled harmonics (the grid's aliasing of the
    /// rounding's steps is not bounded).
    fn rotating_dac_drift_rad(&self, bits: u32, q: u64, beat_hz: f64) -> f64 {
        use core::f64::consts::TAU;
        let Ok(chain) = ChainResponse::new(&self.board_params()) else {
            return 0.0;
        };
        let half = (1u64 << (bits - 1)) as f64;
        let lsb = self.board.dac_full_scale / half;
        let code = |u: f64| dac_code(u, lsb, half);
        let plant = self.resonator_params();
        let fc = self.carrier_hz();
        let fs_out = self.fs_out_hz();
        let n_theta = 64usize;
        let n_psi = ((4e6 / (n_theta as f64 * q as f64)) as usize).clamp(8, 128);
        // The describing function at level a and offset psi (a != 0).
        let df = |a: f64, psi: f64| -> Complex64 {
            (0..q)
                .map(|m| {
                    let x = TAU * m as f64 / q as f64 + psi;
                    Complex64::from_polar(code(a * x.cos()) * lsb, -x)
                })
                .sum::<Complex64>()
                * (2.0 / (q as f64 * a))
        };
        let mut worst: f64 = 0.0;
        for (k, amp) in [self.drive.f1, self.f2()].into_iter().enumerate() {
            // a dN on the grid (theta = Omega t, psi over one pattern offset period), and the
            // sideband factor Nbar_eff.
            let mut grid = vec![Complex64::new(0.0, 0.0); n_theta * n_psi];
            let mut eff = Complex64::new(0.0, 0.0);
            for it in 0..n_theta {
                let th = TAU * it as f64 / n_theta as f64;
                let c = if k == 0 { th.cos() } else { th.sin() };
                let a = amp * c;
                if a == 0.0 {
                    continue;
                }
                let vals: Vec<Complex64> = (0..n_psi)
                    .map(|ip| df(a, TAU * ip as f64 / (n_psi as f64 * q as f64)))
                    .collect();
                let mean = vals.iter().sum::<Complex64>() / n_psi as f64;
                for (ip, v) in vals.iter().enumerate() {
                    grid[it * n_psi + ip] = (v - mean) * a;
                }
                // The +f_m coefficient of c(theta) a Nbar: (A/2) Nbar_eff (-j for sin).
                eff += mean * a * Complex64::from_polar(2.0 / (amp * n_theta as f64), -th);
            }
            let eff = eff.norm();
            // 2D harmonics F_mn: a DFT along psi, then along theta (separable, tabled twiddles).
            let tw_psi: Vec<Complex64> = (0..n_psi)
                .map(|i| Complex64::from_polar(1.0, -TAU * i as f64 / n_psi as f64))
                .collect();
            let tw_theta: Vec<Complex64> = (0..n_theta)
                .map(|i| Complex64::from_polar(1.0, -TAU * i as f64 / n_theta as f64))
                .collect();
            let along_psi: Vec<Complex64> = (0..n_theta)
                .flat_map(|it| {
                    let row = &grid[it * n_psi..(it + 1) * n_psi];
                    let tw_psi = &tw_psi;
                    (0..n_psi).map(move |n| {
                        row.iter()
                            .enumerate()
                            .map(|(ip, v)| v * tw_psi[(n * ip) % n_psi])
                            .sum::<Complex64>()
                    })
                })
                .collect();
            let mut harmonics = Vec::new();
            for n in 1..n_psi {
                let n_signed = if n > n_psi / 2 {
                    n as i64 - n_psi as i64
                } else {
                    n as i64
                };
                for m in 0..n_theta {
                    let f: Complex64 = (0..n_theta)
                        .map(|it| along_psi[it * n_psi + n] * tw_theta[(m * it) % n_theta])
                        .sum();
                    let f = f.norm() / (n_theta * n_psi) as f64;
                    let m_signed = if m >= n_theta / 2 {
                        m as i64 - n_theta as i64
                    } else {
                        m as i64
                    };
                    if f > 0.0 {
                        harmonics.push((m_signed, n_signed, f));
                    }
                }
            }
            let mode = [plant.mode1, plant.mode2][k];
            let wk = TAU * mode.f0_hz;
            let h = |f: f64| {
                let w = TAU * f;
                w / Complex64::new(wk * wk - w * w, w * wk / mode.q).norm()
            };
            for &rate in &self.experiment.rates_dps {
                let fm = (rate * DEG / TAU).abs();
                let window = self.plan_point(rate).window;
                let mut e = 0.0;
                for side in [1.0, -1.0] {
                    let own = 0.5 * amp * eff * h(fc + side * fm) * chain.lowpass(fm).norm();
                    let err: f64 = harmonics
                        .iter()
                        .map(|&(m, n, f)| {
                            let nu = m as f64 * fm + n as f64 * beat_hz;
                            f * h(fc + nu)
                                * chain.lowpass(nu).norm()
                                * window.response((nu - side * fm) / fs_out).norm()
                        })
                        .sum();
                    e += 0.5 * (err / own).min(1.0).asin();
                }
                worst = worst.max(e);
            }
        }
        worst
    }

    /// The two Coriolis drive sequences as the board makes them (its NCO, phase shifter and
    /// gains) through the DAC's quantiser (mid-tread, step 2 FS / 2^bits, ties away from
    /// zero, clipped to [-FS, FS - step]: the arithmetic of `gyroemu_am::Quantizer::quantize`).
    /// A carrier that repeats within 4096 samples (its phase then drifts by under 1e-12 turn
    /// per period: the NCO's step word is within half a unit of the exact ratio): the exact
    /// fundamentals over one period, unquantised and quantised. Any other: the nearest
    /// pattern of `q` samples (the last continued-fraction convergent `p/q` of the step's
    /// ratio with `q <= 4096`), and for Coriolis and table runs every ratio of the quantised
    /// fundamentals (each relative to its unquantised one) that the drift offset gives.
    /// `None` if a fundamental vanishes (the dead-drive rules speak) or the NCO cannot be
    /// built.
    ///
    /// `any_offset`: a repeating carrier is judged as a drifting one (at beat 0), over every
    /// offset of its pattern against the samples.
    fn dac_pattern(&self, bits: u32, any_offset: bool) -> Option<DacPattern> {
        const MAX_SPAN: u64 = 4096;
        let nco = gyroemu_nco::Nco::new(self.carrier_hz(), self.fs_hz(), 0.0).ok()?;
        let step_word = nco.step_word();
        let near_whole = |n: u64| (step_word.wrapping_mul(n) as i64).unsigned_abs() < 1 << 24;
        let shifter = gyroemu_board::drive_shifter(&self.board_params()).ok()?;
        let half = (1u64 << (bits - 1)) as f64;
        let lsb = self.board.dac_full_scale / half;
        let gains = [self.drive.f1, self.f2()];
        let ok = |v: &[Complex64]| v.iter().all(|x| x.norm() > 0.0 && x.norm().is_finite());
        // A pattern repeating only after thousands of samples still drifts within its period
        // (15001 Hz at 240 kHz repeats each second, its rounding beats at 16 Hz; a table run
        // moved 0.76 mdeg, unwarned): exact only for a short one.
        let exact = (1..=MAX_SPAN).find(|&n| near_whole(n));
        let Some(n) = exact.filter(|_| !any_offset || self.shape() == Shape::Rotating) else {
            let x = step_word as f64 / 2f64.powi(64);
            let q = nearest_pattern(x, 4096)?;
            let beat = (q as f64 * x - (q as f64 * x).round()).abs() * self.fs_hz();
            let mut ratios = Vec::new();
            let mut phase_span: f64 = 0.0;
            let mut envelope: f64 = 0.0;
            let cuts = 2.0 * q as f64 + core::f64::consts::TAU * (gains[0] + gains[1]) / lsb;
            if self.shape() != Shape::Rotating && cuts > MAX_DRIFT_CUTS {
                // Too fine a DAC to follow every threshold (a few ms per 1e6): each sample's
                // error is at most lsb/2, so each fundamental is within lsb/a of the
                // unquantised one (relative), the ratio within twice that.
                let eps = lsb / gains[0].min(gains[1]);
                let e2 = (2.0 * eps).min(0.5);
                ratios = [(-e2, -e2), (-e2, e2), (e2, -e2), (e2, e2)]
                    .map(|(r, t)| Complex64::from_polar(1.0 + r, t))
                    .to_vec();
                phase_span = eps.min(1.0).asin();
                envelope = 2.0 * eps / (1.0 - eps.min(0.5));
            } else if self.shape() != Shape::Rotating {
                let s = shifter.apply(Complex64::new(1.0, 0.0));
                let drives = [(gains[0], 0.0), (gains[1] * s.norm(), s.arg())];
                let w = core::f64::consts::TAU / q as f64;
                let mut dead = false;
                let zero = Complex64::new(0.0, 0.0);
                // Running extremes only (up to millions of intervals): the ratio's |g|^2 and
                // tangent, each G_k's box and tangent (all near 1, so the tangent orders the
                // phases), and each G_k's mean over the offset.
                let inf = (f64::INFINITY, f64::NEG_INFINITY);
                let widen = |r: &mut (f64, f64), v: f64| *r = (r.0.min(v), r.1.max(v));
                let (mut g_abs, mut g_tan) = (inf, inf);
                let (mut re, mut im, mut tan) = ([inf; 2], [inf; 2], [inf; 2]);
                let mut mean = [zero; 2];
                let mut behind = false;
                drift_gains(&drives, q, lsb, half, |lo, hi, c| {
                    dead |= !ok(c);
                    let g = c[1] / c[0];
                    behind |= g.re <= 0.0;
                    widen(&mut g_abs, g.norm_sqr());
                    widen(&mut g_tan, g.im / g.re);
                    // G_k = e^{-j phi} c_k on [lo, hi): its mean, and its two ends.
                    let arc = (hi.1 - lo.1) * Complex64::new(0.0, 1.0) / w;
                    for k in 0..2 {
                        mean[k] += c[k] * arc;
                        for v in [lo.1 * c[k], hi.1 * c[k]] {
                            behind |= v.re <= 0.0;
                            widen(&mut re[k], v.re);
                            widen(&mut im[k], v.im);
                            widen(&mut tan[k], v.im / v.re);
                        }
                    }
                });
                if dead {
                    return None;
                }
                if behind {
                    // A fundamental turned by a quarter turn or more: nothing near-linear left.
                    return Some(DacPattern::Drifting {
                        q,
                        ratios: vec![Complex64::new(0.0, 0.0)],
                        beat,
                        phase_span: core::f64::consts::PI,
                        envelope: 0.0,
                    });
                }
                for t in &tan {
                    phase_span = phase_span.max(0.5 * (t.1.atan() - t.0.atan()));
                }
                // Every G_k has a positive real part here: |G_k| >= its smallest one.
                for k in 0..2 {
                    let diam = (re[k].1 - re[k].0).hypot(im[k].1 - im[k].0);
                    envelope = envelope.max(diam / re[k].0);
                }
                // A Coriolis window that spans many beats averages each drive over the whole
                // offset range but at most one partial beat, so its average lies within
                // 1/(T f_b) of the deviations around the mean: the ratio of two such averages
                // (every corner of the two deviation boxes, shrunk).
                let span_s = self
                    .experiment
                    .rates_dps
                    .iter()
                    .map(|&r| self.plan_point(r).window.span() / self.fs_out_hz())
                    .fold(f64::INFINITY, f64::min);
                ratios = if self.shape() == Shape::Coriolis && span_s * beat > 1.0 {
                    let shrink = 1.0 / (span_s * beat);
                    let corners = |k: usize| {
                        [(0, 0), (0, 1), (1, 0), (1, 1)].map(|(a, b)| {
                            let d = Complex64::new([re[k].0, re[k].1][a], [im[k].0, im[k].1][b])
                                - mean[k];
                            mean[k] + d * shrink
                        })
                    };
                    let (c1, c2) = (corners(0), corners(1));
                    c1.iter()
                        .flat_map(|g1| c2.iter().map(move |g2| g2 / g1))
                        .collect()
                } else {
                    // The box of every ratio the offset gives.
                    [(0, 0), (0, 1), (1, 0), (1, 1)]
                        .map(|(a, b)| {
                            Complex64::from_polar(
                                [g_abs.0, g_abs.1][a].sqrt(),
                                [g_tan.0, g_tan.1][b].atan(),
                            )
                        })
                        .to_vec()
                };
            }
            return Some(DacPattern::Drifting {
                q,
                ratios,
                beat,
                phase_span,
                envelope,
            });
        };
        let quantise = |x: f64| dac_code(x, lsb, half) * lsb;
        let mut carrier = gyroemu_nco::RotatingNco::<f64>::new(&[nco]);
        let zero = Complex64::new(0.0, 0.0);
        let (mut exact, mut rounded) = ([zero; 2], [zero; 2]);
        for _ in 0..n {
            let (c, sn) = gyroemu_core::Stage::tick(&mut carrier, ());
            let c = Complex64::new(c, sn);
            let u = [gains[0] * c.re, gains[1] * shifter.apply(c).re];
            for k in 0..2 {
                exact[k] += c.conj() * u[k];
                rounded[k] += c.conj() * quantise(u[k]);
            }
        }
        (ok(&exact) && ok(&rounded)).then_some(DacPattern::Exact(exact, rounded))
    }
}

/// Most threshold crossings [`drift_gains`] follows (about 0.1 s); finer DACs (above about
/// 19 bits at full scale) take the per-sample bound instead.
const MAX_DRIFT_CUTS: f64 = 4e6;

/// The DAC's rounding pattern of the carrier (see [`Config::dac_pattern`]).
enum DacPattern {
    /// The fundamentals of both drives over the exact period, unquantised and quantised.
    Exact([Complex64; 2], [Complex64; 2]),
    /// The nearest `q`-sample pattern, and the ratios F2/F1 of the quantised fundamentals
    /// (each relative to its unquantised one) over the drift offset (Coriolis drives only;
    /// for a Coriolis run whose window spans many beats, those its averages can take).
    Drifting {
        q: u64,
        ratios: Vec<Complex64>,
        /// How fast the offset runs through its range: `|q f_c - p fs|`, Hz.
        beat: f64,
        /// Half the range of either drive's own fundamental phase over the offset, rad.
        phase_span: f64,
        /// The largest distance between two values of either drive's fundamental over the
        /// offset, relative to its smallest magnitude (0 where not followed).
        envelope: f64,
    },
}

/// The denominator of the last continued-fraction convergent of `x` (turns per sample) not
/// above `max_q`: the carrier's phases over `q` samples are then `2 pi m / q` (m < q) plus an
/// offset that drifts by `|q x - p| < 1 / q_next` turn per pattern. `None` below 3 samples
/// (the double-frequency terms of the pattern's fundamental would not cancel).
fn nearest_pattern(x: f64, max_q: u64) -> Option<u64> {
    let (mut h0, mut h1, mut k0, mut k1) = (0u64, 1u64, 1u64, 0u64);
    let mut r = x;
    let mut best = None;
    for _ in 0..64 {
        let a = r.floor();
        let a_u = a as u64;
        let k2 = a_u.checked_mul(k1)?.checked_add(k0)?;
        if k2 > max_q {
            break;
        }
        let h2 = a_u.saturating_mul(h1).saturating_add(h0);
        (h0, h1, k0, k1) = (h1, h2, k1, k2);
        if k2 >= 3 {
            best = Some(k2);
        }
        let f = r - a;
        if f < 1e-12 {
            break;
        }
        r = 1.0 / f;
    }
    best
}

/// The quantiser's describing functions over a `q`-sample pattern as its offset drifts: the
/// drives `(a_k, beta_k)` are `a_k cos(2 pi m / q + beta_k + phi)` at sample m, offset phi
/// in [0, 2 pi / q). Between the offsets where a sample crosses a rounding threshold every
/// code is fixed, so each drive's fundamental relative to its unquantised one is
/// `e^{-j phi} c_k` there: `visit((phi_lo, e^{-j phi_lo}), (phi_hi, e^{-j phi_hi}), c)` for each
/// such interval. Every threshold
/// crossing is found (the levels between a sample's extremes over the arc), and each moves
/// one code: O(q + 2 pi a / lsb) in all.
fn drift_gains(
    drives: &[(f64, f64)],
    q: u64,
    lsb: f64,
    half: f64,
    mut visit: impl FnMut((f64, Complex64), (f64, Complex64), &[Complex64]),
) {
    use core::f64::consts::{PI, TAU};
    let w = TAU / q as f64;
    let code = |u: f64| dac_code(u, lsb, half);
    let mut cuts: Vec<(f64, usize, u64)> = Vec::new();
    for (k, &(a, beta)) in drives.iter().enumerate() {
        for m in 0..q {
            let x0 = TAU * m as f64 / q as f64 + beta;
            let (u0, u1) = (a * x0.cos(), a * (x0 + w).cos());
            let (mut lo, mut hi) = (u0.min(u1), u0.max(u1));
            let top = (x0 / PI).ceil() * PI;
            if top < x0 + w {
                let e = a * top.cos();
                (lo, hi) = (lo.min(e), hi.max(e));
            }
            for c in ((lo / lsb - 0.5).ceil() as i64)..=((hi / lsb - 0.5).floor() as i64) {
                let level = (c as f64 + 0.5) * lsb;
                if level.abs() >= a {
                    continue;
                }
                let base = (level / a).acos();
                for s in [base, -base] {
                    let phi = s + TAU * ((x0 - s) / TAU).ceil() - x0;
                    if (0.0..w).contains(&phi) {
                        cuts.push((phi, k, m));
                    }
                }
            }
        }
    }
    cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let norm: Vec<f64> = drives.iter().map(|&(a, _)| 2.0 / (q as f64 * a)).collect();
    let unit = |k: usize, m: u64| {
        Complex64::from_polar(1.0, -(TAU * m as f64 / q as f64 + drives[k].1)) * lsb * norm[k]
    };
    let ends: Vec<f64> = core::iter::once(0.0)
        .chain(cuts.iter().map(|c| c.0))
        .chain(core::iter::once(w))
        .collect();
    // Codes on the first interval, at its middle.
    let mid0 = 0.5 * (ends[0] + ends[1]);
    let mut codes: Vec<Vec<f64>> = drives
        .iter()
        .map(|&(a, beta)| {
            (0..q)
                .map(|m| code(a * (TAU * m as f64 / q as f64 + beta + mid0).cos()))
                .collect()
        })
        .collect();
    let mut sums: Vec<Complex64> = (0..drives.len())
        .map(|k| (0..q).map(|m| unit(k, m) * codes[k][m as usize]).sum())
        .collect();
    // e^{-j phi} at every interval's end, once each.
    let rot: Vec<Complex64> = ends
        .iter()
        .map(|&phi| Complex64::from_polar(1.0, -phi))
        .collect();
    // An interval narrower than this share of the offset range is one a run sits in with
    // that chance at most: two drives that are shifted copies (a quadrature drive at a
    // multiple of 4 samples per period) cross their thresholds at the same offset but for
    // the rounding of their phases, and the sliver between read a mismatch of a whole code
    // (113 mdeg stated, 0.55 measured, on a PLL's lock at 16 samples per period, 6 bits).
    let wide = |lo: f64, hi: f64| hi - lo > SLIVER * w;
    if wide(ends[0], ends[1]) {
        visit((ends[0], rot[0]), (ends[1], rot[1]), &sums);
    }
    let mut past = 0;
    for (i, &(_, k, m)) in cuts.iter().enumerate() {
        let (lo, hi) = (ends[i + 1], ends[i + 2]);
        // The code just past the crossing, read clear of its threshold: at the middle of the
        // next interval that is not a sliver. Two drives crossing at one offset (but for
        // rounding) left a zero-width interval whose middle sat on the threshold, the code
        // was not moved, and the stale code read a mismatch of a whole code from there on.
        past = past.max(i + 2);
        while past + 1 < ends.len() && !wide(lo, ends[past]) {
            past += 1;
        }
        let (a, beta) = drives[k];
        let new = code(a * (TAU * m as f64 / q as f64 + beta + 0.5 * (lo + ends[past])).cos());
        let old = &mut codes[k][m as usize];
        if new != *old {
            sums[k] += unit(k, m) * (new - *old);
            *old = new;
        }
        if wide(lo, hi) {
            visit((lo, rot[i + 1]), (hi, rot[i + 2]), &sums);
        }
    }
}

/// `R'/R` of mode `k`'s velocity under `force` at `f_hz` and the rate `w` (rad/s), 1/Hz: a
/// central difference of `ln R` over a thousandth of the narrower half-bandwidth.
fn log_slope(
    p: &gyroemu_resonator::ResonatorParams,
    w: f64,
    f_hz: f64,
    force: [Complex64; 2],
    k: usize,
) -> Complex64 {
    let d = 1e-3 * (p.mode1.f0_hz / p.mode1.q).min(p.mode2.f0_hz / p.mode2.q) / 2.0;
    let v = |f: f64| gyroemu_resonator::continuous_steady_state(p, w, f, force)[2 + k];
    (v(f_hz + d) / v(f_hz - d)).ln() / (2.0 * d)
}

/// See [`drift_gains`]: intervals of the drift offset narrower than this share of its range
/// are not weighed.
const SLIVER: f64 = 1e-9;
