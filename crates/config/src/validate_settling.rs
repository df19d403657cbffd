//! What the averaging window cannot remove, checked before any sample: the start-up left at
//! the window's start by a hand-set `experiment.settle_s` (the plant's and the stage-1
//! low-pass's together), and rate-table harmonics that the output rate aliases onto each other.

use crate::config::Config;
use crate::error::ConfigError;
use crate::rules::Rules;
use crate::validate_regime::WARN_HOLD_ERROR_MDEG;
use gyroemu_board::Shape;
use gyroemu_core::Complex64;
use gyroemu_lpf::Window;

/// Two demodulated table harmonics whose difference aliases to within this many cycles per
/// averaging window of DC cannot be told apart: the window-leak system the read-out solves is
/// then too close to singular for f64. Measured (m2tfg device, order-2 low-pass at 60 Hz,
/// fs_out = 8 x 25 Hz, 0.4 s and 4 s windows): an alias distance delta with delta T = 4e-6
/// added below 1e-4 mdeg, 4e-7 added 0.005 mdeg, 4e-8 added 6 mdeg and 4e-9 degrees (0 is
/// singular: NaN or degree-size garbage). 1e-5 keeps a factor 25 from the first harm.
pub const MIN_TABLE_ALIAS_CYCLES: f64 = 1e-5;

/// The poles `z_k` and residues `r_k` of the stage-1 Butterworth low-pass as the lpf crate
/// builds it (the bilinear transform of the analog prototype with the cutoff prewarped, so
/// `H(z) = G prod (1 + z^-1) / (1 - z_k z^-1)`), and `h[0] = G`: `h[n] = sum r_k z_k^n`
/// for `n >= 1`. The differences are formed from the analog poles, with no cancellation for
/// the narrow filters whose poles crowd z = 1.
pub(crate) fn lowpass_modes(
    order: usize,
    cutoff_hz: f64,
    fs_hz: f64,
) -> (Vec<(Complex64, Complex64)>, f64) {
    let wc = (core::f64::consts::PI * cutoff_hz / fs_hz).tan();
    let one = Complex64::new(1.0, 0.0);
    let s: Vec<Complex64> = (0..order)
        .map(|k| {
            let a = core::f64::consts::PI * (2 * k + order + 1) as f64 / (2 * order) as f64;
            Complex64::from_polar(wc, a)
        })
        .collect();
    let g = s.iter().fold(one, |g, &sk| g * (-sk / (one - sk))).re;
    let modes = s
        .iter()
        .enumerate()
        .map(|(k, &sk)| {
            let z = (one + sk) / (one - sk);
            // (1 + 1/z_k)^N / prod_{i != k} (1 - z_i / z_k), each factor from the s-plane.
            let mut r = Complex64::new(g, 0.0) * (2.0 / (one + sk)).powi(order as i32);
            for (i, &si) in s.iter().enumerate() {
                if i != k {
                    r /= 2.0 * (sk - si) / ((one - si) * (one + sk));
                }
            }
            (z, r)
        })
        .collect();
    (modes, g)
}

/// `e^x - 1` for complex `x`, accurate near 0 (the geometric ratios of slow poles sit there).
fn expm1(x: Complex64) -> Complex64 {
    let (s, c) = x.im.sin_cos();
    let h = (0.5 * x.im).sin();
    Complex64::new(x.re.exp_m1() * c - 2.0 * h * h, x.re.exp() * s)
}

/// `e^{n l}` for a complex log `l` and a possibly huge `n` (the phase wrapped first).
fn pow_log(l: Complex64, n: f64) -> Complex64 {
    let mag = (n * l.re).exp();
    if mag == 0.0 {
        return Complex64::new(0.0, 0.0);
    }
    let turns = (n * l.im / core::f64::consts::TAU).rem_euclid(1.0);
    Complex64::from_polar(mag, turns * core::f64::consts::TAU)
}

