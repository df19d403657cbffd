//! The carrier PLL of a config (`[pll]`, issue 14 point 1): a lock run emulated on the board at
//! zero rate, the PLL steering the carrier onto the resonance of one mode, and the config the
//! sweep then runs: the carrier held where the lock ended.

use crate::sweep::SweepError;
use core::sync::atomic::AtomicBool;
use gyroemu_board::{lock_carrier as board_lock, ChainResponse};
use gyroemu_config::Config;
use gyroemu_core::{ParamResult, Stage};
use gyroemu_lpf::LowPass;
use gyroemu_pll::{Pll, PllParams};

/// How a config's carrier was locked.
#[derive(Clone, Debug, PartialEq)]
pub struct CarrierLock {
    /// The carrier the lock started from (`drive.carrier_hz`), Hz.
    pub nominal_hz: f64,
    /// The carrier where the lock ended (what the sweep runs at), Hz.
    pub carrier_hz: f64,
    /// The resonance of the locked mode as configured, Hz (for comparison only: the PLL
    /// does not know it).
    pub resonance_hz: f64,
    /// When the lock indicator came on for good, s.
    pub lock_time_s: Option<f64>,
}

impl CarrierLock {
    /// `cfg` as its sweeps run after this lock: the carrier held where the lock ended, the
    /// `[pll]` section spent.
    pub fn hold(&self, cfg: &Config) -> Config {
        let mut held = cfg.clone();
        held.drive.carrier_hz = Some(self.carrier_hz);
        held.pll = None;
        held
    }

    /// What the lock did, for the run's log: `pll: locked the carrier at F Hz, the lock
    /// indicator on from T s (started at S Hz; ...)`. T is when the indicator came on for
    /// good, about a loop period after the error entered its band.
    pub fn note(&self) -> String {
        format!(
            "pll: locked the carrier at {} Hz, the lock indicator on from {} (started at {} Hz; the locked mode resonates at {} Hz as configured); every sweep that follows runs at that carrier",
            self.carrier_hz,
            self.lock_time_s
                .map_or("the end of the lock run".to_string(), |t| format!("{t:.3} s")),
            self.nominal_hz,
            self.resonance_hz
        )
    }
}

/// The PLL that `design` (the config whose `[pll]`, device and board define the loop) puts on
/// the board of `cfg`: its nominal carrier `cfg`'s, its update rate the decimated rate, its
/// gains from the locked mode's nominal tau, its phase offset the chain's phase at the carrier
/// (the DAC hold and the TIA: the velocity is in phase with the force at resonance; for mode 2
/// also the phase shifter's lag), limits
/// of a fifth of the carrier either side. `None` without a `[pll]`.
pub fn pll_params(cfg: &Config, design: &Config) -> ParamResult<Option<PllParams>> {
    let Some(pll) = &design.pll else {
        return Ok(None);
    };
    let (f0, q) = if pll.mode == 2 {
        (
            design.f0_mode2_hz(),
            design.device.q_mode2.unwrap_or(design.device.q),
        )
    } else {
        (design.device.f0_hz, design.device.q)
    };
    let fc = cfg.carrier_hz();
    let chain = ChainResponse::new(&cfg.board_params())?;
    let lowpass = LowPass::<f64>::new(cfg.lowpass_design(), cfg.fs_hz())?;
    let mut p = PllParams::new(
        fc,
        cfg.fs_out_hz(),
        design.pll_natural_hz().unwrap_or(f64::NAN),
        pll.damping,
        PllParams::tau_s_of(f0, q),
    );
    // Mode 2 is driven through the phase shifter, F2 cos(w t - 90 deg - error): at its
    // resonance its phasor lags mode 1's by that shift (without it the loop sought +90 deg
    // and ran off the resonance).
    let shift = if pll.mode == 2 {
        (90.0 + cfg.board.phase_shifter_error_deg).to_radians()
    } else {
        0.0
    };
    p.phase_offset_rad = (chain.dac_hold(fc) * chain.tia(fc)).arg() - shift;
    p.lowpass_delay_s = lowpass.latency_samples() / cfg.fs_hz();
    p.min_hz = Some(0.8 * fc);
    p.max_hz = Some((1.2 * fc).min(0.49 * cfg.fs_hz()));
    Ok(Some(p))
}

/// Locks `cfg`'s carrier with the PLL `design` defines (see [`pll_params`]); `None` without a
/// `[pll]`. A lock that does not hold at the end of `pll.lock_s` is an error: a sweep at a
/// carrier still moving would be read as if it sat on the resonance.
pub fn lock_config_carrier(
    cfg: &Config,
    design: &Config,
) -> Result<Option<CarrierLock>, SweepError> {
    lock_config_carrier_with(cfg, design, None)
}

