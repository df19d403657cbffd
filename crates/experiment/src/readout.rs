//! From the board's averages to phases: the estimators of THEORY.md section 6, the chain terms
//! compensated from the board's own stage responses, the exact theory beside every point, and
//! the paper's best linear fit.

use crate::fit::{fit_line, unwrapped_along, unwrapped_along_theory, LineFit};
use crate::leaks::Stage2Leaks;
use gyroemu_board::{
    unleak_sidebands, unleak_table_harmonics, ChainResponse, Health, LaneResult, Point, Shape,
};
use gyroemu_config::Config;
use gyroemu_core::{Complex64, ParamError};
use gyroemu_lpf::Window;
use gyroemu_mixer::{
    paper_i_channel_psi_rad, phase_fundamental_checked, phase_lag_rad, sideband_estimate, wrap_pi,
    Mode, NoFundamental, MAX_TABLE_HARMONIC,
};
use serde::Serialize;

const DEG: f64 = core::f64::consts::PI / 180.0;

/// One operating point's result. Phases in degrees, lag positive.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PointResult {
    /// Rate (rotation, excitation, or rate-table amplitude), deg/s.
    pub rate_dps: f64,
    /// Measured phase per mode: Coriolis shift against zero rate, compensated psi (rotating),
    /// or the amplitude of the phase's fundamental at the table frequency (rate table).
    pub phase_deg: [f64; 2],
    /// Exact theory for the same quantity.
    pub theory_deg: [f64; 2],
    /// Rotating: the paper-style real-I-channel estimate, with the same compensation.
    pub paper_i_deg: Option<[f64; 2]>,
    /// Rotating: psi before compensation of the chain terms.
    pub raw_psi_deg: Option<[f64; 2]>,
    /// Rotating: the carrier phase alpha of each mode.
    pub alpha_deg: Option<[f64; 2]>,
    /// Coriolis: the paper's single real mixer DC reading (mixing with the mode's own drive), V.
    pub single_mixer_dc_v: Option<[f64; 2]>,
    /// Rate table: lag of the phase response behind the table, degrees (theory beside).
    pub table_lag_deg: Option<[f64; 2]>,
    /// Rate table: exact theory of that lag per mode (the plant's periodic steady state).
    pub table_lag_theory_deg: Option<[f64; 2]>,
    /// Averaging time actually used, s.
    pub averaged_s: f64,
}

/// What the rotating readout compensated at one point, millidegrees (added to psi by the chain).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Compensation {
    /// The point's rate, deg/s.
    pub rate_dps: f64,
    /// TIA: (arg H(f0 - fm) - arg H(f0 + fm))/2, removed from psi.
    pub tia_mdeg: f64,
    /// DAC zero-order hold (about Omega Ts / 2), removed from psi.
    pub dac_hold_mdeg: f64,
    /// Stage-1 low-pass, -arg L(fm): it delays the envelope but not the Omega references
    /// (taken at the decimated instants), so it is removed from psi from the filter's exact
    /// discrete response.
    pub lowpass_mdeg: f64,
    /// Pipeline delay between drive and reference, samples (0: both use the same sample).
    pub pipeline_delay_samples: u64,
}

/// A whole sweep's results and how they were obtained.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepResult {
    /// The experiment.
    pub shape: Shape,
    /// One result per listed rate.
    pub points: Vec<PointResult>,
    /// Rotating: what was compensated at each point.
    pub compensation: Vec<Compensation>,
    /// Fit of the measured phase against the listed rates, per mode.
    pub fit: [LineFit; 2],
    /// Small-angle theory slope per mode, degrees per deg/s.
    pub theory_slope_deg_per_dps: [f64; 2],
    /// Settling before the averages, s.
    pub settle_s: f64,
    /// Sample rate, Hz.
    pub fs_hz: f64,
    /// Decimated rate, Hz.
    pub fs_out_hz: f64,
    /// Input samples emulated in all (per lane group).
    pub samples: u64,
    /// Operating-point samples emulated (samples times the points each group carries).
    pub point_samples: u64,
    /// The converters' and rails' counts, summed over every emulated point.
    pub health: Health,
    /// Why a phase was refused (set to NaN): a dead channel, a non-finite read-out. A sweep
    /// with problems has no trustworthy number and the program exits non-zero.
    pub problems: Vec<String>,
    /// What the user should know but that does not void a phase (clipping, saturation).
    pub warnings: Vec<String>,
}