/// `sum_j w_j q^j / sum_j w_j` over `window`'s weights with `q = e^l` (`|q| <= 1`), in closed
/// form: the window's mean of a geometric sequence.
fn window_mean(window: &Window, l: Complex64) -> Complex64 {
    // sum_{j < n} e^{l j} = (e^{l n} - 1) / (e^l - 1); l = 0 gives n.
    let geo = |l: Complex64, n: u64| {
        let d = expm1(l);
        if d.norm() == 0.0 {
            Complex64::new(n as f64, 0.0)
        } else {
            expm1(l * n as f64) / d
        }
    };
    match *window {
        Window::Boxcar { n, frac } => (geo(l, n) + pow_log(l, n as f64) * frac) / (n as f64 + frac),
        Window::Hann { n } => {
            // sin^2(pi (j + 1/2)/n) = 1/2 - (e^{j 2 pi (j + 1/2)/n} + conj) / 4.
            let step = core::f64::consts::TAU / n as f64;
            let half = Complex64::from_polar(1.0, 0.5 * step);
            let j = Complex64::new(0.0, step);
            let sum = 0.5 * geo(l, n) - 0.25 * (half * geo(l + j, n) + half.conj() * geo(l - j, n));
            sum / if n == 1 { 1.0 } else { 0.5 * n as f64 }
        }
    }
}

/// The start-up a point's read-out keeps, per unit of the stage-1 input: the input samples
/// its window averages are `n_j = (n_settle + j) M + M - 1`.
struct StartUp<'a> {
    modes: &'a [(Complex64, Complex64)],
    window: Window,
    n0: f64,
    m: f64,
    /// ln of the plant's start-up decay per input sample, -1/(tau fs).
    ln_a: f64,
}

impl StartUp<'_> {
    /// The low-pass's own start-up on a tone `e^{j w n}` applied from sample 0, read at `w_read`
    /// (rad per input sample): exactly `-sum_{k > n} h_k e^{j w (n - k)}`, demodulated by
    /// `e^{-j w_read n}` and averaged over the window (each pole is a geometric sequence).
    fn lowpass(&self, w: f64, w_read: f64) -> Complex64 {
        let jw = Complex64::new(0.0, w);
        let mut sum = Complex64::new(0.0, 0.0);
        for &(z, r) in self.modes {
            let lz = z.ln();
            // e^{jwn} sum_{k > n} r z^k e^{-jwk} = r z^n (z e^{-jw}) / (1 - z e^{-jw}), so the
            // demodulated start-up of this pole is -c z^n e^{-j w_read n}.
            let c = r * (lz - jw).exp() / -expm1(lz - jw);
            let l = lz - Complex64::new(0.0, w_read);
            sum -= c * pow_log(l, self.n0) * window_mean(&self.window, l * self.m);
        }
        sum
    }

    /// A bound on the plant's start-up after the low-pass: the plant starts at rest, so its
    /// input differs from the steady one by a transient of at most the steady amplitude times
    /// `a^n` (`a = e^{-1/(tau fs)}`), whose output is at most `sum_k |h_k| a^{n-k}`. The first
    /// `k0` taps are the built filter's own (`head = sum_{k <= k0} |h_k| a^{k0-k}`, see
    /// [`impulse_head`]); beyond, `|h_k| <= sum |r_i| rho_i^k` sums in closed form to
    /// `sum |r_i| rho_i^(k0+1) (a^n' - rho_i^n') / (a - rho_i)`, `n' = n - k0`; averaged over
    /// the window.
    fn plant(&self, k0: f64, head: f64) -> f64 {
        let n0 = self.n0 - k0;
        let mean = |ln_q: f64| {
            (pow_log(Complex64::new(ln_q, 0.0), n0)
                * window_mean(&self.window, Complex64::new(ln_q * self.m, 0.0)))
            .re
        };
        let mut total = head * mean(self.ln_a);
        for &(z, r) in self.modes {
            let ln_rho = z.norm().ln();
            let mut ln_a = self.ln_a;
            // Equal decays: a slightly slower plant only raises the bound.
            if (ln_a - ln_rho).abs() < 1e-6 * ln_rho.abs() {
                ln_a = ln_rho * (1.0 - 1e-3);
            }
            let (a, rho) = (ln_a.exp(), ln_rho.exp());
            let far = (ln_rho * (k0 + 1.0)).exp();
            total += r.norm() * far * (mean(ln_a) - mean(ln_rho)) / (a - rho);
        }
        total.max(0.0)
    }

    /// The plant's start-up bound `b_j` (the per-sample form of [`StartUp::plant`]) at each of
    /// the window's samples, weighted by the window and folded onto `bins` equal bins of the
    /// table period (by the table's phase at the sample): entry `i` is the window's mean of
    /// `b` over the samples whose phase lies in `[i, i + 1) / bins` of a turn.
    fn plant_fold(
        &self,
        k0: f64,
        head: f64,
        cycles_per_sample: f64,
        bins: usize,
    ) -> Option<Vec<f64>> {
        // Beyond this many samples (a few ms each million) the caller weighs the window's
        // mean against the kernel's largest value instead.
        if self.window.samples() > 1 << 22 {
            return None;
        }
        let m = self.m;
        // b at the window's sample j, n' = n0 + j M - k0 (see `plant`): the head's a^{n'} and,
        // per pole, c (a^{n'} - rho^{n'}) / (a - rho); each a geometric sequence in j.
        let n1 = self.n0 - k0;
        let mut head_term = head * (self.ln_a * n1).exp();
        let head_step = (self.ln_a * m).exp();
        let mut terms: Vec<[f64; 4]> = self
            .modes
            .iter()
            .map(|&(z, r)| {
                let ln_rho = z.norm().ln();
                let mut ln_a = self.ln_a;
                if (ln_a - ln_rho).abs() < 1e-6 * ln_rho.abs() {
                    ln_a = ln_rho * (1.0 - 1e-3);
                }
                let c = r.norm() * (ln_rho * (k0 + 1.0)).exp() / (ln_a.exp() - ln_rho.exp());
                [
                    c * (ln_a * n1).exp(),
                    c * (ln_rho * n1).exp(),
                    (ln_a * m).exp(),
                    (ln_rho * m).exp(),
                ]
            })
            .collect();
        let mut folded = vec![0.0; bins];
        let mut wsum = 0.0;
        let phase0 = (cycles_per_sample * self.n0).rem_euclid(1.0);
        let dphase = (cycles_per_sample * m).rem_euclid(1.0);
        for j in 0..self.window.samples() {
            let w = self.window.weight(j);
            wsum += w;
            let b = (head_term + terms.iter().map(|t| t[0] - t[1]).sum::<f64>()).max(0.0);
            let phase = (phase0 + dphase * j as f64).rem_euclid(1.0);
            folded[((phase * bins as f64) as usize).min(bins - 1)] += w * b;
            head_term *= head_step;
            for t in terms.iter_mut() {
                t[0] *= t[2];
                t[1] *= t[3];
            }
        }
        if wsum > 0.0 {
            for f in folded.iter_mut() {
                *f /= wsum;
            }
        }
        Some(folded)
    }
}