/// [`lock_config_carrier`], stopped by a raised `cancel` after the block in progress
/// ([`SweepError::Cancelled`]).
pub fn lock_config_carrier_with(
    cfg: &Config,
    design: &Config,
    cancel: Option<&AtomicBool>,
) -> Result<Option<CarrierLock>, SweepError> {
    let Some(params) = pll_params(cfg, design)? else {
        return Ok(None);
    };
    let pll_cfg = design.pll.as_ref().expect("pll_params found a [pll]");
    let mut pll = Pll::new(&params)?;
    let lock_s = design.pll_lock_s().unwrap_or(f64::NAN);
    let blocks = lock_blocks(lock_s, cfg.fs_out_hz());
    let mode = pll_cfg.mode - 1;
    let run = board_lock(&cfg.board_params(), &mut pll, mode, blocks, cancel)??;
    if run.cancelled {
        return Err(SweepError::Cancelled);
    }
    // The locked mode's configured resonance and half-bandwidth.
    let (resonance, half_bw) = cfg.mode_resonances_hz()[mode];
    if !run.locked {
        let error = pll.phase_error_rad();
        let threshold = params.lock_threshold_rad;
        let cause = format!(
            "the carrier PLL did not lock within {lock_s} s: it ended at {} Hz with a phase error of {error:.3e} rad (started at {} Hz, mode {} resonates at {} Hz as configured)",
            run.carrier_hz,
            params.carrier_hz,
            pll_cfg.mode,
            resonance,
        );
        // Settled within 5 % of a half-bandwidth of the resonance yet never held the
        // phase within the lock threshold for a natural period. Either the phase noise at its
        // input keeps breaking the lock (a longer pll.lock_s did not help: its error's last
        // stretch inside the threshold was 80 of the 753 updates a lock takes), or the run
        // ended while it held (316 of 753, the error 1.24e-2 rad against 0.05: it had been
        // told to lower the noise, and a longer lock run locks). A last stretch of a quarter
        // of a lock's updates tells them apart.
        let near = (run.carrier_hz - resonance).abs() < 0.05 * half_bw;
        let noisy = cfg.noise.is_some();
        let holding = 4 * u64::from(pll.in_band_updates()) >= u64::from(params.lock_updates);
        let (cause, advice) = if near && noisy && !holding {
            (
                format!(
                    "{cause}: its frequency settled near the resonance, but the phase noise at its input kept its phase error above the lock threshold ({threshold} rad) for a whole natural period"
                ),
                "lower the [noise] sources (a longer pll.lock_s does not help)".to_string(),
            )
        } else if near && holding {
            (
                format!(
                    "{cause}: its frequency settled near the resonance and its phase error had been inside the lock threshold ({threshold} rad) for {} of the {} updates a lock takes when the lock run ended",
                    pll.in_band_updates(),
                    params.lock_updates
                ),
                if noisy {
                    "raise pll.lock_s (and, if it still does not lock, lower the [noise] sources)"
                } else {
                    "raise pll.lock_s"
                }
                .to_string(),
            )
        } else {
            (
                cause,
                "raise pll.lock_s, or start drive.carrier_hz nearer the resonance".to_string(),
            )
        };
        return Err(SweepError::NotLocked { cause, advice });
    }
    Ok(Some(CarrierLock {
        nominal_hz: params.carrier_hz,
        carrier_hz: run.carrier_hz,
        resonance_hz: resonance,
        lock_time_s: run.lock_time_s,
    }))
}

/// The decimation blocks of a lock run of `lock_s` seconds at the output rate `fs_out_hz`
/// (whole blocks, at least the time asked; saturating, as a float cast does).
pub fn lock_blocks(lock_s: f64, fs_out_hz: f64) -> u64 {
    (lock_s * fs_out_hz).ceil() as u64
}

/// The config a sweep of `cfg` runs: with a `[pll]`, its carrier locked first (the lock is
/// deterministic, so every rerun, shard and merge gets the same bits) and held, the `[pll]`
/// section then spent; otherwise `cfg` itself.
pub fn resolve_lock(cfg: &Config) -> Result<(Config, Option<CarrierLock>), SweepError> {
    resolve_lock_with(cfg, None)
}

/// [`resolve_lock`], its lock stopped by a raised `cancel` ([`SweepError::Cancelled`]).
pub fn resolve_lock_with(
    cfg: &Config,
    cancel: Option<&AtomicBool>,
) -> Result<(Config, Option<CarrierLock>), SweepError> {
    let Some(lock) = lock_config_carrier_with(cfg, cfg, cancel)? else {
        return Ok((cfg.clone(), None));
    };
    Ok((lock.hold(cfg), Some(lock)))
}