impl SweepResult {
    /// Largest |measured - theory| of one mode over the points, millidegrees; NaN when any
    /// point's is (a refused phase is never skipped into a clean-looking maximum).
    pub fn max_abs_error_mdeg(&self, mode: usize) -> f64 {
        self.points
            .iter()
            .map(|p| ((p.phase_deg[mode] - p.theory_deg[mode]) * 1e3).abs())
            .fold(0.0, |a, b| {
                if a.is_nan() || b.is_nan() {
                    f64::NAN
                } else {
                    a.max(b)
                }
            })
    }
}

/// The channels of one point that carry no signal: `(mode, reason)`. A drive the DAC put out
/// as zeros on every sample voids both modes (each phase is read against both drives).
fn dead_channels(cfg: &Config, lr: &LaneResult) -> Vec<(usize, String)> {
    let h = &lr.health;
    let b = &cfg.board;
    let mut dead = Vec::new();
    for k in 0..2 {
        if b.dac_bits.is_some() && h.samples > 0 && h.dac_zero[k] == h.samples {
            let key = ["drive.f1", "drive.f2"][k];
            for md in 0..2 {
                dead.push((
                    md,
                    format!(
                        "the DAC put out every sample of drive {} as 0 ({key} is below half an LSB of board.dac_full_scale / 2^(board.dac_bits - 1)): raise {key} or board.dac_bits, or lower board.dac_full_scale",
                        k + 1
                    ),
                ));
            }
        }
        if b.adc_bits.is_some() && h.samples > 0 && h.adc_zero[k] == h.samples {
            dead.push((
                k,
                format!(
                    "the ADC put out every sample of mode {} as 0 (the TIA output is below half an LSB): raise board.tia_gain_ohm or board.adc_bits, or lower board.adc_full_scale_v",
                    k + 1
                ),
            ));
        }
    }
    let zero = Complex64::new(0.0, 0.0);
    for k in 0..2 {
        let silent = match cfg.shape() {
            Shape::Coriolis => lr.z[k] == zero,
            Shape::RateTable { .. } => lr.table_z[k].iter().all(|&v| v == zero),
            Shape::Rotating => lr.c[k] == zero && lr.s[k] == zero,
        };
        if silent && !dead.iter().any(|d| d.0 == k) {
            dead.push((
                k,
                format!(
                    "mode {}'s read-out averaged to exactly 0 (no signal reached the mixer): check the drive amplitudes, device.transduction_a_s_per_m and board.tia_gain_ohm",
                    k + 1
                ),
            ));
        }
    }
    dead
}