/// Most taps of the built low-pass [`impulse_head`] runs: a bound on validation's own work.
const MAX_HEAD_TAPS: f64 = 1.5e6;

/// The built stage-1 filter's impulse response, run for `k0 + 1` taps (`k0` at most `n0`, the
/// first averaged sample, and 40 time constants of the cutoff): `(k0, sum_{k <= k0} |h_k|
/// a^{k0-k})`. Its exact taps keep the plant's bound from the modal envelope's looseness (10x
/// at order 4, where the poles still cancel); by 40 time constants only the slowest pair is
/// left (order 8's next one has decayed by e^-22), and the envelope `sum |r_i| rho_i^k` of a
/// single pair is its own peak. (200 time constants ran five times the taps for no tighter bound.)
fn impulse_head(
    design: gyroemu_lpf::LowPassDesign,
    fs: f64,
    cutoff: f64,
    n0: f64,
    ln_a: f64,
) -> (f64, f64) {
    use gyroemu_core::Stage;
    let Ok(mut lp) = gyroemu_lpf::LowPass::<f64>::new(design, fs) else {
        return (0.0, 0.0);
    };
    let k0 = n0
        .min((40.0 * fs / (core::f64::consts::TAU * cutoff)).ceil())
        .min(MAX_HEAD_TAPS);
    let a = ln_a.exp();
    let mut head = 0.0;
    for k in 0..=(k0 as u64) {
        head = head * a + lp.tick(if k == 0 { 1.0 } else { 0.0 }).abs();
    }
    (k0, head)
}