/// The clipping a point's counts show, as warnings naming the stage and its setting, and
/// which phases it spoils. On the sense side (TIA rails, ADC): the clipped points', or every
/// point's where each is read against a zero-rate reference that clipped (`coriolis`). A
/// clipped drive (DAC): the points it clipped at, and in a Coriolis sweep every point, whose
/// phases all depend on the two drives' ratio (the drive is the same at every rate).
fn clipping_warnings(h: &Health, points: &[(f64, bool, Health)], coriolis: bool) -> Vec<String> {
    let pct = |n: u64| 100.0 * n as f64 / h.samples.max(1) as f64;
    let mut w = Vec::new();
    for (what, counts, setting, of) in [
        (
            "the DAC clipped",
            h.dac_clipped,
            "board.dac_full_scale",
            (|h: &Health| h.dac_clipped) as fn(&Health) -> [u64; 2],
        ),
        (
            "the TIA sat on its rails for",
            h.tia_railed,
            "board.tia_rail_v",
            |h: &Health| h.tia_railed,
        ),
        (
            "the ADC clipped",
            h.adc_clipped,
            "board.adc_full_scale_v",
            |h: &Health| h.adc_clipped,
        ),
    ] {
        for (k, &n) in counts.iter().enumerate() {
            if n > 0 {
                // Which points: the others' numbers are clean (in one run only 25 to 100 deg/s
                // of seven points railed, and only they were off, by up to 2.7 mdeg).
                let at: Vec<String> = points
                    .iter()
                    .filter(|(_, _, p)| of(p)[k] > 0)
                    .map(|&(rate, listed, _)| {
                        if listed {
                            format!("{rate} deg/s")
                        } else {
                            "the zero-rate reference".to_string()
                        }
                    })
                    .collect();
                let reference_clipped = coriolis
                    && points
                        .iter()
                        .any(|(rate, _, p)| *rate == 0.0 && of(p)[k] > 0);
                let drive = setting == "board.dac_full_scale";
                let spoilt = match (drive, coriolis, reference_clipped) {
                    (true, true, _) => "no phase of this run can be trusted unless both drives clip alike: a clipped drive's fundamental shrinks and its aliased harmonics move its phase, and every Coriolis phase depends on the two drives' ratio".to_string(),
                    (true, false, _) => "the phases at those points cannot be trusted: a clipped drive's fundamental shrinks and its aliased harmonics move its phase".to_string(),
                    (false, _, true) => format!(
                        "no mode-{} phase of this run can be trusted: each is read against the zero-rate reference, which clipped (sampled at fs, even a clipped pure tone's harmonics alias onto the carrier and move its phase, by degrees when deeply clipped)",
                        k + 1
                    ),
                    (false, _, false) => "the phases at those points cannot be trusted (sampled at fs, even a clipped pure tone's harmonics alias onto the carrier and move its phase, by degrees when deeply clipped)".to_string(),
                };
                w.push(format!(
                    "{what} {n} of {} samples ({:.3} %) of mode {}, at {} (counted over each run, settling included): raise {setting}; {spoilt}",
                    h.samples,
                    pct(n),
                    k + 1,
                    at.join(", ")
                ));
            }
        }
    }
    w
}

/// The period of a sweep's readings' branch, degrees: psi is read on a half turn's, a phase
/// on a turn's.
pub fn reading_period_deg(shape: Shape) -> f64 {
    if matches!(shape, Shape::Rotating) {
        180.0
    } else {
        360.0
    }
}

/// Mode `k`'s readings `ys` at rates `xs` as the sweep's line is fitted to them: unwrapped
/// along rate by the exact theory's continuous change ([`unwrapped_along_theory`]; a rate
/// table's amplitudes, whose theory is a harmonic balance per rate, along the readings alone).
pub fn fit_readings(cfg: &Config, xs: &[f64], ys: &[f64], k: usize) -> Vec<f64> {
    let shape = cfg.shape();
    let period = reading_period_deg(shape);
    match shape {
        Shape::RateTable { .. } => unwrapped_along(xs, ys, period),
        _ => unwrapped_along_theory(xs, ys, period, &|x| theory_deg(cfg, x)[k]),
    }
}

/// `x` moved by a whole number of half turns into `(centre - pi/2, centre + pi/2]`, and
/// whether that number was odd. `x` itself is moved (not `x - centre`), so a reading already on
/// its branch keeps its bits.
fn fold_half_turn(x: f64, centre: f64) -> (f64, bool) {
    use core::f64::consts::{FRAC_PI_2, PI};
    let k = ((x - centre) / PI).round();
    let mut y = x - k * PI;
    let mut odd = k.rem_euclid(2.0) == 1.0;
    if y - centre <= -FRAC_PI_2 {
        y += PI;
        odd = !odd;
    } else if y - centre > FRAC_PI_2 {
        y -= PI;
        odd = !odd;
    }
    (y, odd)
}

/// The exact theory of the quantity a sweep measures at `rate_dps`, per mode, degrees (a rate
/// table: the amplitude of the phase's fundamental in the plant's periodic steady state, at
/// any swing).
pub fn theory_deg(cfg: &Config, rate_dps: f64) -> [f64; 2] {
    let omega = rate_dps * DEG;
    let dev = cfg.driven_device();
    let rad = match cfg.shape() {
        Shape::Coriolis => dev.coriolis_phase_rad(omega),
        Shape::RateTable { freq_hz } => dev.rate_table_response(omega, freq_hz).0,
        Shape::Rotating => dev.rotating_psi_rad(omega),
    };
    rad.map(|r| r / DEG)
}

/// The exact theory's slope at small rates, deg per deg/s per mode, from [`theory_deg`] at
/// rates h, 2h and 4h: the forward differences D(h) and D(2h) combine as 2 D(h) - D(2h), which
/// cancels the curvature's first term (a curve that starts off zero, as a strongly coupled
/// device's psi, counts only its slope). h puts the phase near 1e-4 rad: smaller rates lose
/// digits in the theory's w0^2 - w^2, larger ones bend (atan's cube leaves 14/3 (1e-4)^2 =
/// 5e-8 relative; Q = 36 000 loses about as much to rounding). The closed forms (2 Q lambda /
/// w0 times a drive ratio) hold for the ideal device only: a mode-2 Q of half mode 1's halves
/// mode 1's Coriolis slope, and a 2 Hz mode split lowers it by 22 %.
fn small_rate_slope(cfg: &Config) -> [f64; 2] {
    let d = &cfg.device;
    let q = d.q.max(d.q_mode2.unwrap_or(d.q));
    // The ideal device's largest slope, rad per rad/s: a rotating psi has no lambda, a
    // Coriolis phase the larger drive ratio.
    let gain = match cfg.shape() {
        Shape::Rotating => 1.0,
        _ => d.angular_gain * (cfg.drive.f1 / cfg.f2()).max(cfg.f2() / cfg.drive.f1),
    };
    let ideal = 2.0 * q * gain / (core::f64::consts::TAU * d.f0_hz);
    let h = 1e-4 / ideal / DEG;
    let t = [1.0, 2.0, 4.0].map(|m| theory_deg(cfg, m * h));
    [0, 1].map(|k| {
        let d1 = (t[1][k] - t[0][k]) / h;
        let d2 = (t[2][k] - t[1][k]) / (2.0 * h);
        2.0 * d1 - d2
    })
}

/// The rate-table read-out of one point: each harmonic of `z` freed of the window's leak, the
/// low-pass `L(n f_t)` and the TIA `H(f_c + n f_t)` divided out of it (the chain acts on `z`,
/// not on its phase), then the fundamental of the phase lag of the envelope they make. Writes
/// the amplitude into `phase_deg` and returns the lag, degrees per mode, and why a mode with
/// finite harmonics has no phase (its envelope went around zero, or so near it that its
/// phase cannot be resolved: NaN, and not an overflow). The phase's fundamental is taken on a
/// grid as fine as its phase needs, as the theory's is (on 1024 points a dip's phase aliased:
/// 12 mdeg off the theory, unwarned).
///
/// `leak`: the point's window's [`ChainResponse::table_leak`] for `n` harmonics.
fn table_phase_readout(
    chain: &ChainResponse,
    lr: &LaneResult,
    leak: &[Complex64],
    n: usize,
    phase_deg: &mut [f64; 2],
) -> ([f64; 2], [Option<NoFundamental>; 2]) {
    let ft = chain.table_hz();
    let fc = chain.carrier_hz();
    let mut lag = [0.0; 2];
    let mut wound = [None; 2];
    for k in 0..2 {
        let avg = &lr.table_z[k][MAX_TABLE_HARMONIC - n..=MAX_TABLE_HARMONIC + n];
        let v: Vec<Complex64> = unleak_table_harmonics(avg, leak)
            .into_iter()
            .enumerate()
            .map(|(i, z)| {
                let f = (i as f64 - n as f64) * ft;
                z / (chain.lowpass(f) * chain.tia(fc + f))
            })
            .collect();
        let x = match phase_fundamental_checked(&v) {
            Ok(x) => x,
            Err(why) => {
                if v.iter().all(|z| z.is_finite()) {
                    wound[k] = Some(why);
                }
                Complex64::new(f64::NAN, f64::NAN)
            }
        };
        phase_deg[k] = x.norm() / DEG;
        // A lag a sin(w_t t - l) has the complex amplitude -j a e^{-j l}.
        lag[k] = -(x * Complex64::new(0.0, 1.0)).arg() / DEG;
    }
    (lag, wound)
}