impl Config {
    /// The start-up the settling leaves in the averaging windows, hand-set or the default
    /// (which once went unchecked: an eighth-order low-pass left tens of degrees in a rate
    /// table's reading), bounded per point from the plant's decay and the low-pass's exact
    /// start-up; a warning with the bound, or a refusal when the start-up can be as large as
    /// the signal read.
    pub(crate) fn validate_settling(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let settle = self.settle_s();
        let set = self.experiment.settle_s.is_some();
        if !p.clean(&[
            "experiment.settle_s",
            "experiment.average_s",
            "experiment.table_freq_hz",
            "experiment.rate_table",
        ]) {
            return;
        }
        let Some((worst, at, table_lag, (exact, exact_at))) = self.settling_bound() else {
            return;
        };
        let tau = self.slowest_tau_s();
        let fc = self.lpf_cutoff_hz();
        let settling = if set {
            format!("experiment.settle_s = {settle}")
        } else {
            format!("the default settling ({settle:.4} s; experiment.settle_s not set)")
        };
        let what = format!(
            "{settling} leaves the plant's start-up (tau = {tau} s) and the stage-1 low-pass's (order {} at {fc} Hz) in the averaging window",
            self.board.lpf_order
        );
        let fix = if set {
            format!(
                "raise settle_s (the default, {:.4} s here, is 16 tau + 40/(2 pi lpf_cutoff_hz), longer above order 4) or remove the key",
                self.default_settle_s()
            )
        } else {
            // Each low-pass e-fold and each plant tau divides what is left by e.
            let fold = self.lowpass_efold_s();
            format!(
                "set experiment.settle_s longer than this default: each {fold:.4} s more (an e-fold of the low-pass's slowest pole, 1/(2 pi lpf_cutoff_hz sin(pi/(2 lpf_order)))) divides the low-pass's part by e, each tau = {tau:.4} s the plant's"
            )
        };
        // The low-pass's own start-up on the sidebands read is exact (no bound): once it is as
        // large as what the filter passes of them, the phase read is undetermined and no bound
        // on it exists, so the run is refused. The rest is a bound, stated in a warning.
        if exact >= 1.0 || exact.is_nan() {
            p.push(ConfigError::key(
                "experiment.settle_s",
                settle,
                format!("{what}: at {exact_at} deg/s the low-pass's start-up left in the window is {exact:.2e} of the sideband it passes, so the measured phase is undetermined; {fix}"),
            ));
            return;
        }
        let mdeg = worst.min(1.0).asin().to_degrees() * 1e3;
        let mdeg = match self.shape() {
            // Each Coriolis phase is the difference of two read-outs, each with a start-up.
            Shape::Coriolis => 2.0 * mdeg,
            _ => mdeg,
        };
        if mdeg > WARN_HOLD_ERROR_MDEG {
            let lag = table_lag
                .map(|l: f64| format!(" (the table lag by up to {:.3e} deg)", l.to_degrees()))
                .unwrap_or_default();
            let size = if worst < 1.0 {
                format!("by up to {mdeg:.3e} mdeg{lag}")
            } else {
                // asin saturates: beyond a relative 1 the bound says nothing smaller than this.
                format!("by up to {mdeg:.3e} mdeg or more (the start-up bound reaches the signal's size: do not trust the reading){lag}")
            };
            warnings.push(format!(
                "{what}: it can move the measured phase {size} (worst at {at} deg/s); {fix}"
            ));
        }
    }

    /// The largest relative start-up of a read phasor over the points (for a rate table, of
    /// the phase amplitude read, rad), the rate it is at, for a rate table the lag bound (rad)
    /// it implies, and the largest exact low-pass start-up on a rotating run's sidebands,
    /// relative, with its rate; `None` if the chain cannot be built.
    #[allow(clippy::type_complexity)]
    fn settling_bound(&self) -> Option<(f64, f64, Option<f64>, (f64, f64))> {
        let chain = gyroemu_board::ChainResponse::new(&self.board_params()).ok()?;
        let fs = self.fs_hz();
        let (modes, _) = lowpass_modes(self.board.lpf_order, self.lpf_cutoff_hz(), fs);
        let m = self.decimation() as f64;
        let n0 = self.n_settle_out() as f64 * m + m - 1.0;
        let w_of = |f: f64| core::f64::consts::TAU * f / fs;
        // The mixer's 2 f_c product starts up with the rest (its start-up is tiny: the
        // low-pass stops it).
        let image = -w_of(2.0 * self.carrier_hz());
        let (mut worst, mut at, mut lag) = (0.0f64, f64::NAN, None);
        let (mut exact, mut exact_at) = (0.0f64, f64::NAN);
        let ln_a = -1.0 / (self.slowest_tau_s() * fs);
        // The same for every point: computed once (it runs up to MAX_HEAD_TAPS taps).
        let (k0, head) = impulse_head(self.lowpass_design(), fs, self.lpf_cutoff_hz(), n0, ln_a);
        // Every table point has the same window: the plant's Dirichlet-weighted bound once.
        let mut table_fold: Option<Option<Vec<f64>>> = None;
        // So are the unit phasors of the envelope grid and of the kernel's bins (N is the
        // config's): formed once, not per point and mode (the same angles, the same bits).
        let mut grid_memo: Option<(usize, Vec<Complex64>)> = None;
        let mut bins_memo: Option<(usize, Vec<Complex64>)> = None;
        let mut lp_memo: Option<((Window, usize), Vec<f64>)> = None;
        for rate in self.emulated_rates_dps() {
            let su = StartUp {
                modes: &modes,
                window: self.plan_point(rate).window,
                n0,
                m,
                ln_a,
            };
            let plant = su.plant(k0, head);
            let (e, l) = match self.shape() {
                Shape::Coriolis => {
                    // The low-pass's start-up on DC scales every point's phasor alike: the
                    // phase against the zero-rate reference keeps none of it.
                    let kept = (Complex64::new(1.0, 0.0) + su.lowpass(0.0, 0.0)).norm();
                    ((plant + su.lowpass(image, 0.0).norm()) / kept, None)
                }
                Shape::Rotating => {
                    // z = A/2 (e^{j Omega t} + e^{-j Omega t}) (THEORY section 6); each
                    // sideband read against |L(fm)| A/2, psi is half their phase difference.
                    let wm = w_of(rate.abs() / 360.0);
                    let mut e = 0.0;
                    for w_read in [wm, -wm] {
                        let left: f64 = [wm, -wm, image + wm, image - wm]
                            .iter()
                            .map(|&w| 0.5 * su.lowpass(w, w_read).norm())
                            .sum();
                        let steady =
                            0.5 * chain.lowpass(w_read * fs / core::f64::consts::TAU).norm();
                        if left / steady > exact || (left / steady).is_nan() {
                            (exact, exact_at) = (left / steady, rate);
                        }
                        e += 0.5 * ((left + plant) / steady).min(1.0);
                    }
                    (e, None)
                }
                Shape::RateTable { freq_hz } => {
                    let n = self.table_harmonics() as i64;
                    let nu = n as usize;
                    let tau = core::f64::consts::TAU;
                    let env = self.driven_device().rate_table_envelopes(
                        rate.abs() * core::f64::consts::PI / 180.0,
                        freq_hz,
                        nu,
                    );
                    let inv_l: Vec<Complex64> = (-n..=n)
                        .map(|r| 1.0 / chain.lowpass(r as f64 * freq_hz))
                        .collect();
                    let bins = 64 * (2 * nu + 1);
                    let fold = table_fold
                        .get_or_insert_with(|| su.plant_fold(k0, head, freq_hz / fs, bins))
                        .as_deref();
                    let mut amp_err: f64 = 0.0;
                    let mut pointwise: f64 = 0.0;
                    for z in &env {
                        // z(theta) on a fine grid: its floor, and g = 1/z's harmonics
                        // -(N+1) ..= N+1 (smooth while z stays off 0: its higher ones fall
                        // geometrically; 64 (N+1) points leave their fold-over negligible).
                        let total: f64 = z.iter().map(|v| v.norm()).sum();
                        let steps = 64 * (nu + 1);
                        // e^{j k theta_t} for k = -(N+1) ..= N+1 (index k + N + 1): z's terms
                        // take |k| <= N, g's harmonic m takes k = -m.
                        let row = 2 * nu + 3;
                        // (Its length is its key: 64 (N + 1) (2N + 3) grows with N.)
                        let grid = memo(&mut grid_memo, steps * row, || {
                            (0..steps)
                                .flat_map(|t| {
                                    let th = tau * t as f64 / steps as f64;
                                    (-(n + 1)..=n + 1)
                                        .map(move |k| Complex64::from_polar(1.0, k as f64 * th))
                                })
                                .collect()
                        });
                        let at = |t: usize, k: i64| grid[t * row + (k + n + 1) as usize];
                        let zs: Vec<Complex64> = (0..steps)
                            .map(|t| {
                                z.iter()
                                    .enumerate()
                                    .map(|(i, v)| v * at(t, i as i64 - n))
                                    .sum::<Complex64>()
                            })
                            .collect();
                        let floor = zs.iter().map(|v| v.norm()).fold(f64::INFINITY, f64::min);
                        if floor.is_nan() || floor <= 0.0 {
                            (amp_err, pointwise) = (f64::INFINITY, f64::INFINITY);
                            break;
                        }
                        let g = |m: i64| -> Complex64 {
                            zs.iter()
                                .enumerate()
                                .map(|(t, v)| at(t, -m) / v)
                                .sum::<Complex64>()
                                / steps as f64
                        };
                        let gs: Vec<Complex64> = (-(n + 1)..=n + 1).map(g).collect();
                        let g_at = |m: i64| gs[(m + n + 1) as usize];
                        // The low-pass's own start-up, exact per tone and per harmonic read:
                        // |d_n| <= left_n / |L_n| in the rebuilt envelope.
                        // |L's start-up| of harmonic i (and its image) read at harmonic
                        // `read`: the window's and N's alone, so formed once for every
                        // point and mode that share the window.
                        let nz = z.len();
                        let lp = memo(&mut lp_memo, (su.window, nz * (2 * nu + 1)), || {
                            (-n..=n)
                                .flat_map(|read| {
                                    let w_read = w_of(read as f64 * freq_hz);
                                    let su = &su;
                                    (0..nz).map(move |i| {
                                        let w = w_of((i as i64 - n) as f64 * freq_hz);
                                        su.lowpass(w, w_read).norm()
                                            + su.lowpass(image - w, w_read).norm()
                                    })
                                })
                                .collect()
                        });
                        let d: Vec<f64> = (-n..=n)
                            .map(|read| {
                                let row = &lp[(read + n) as usize * nz..][..nz];
                                let left: f64 = z.iter().zip(row).map(|(v, l)| v.norm() * l).sum();
                                left * inv_l[(read + n) as usize].norm()
                            })
                            .collect();
                        // Pointwise |dz| / |z| (the old bound): the second-order remainder,
                        // and the whole bound once the first order no longer holds.
                        let e = (total * plant * inv_l.iter().map(|l| l.norm()).sum::<f64>()
                            + d.iter().sum::<f64>())
                            / floor;
                        pointwise = pointwise.max(e);
                        let a = if e < 0.5 {
                            // The fundamental of delta phi = Im(dz g) (+ at most |u|^2, u =
                            // dz/z, as |arg(1 + u) - Im u| <= |u|^2 for |u| <= 1/2) has
                            // amplitude <= |(dz g)_1| + |(dz g)_-1|. Low-pass part:
                            // sum_n |d_n| |g_{+-1-n}|. Plant part: dz_n = <dy e^{-j n w t}> / L_n
                            // with |dy| <= total b(t), so (dz g)_{+-1} = <dy K_{+-}(w t)>,
                            // K_{+-}(x) = sum_n g_{+-1-n} e^{-j n x} / L_n: charged once
                            // against the folded b, not per harmonic.
                            let lp: f64 = (-n..=n)
                                .map(|r| {
                                    d[(r + n) as usize] * (g_at(1 - r).norm() + g_at(-1 - r).norm())
                                })
                                .sum();
                            let slope: f64 = (-n..=n)
                                .map(|r| {
                                    let l = inv_l[(r + n) as usize].norm();
                                    r.abs() as f64 * l * (g_at(1 - r).norm() + g_at(-1 - r).norm())
                                })
                                .sum();
                            let half_bin = 0.5 * tau / bins as f64;
                            // A window too long to fold: its whole mean in every bin's place.
                            let uniform;
                            let folded = fold.is_some();
                            let fold: &[f64] = match fold {
                                Some(f) => f,
                                None => {
                                    uniform = vec![plant; bins];
                                    &uniform
                                }
                            };
                            // K_{+-} at each bin: g_{+-1-r} / L_r does not depend on the
                            // bin, and both share its phasors e^{-j r x} (the same products
                            // and sums as forming each term whole, so the same bits).
                            let coef = |s: i64| -> Vec<Complex64> {
                                (-n..=n)
                                    .map(|r| g_at(s - r) * inv_l[(r + n) as usize])
                                    .collect()
                            };
                            let (plus, minus) = (coef(1), coef(-1));
                            let width = plus.len();
                            let rots = memo(&mut bins_memo, bins * width, || {
                                (0..bins)
                                    .flat_map(|b| {
                                        let x = tau * (b as f64 + 0.5) / bins as f64;
                                        (-n..=n).map(move |r| {
                                            Complex64::from_polar(1.0, -(r as f64) * x)
                                        })
                                    })
                                    .collect()
                            });
                            let kernel = fold.iter().enumerate().filter(|&(_, &f)| f > 0.0).map(
                                |(b, &f)| {
                                    let rot = &rots[b * width..][..width];
                                    let k = |c: &[Complex64]| {
                                        c.iter()
                                            .zip(rot)
                                            .map(|(a, p)| a * p)
                                            .sum::<Complex64>()
                                            .norm()
                                    };
                                    f * (k(&plus) + k(&minus) + slope * half_bin)
                                },
                            );
                            let plant_part: f64 = if folded {
                                kernel.sum()
                            } else {
                                kernel.fold(0.0, f64::max)
                            };
                            total * plant_part + lp + 4.0 / core::f64::consts::PI * e * e
                        } else {
                            // The fundamental of a function bounded by x is at most 4x/pi.
                            4.0 / core::f64::consts::PI * e.min(1.0).asin()
                        };
                        amp_err = amp_err.max(a);
                    }
                    let amp = self
                        .driven_device()
                        .rate_table_response(rate.abs() * core::f64::consts::PI / 180.0, freq_hz)
                        .0
                        .into_iter()
                        .fold(f64::INFINITY, |m, a| m.min(a.abs()));
                    // Stated as asin of what is returned (1 and beyond: "or more").
                    let stated = if pointwise >= 1.0 || amp_err >= 0.5 * core::f64::consts::PI {
                        pointwise.max(1.0)
                    } else {
                        amp_err.sin()
                    };
                    (stated, Some((amp_err / amp).min(core::f64::consts::PI)))
                }
            };
            if e > worst || e.is_nan() {
                (worst, at) = (e, rate);
                if l.is_some() {
                    lag = l;
                }
            }
        }
        Some((worst, at, lag, (exact, exact_at)))
    }