/// Turns each emulated point's lane averages into phases, compensation, theory and fits (the
/// `samples` and rate fields of the result are left for the caller).
pub fn post_process(
    cfg: &Config,
    rates: &[f64],
    points: &[Point],
    lanes: &[LaneResult],
) -> Result<SweepResult, ParamError> {
    post_process_with(cfg, rates, points, lanes, &Stage2Leaks::default())
}

/// [`post_process`], taking each rotating point's stage-2 leak from `leaks` where it holds
/// that point's (the same value: see [`Stage2Leaks`]), else computing it.
#[allow(clippy::needless_range_loop)] // mode indices address parallel arrays
pub fn post_process_with(
    cfg: &Config,
    rates: &[f64],
    points: &[Point],
    lanes: &[LaneResult],
    leaks: &Stage2Leaks,
) -> Result<SweepResult, ParamError> {
    let fs_out = cfg.fs_out_hz();
    let shape = cfg.shape();
    let chain = ChainResponse::new(&cfg.board_params())?;
    let dev = cfg.driven_device();
    let table_harmonics = cfg.table_harmonics();
    let mut out = Vec::new();
    // Per listed point: whether each mode's rate-table envelope went around zero.
    let mut wound_at = Vec::new();
    let mut comp = Vec::new();
    let zero = rates.iter().position(|&r| r == 0.0);
    let averaged = |p: &Point| p.span_samples() / fs_out;
    // A rate-table point's leak between table harmonics depends on its window alone, which
    // a sweep's points share: computed once per window (it costs a sin_cos and 2N + 1
    // complex products per averaged sample, 15 % of a long sweep's run when done per point).
    let mut table_leaks: Vec<(Window, Vec<Complex64>)> = Vec::new();
    for (i, &rate) in rates.iter().enumerate() {
        if !cfg.experiment.rates_dps.contains(&rate) {
            continue; // the implicit zero-rate reference
        }
        let lr = &lanes[i];
        let omega = rate * DEG;
        // A rate table's theory gives the lag too: solved once.
        let table_theory = match shape {
            Shape::RateTable { freq_hz } => Some(dev.rate_table_response(omega, freq_hz)),
            _ => None,
        };
        let mut wound = [None; 2];
        let mut r = PointResult {
            rate_dps: rate,
            phase_deg: [0.0; 2],
            theory_deg: match table_theory {
                Some((amp, _)) => amp.map(|a| a / DEG),
                None => theory_deg(cfg, rate),
            },
            paper_i_deg: None,
            raw_psi_deg: None,
            alpha_deg: None,
            single_mixer_dc_v: None,
            table_lag_deg: None,
            table_lag_theory_deg: None,
            averaged_s: averaged(&points[i]),
        };
        match shape {
            Shape::Coriolis => {
                let z0 = lanes[zero.expect("zero rate is always emulated")].z;
                for k in 0..2 {
                    // A product that underflowed to 0 has no phase (atan2(0, 0) would read 0).
                    r.phase_deg[k] = if z0[k] * lr.z[k].conj() == Complex64::new(0.0, 0.0) {
                        f64::NAN
                    } else {
                        phase_lag_rad(lr.z[k], z0[k]) / DEG
                    };
                }
                // Mixing with the mode's own drive: cos w0t (mode 1), sin w0t (mode 2).
                r.single_mixer_dc_v = Some([0.5 * lr.z[0].re, -0.5 * lr.z[1].im]);
            }
            Shape::RateTable { .. } => {
                r.table_lag_theory_deg = table_theory.map(|(_, lag)| lag.map(|l| l / DEG));
                let window = points[i].window;
                let at = match table_leaks.iter().position(|(w, _)| *w == window) {
                    Some(at) => at,
                    None => {
                        let leak =
                            chain.table_leak(&points[i], cfg.n_settle_out(), table_harmonics);
                        table_leaks.push((window, leak));
                        table_leaks.len() - 1
                    }
                };
                let (lag, w) = table_phase_readout(
                    &chain,
                    lr,
                    &table_leaks[at].1,
                    table_harmonics,
                    &mut r.phase_deg,
                );
                r.table_lag_deg = Some(lag);
                wound = w;
            }
            Shape::Rotating => {
                let terms = chain.rotating_terms(omega / core::f64::consts::TAU);
                let total = terms.total_rad();
                comp.push(Compensation {
                    rate_dps: rate,
                    tia_mdeg: terms.tia_rad / DEG * 1e3,
                    dac_hold_mdeg: terms.dac_hold_rad / DEG * 1e3,
                    lowpass_mdeg: terms.lowpass_rad / DEG * 1e3,
                    pipeline_delay_samples: 0,
                });
                let mut raw = [0.0; 2];
                let mut paper = [0.0; 2];
                let mut alpha = [0.0; 2];
                // The window is a not quite whole number of half periods of decimated samples:
                // its exact leak is removed before the sidebands are read.
                let leak = leaks.get_or_compute(&chain, &points[i], cfg.n_settle_out())?;
                for (k, mode) in [Mode::One, Mode::Two].into_iter().enumerate() {
                    let (c, s) = unleak_sidebands(lr.c[k], lr.s[k], leak);
                    let est = sideband_estimate(c, s, mode);
                    let zero = Complex64::new(0.0, 0.0);
                    if est.z_plus == zero || est.z_minus == zero {
                        // A sideband that vanished (or underflowed) has no phase.
                        r.phase_deg[k] = f64::NAN;
                        continue;
                    }
                    // (psi, alpha) and (psi + pi, alpha + pi) give the same sidebands, so the
                    // read-out fixes psi only modulo a half turn. The branch is chosen once the
                    // chain (up to 180 degrees near the low-pass cutoff) is removed, centred on
                    // the point's exact theory: the plant's psi leaves (-90, 90) degrees with
                    // the phase shifter's error (x = 5 deg at 20000 deg/s) or a strong
                    // quadrature coupling (k12 Q / w0^2 = 2: +93.5 deg, read as -86.5). A
                    // reading far from its theory still shows as an error of up to 90 deg.
                    let centre = if r.theory_deg[k].is_finite() {
                        r.theory_deg[k] * DEG
                    } else {
                        match mode {
                            Mode::One => 0.0,
                            Mode::Two => cfg.board.phase_shifter_error_deg * DEG,
                        }
                    };
                    let (psi, turned) = fold_half_turn(est.psi_rad - total, centre);
                    let a = if turned {
                        wrap_pi(est.alpha_rad + core::f64::consts::PI)
                    } else {
                        est.alpha_rad
                    };
                    r.phase_deg[k] = psi / DEG;
                    raw[k] = (psi + total) / DEG;
                    alpha[k] = a / DEG;
                    // A real channel cannot tell the sign of the carrier (an inverting TIA
                    // flips it): fold the paper-style reading onto psi's branch.
                    let p = paper_i_channel_psi_rad(c, s, mode) - total;
                    paper[k] = fold_half_turn(p, centre).0 / DEG;
                }
                r.raw_psi_deg = Some(raw);
                r.paper_i_deg = Some(paper);
                r.alpha_deg = Some(alpha);
            }
        }
        out.push(r);
        wound_at.push(wound);
    }
    // Refuse what no signal supports, and any read-out that is not a finite number.
    let mut problems = Vec::new();
    let mut health = Health::default();
    let reference_dead = match (shape, zero) {
        (Shape::Coriolis, Some(z)) => dead_channels(cfg, &lanes[z]),
        _ => Vec::new(),
    };
    let mut listed = out.iter_mut().zip(&wound_at);
    for (i, &rate) in rates.iter().enumerate() {
        health.add(&lanes[i].health);
        if !cfg.experiment.rates_dps.contains(&rate) {
            continue;
        }
        let Some((r, wound)) = listed.next() else {
            break;
        };
        let mut dead = dead_channels(cfg, &lanes[i]);
        dead.extend(
            reference_dead
                .iter()
                .map(|(k, why)| (*k, format!("{why} (in the zero-rate reference)"))),
        );
        let mut refused = [false; 2];
        for (k, why) in dead {
            if !refused[k] {
                refused[k] = true;
                problems.push(format!(
                    "point {rate} deg/s, mode {}: no phase: {why}",
                    k + 1
                ));
            }
        }
        for k in 0..2 {
            if let (false, Some(why)) = (refused[k], wound[k]) {
                refused[k] = true;
                let what = match why {
                    NoFundamental::Winds => "went around zero within a table period (its phase turns a whole turn per period and has no lag or amplitude to read)",
                    NoFundamental::Unresolved => "passed so near zero within a table period that its phase turns by nearly a half turn in an instant and its fundamental cannot be resolved",
                };
                problems.push(format!(
                    "point {rate} deg/s, mode {}: no phase: the mode's velocity envelope {what}; lower the rate-table amplitude, raise the mode's drive, or bring the mode nearer the carrier",
                    k + 1
                ));
            }
            if !refused[k] && !r.phase_deg[k].is_finite() {
                refused[k] = true;
                problems.push(format!(
                    "point {rate} deg/s, mode {}: the read-out is not a finite number ({}): the chain's values overflowed or underflowed (check the drive amplitudes and gains)",
                    k + 1,
                    r.phase_deg[k]
                ));
            }
            if refused[k] {
                // Every reading of a refused channel goes, not just the headline phase.
                r.phase_deg[k] = f64::NAN;
                for v in [
                    &mut r.paper_i_deg,
                    &mut r.raw_psi_deg,
                    &mut r.alpha_deg,
                    &mut r.table_lag_deg,
                    &mut r.single_mixer_dc_v,
                ]
                .into_iter()
                .flatten()
                {
                    v[k] = f64::NAN;
                }
            }
        }
    }
    let per_point: Vec<(f64, bool, Health)> = rates
        .iter()
        .zip(lanes)
        .map(|(&rate, l)| (rate, cfg.experiment.rates_dps.contains(&rate), l.health))
        .collect();
    let warnings = clipping_warnings(&health, &per_point, matches!(shape, Shape::Coriolis));
    let xs: Vec<f64> = out.iter().map(|p| p.rate_dps).collect();
    let fit = [0, 1].map(|k| {
        let ys: Vec<f64> = out.iter().map(|p| p.phase_deg[k]).collect();
        fit_line(&xs, &fit_readings(cfg, &xs, &ys, k))
    });
    let slope = small_rate_slope(cfg);
    Ok(SweepResult {
        shape,
        points: out,
        compensation: comp,
        fit,
        theory_slope_deg_per_dps: slope,
        settle_s: 0.0,
        fs_hz: 0.0,
        fs_out_hz: 0.0,
        samples: 0,
        point_samples: 0,
        health,
        problems,
        warnings,
    })
}