    /// Rate-table runs: two demodulated harmonics `n` and `n + d` (`d <= 2N`) whose frequency
    /// difference `d f_t` the output rate aliases to near DC. Within
    /// [`MIN_TABLE_ALIAS_CYCLES`] of the window they read as one: the window-leak system the
    /// read-out solves is singular (NaN, or finite garbage with exit 0), refused. Within one
    /// cycle it is ill-conditioned, and the read-out divides each harmonic by the low-pass's
    /// response there, so what the leak solve gets wrong is amplified: warned. A 100.01 Hz
    /// table at a 400 Hz output rate, 0.2 s, behind a 150 Hz low-pass read 117.6 deg where the
    /// theory is 31.8 deg, exit 0 and unwarned (0.008 cycles apart; 4.1 deg at 0.024 cycles,
    /// 1.5e-3 deg at 0.04, 4e-6 deg at 0.08).
    pub(crate) fn validate_table_alias(&self, p: &mut Rules, warnings: &mut Vec<String>) {
        let Shape::RateTable { freq_hz: ft } = self.shape() else {
            return;
        };
        if !p.clean(&["experiment.table_freq_hz", "experiment.average_s"]) {
            return;
        }
        let n = self.table_harmonics();
        let fs_out = self.fs_out_hz();
        // Every table point averages whole table periods of the same span.
        let Some(rate) = self.experiment.rates_dps.first() else {
            return;
        };
        let t = self.plan_point(*rate).window.span() / fs_out;
        // Each pair's alias distance: the first one refused, else the first one warned.
        let pairs: Vec<(usize, f64, f64)> = (1..=2 * n)
            .filter_map(|d| {
                let f = d as f64 * ft;
                let k = (f / fs_out).round();
                (k >= 1.0).then(|| (d, k, (f - k * fs_out).abs()))
            })
            .collect();
        let first = |below: f64| {
            pairs
                .iter()
                .copied()
                .find(|&(_, _, delta)| delta * t < below)
        };
        if let Some((d, k, delta)) = first(MIN_TABLE_ALIAS_CYCLES) {
            // Removing the key helps only when the derived decimation is another one.
            let derived = {
                let mut c = self.clone();
                c.board.decimation = None;
                c.decimation()
            };
            let derived_note = if derived == self.decimation() {
                String::new()
            } else {
                format!(", or remove the key for the derived one ({derived})")
            };
            p.push(ConfigError::key(
                "board.decimation",
                self.decimation(),
                format!(
                    "the output rate fs_hz/decimation = {fs_out} Hz is {} x {d} x experiment.table_freq_hz ({ft} Hz){}: at the output instants table harmonics n and n + {d} are the same frequency, and the read-out demodulates harmonics -{n} ..= {n}, so it cannot tell them apart (their alias distance {delta:.3e} Hz is below {MIN_TABLE_ALIAS_CYCLES:e} cycles of the {t} s window); choose a decimation whose output rate is not within that of a multiple of table_freq_hz / k for k <= {}{}, or change table_freq_hz",
                    if k == 1.0 { "1".to_string() } else { format!("1/{k}") },
                    if delta == 0.0 { "" } else { " (nearly)" },
                    2 * n,
                    derived_note
                ),
            ));
        } else if let Some((d, _, delta)) = first(1.0).filter(|_| p.clean(&["board.decimation"])) {
            let cycles = delta * t;
            warnings.push(format!(
                "board.decimation = {}: the output rate {fs_out} Hz aliases table harmonics n and n + {d} ({d} x {ft} Hz) to {cycles:.3e} cycles of the {t} s window from each other: the read-out parts them by solving the window's leak, which is then ill-conditioned, and what it gets wrong is divided by the low-pass's response at each harmonic, so the readings can be off by degrees with no other warning (a 100.01 Hz table at 400 Hz read 117.6 deg for 31.8 at 0.008 cycles); choose a decimation whose output rate is not near a multiple of table_freq_hz / k for k <= {}, or average longer",
                self.decimation(),
                2 * n
            ));
        }
    }
}

/// The vector kept in `slot` if it was made for `key`, else `make()`'s, kept there for `key`.
fn memo<K: PartialEq, T>(
    slot: &mut Option<(K, Vec<T>)>,
    key: K,
    make: impl FnOnce() -> Vec<T>,
) -> &[T] {
    if slot.as_ref().is_none_or(|(k, _)| *k != key) {
        *slot = Some((key, make()));
    }
    slot.as_ref().map_or(&[], |(_, v)| v.as_slice())
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyroemu_core::Stage;
    use gyroemu_lpf::{LowPass, LowPassDesign};

    /// A kept vector is reused for its key and replaced for another.
    #[test]
    fn memo_keeps_a_vector_for_its_key_only() {
        let mut slot = None;
        assert_eq!(memo(&mut slot, 2, || vec![1, 2]), &[1, 2]);
        assert_eq!(memo(&mut slot, 2, || vec![7, 7]), &[1, 2]);
        assert_eq!(memo(&mut slot, 3, || vec![3, 4, 5]), &[3, 4, 5]);
        assert_eq!(slot, Some((3, vec![3, 4, 5])));
    }

    /// The modal impulse response is the built filter's (run on an impulse), every order, a
    /// narrow and a wide cutoff: the bound rests on the real filter, not an analog model.
    #[test]
    fn the_modes_give_the_built_filters_impulse_response() {
        let fs = 240_000.0;
        for order in 1..=8 {
            for fc in [3.0, 2000.0] {
                let (modes, h0) = lowpass_modes(order, fc, fs);
                let mut lp = LowPass::<f64>::new(
                    LowPassDesign::Butterworth {
                        order,
                        cutoff_hz: fc,
                    },
                    fs,
                )
                .unwrap();
                let n_max = (20.0 * fs / (core::f64::consts::TAU * fc)) as u64;
                let mut peak: f64 = 0.0;
                let mut worst: f64 = 0.0;
                for n in 0..n_max {
                    let h = lp.tick(if n == 0 { 1.0 } else { 0.0 });
                    let modal = if n == 0 {
                        h0
                    } else {
                        modes.iter().map(|&(z, r)| (r * z.powf(n as f64)).re).sum()
                    };
                    peak = peak.max(h.abs());
                    worst = worst.max((h - modal).abs());
                }
                assert!(
                    worst < 1e-7 * peak,
                    "order {order}, {fc} Hz: {worst:e} of {peak:e}"
                );
            }
        }
    }

    /// The closed-form window mean is the direct weighted sum.
    #[test]
    fn the_window_mean_is_the_weighted_sum() {
        let l = Complex64::new(-1e-3, 0.37);
        for w in [
            Window::Boxcar { n: 500, frac: 0.3 },
            Window::Hann { n: 500 },
        ] {
            let (mut s, mut ws) = (Complex64::new(0.0, 0.0), 0.0);
            for j in 0..w.samples() {
                s += w.weight(j) * (l * j as f64).exp();
                ws += w.weight(j);
            }
            let d = (window_mean(&w, l) - s / ws).norm();
            assert!(d < 1e-12, "{w:?}: {d:e}");
        }
    }
}
