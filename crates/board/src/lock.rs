//! Locking the carrier onto a resonance with the PLL (issue 14 point 1): the board runs at
//! zero rate with its Coriolis drives, sample by sample, and after every decimation block the
//! PLL reads the demodulated output of the locked mode and sets the carrier oscillator's
//! frequency for the next block (phase-continuous, exact to the 64-bit word). A sweep then
//! holds the carrier at the frequency the lock reached: a closed loop during the sweep would
//! also follow the Coriolis detuning it is meant to measure.

use crate::board::{Board, CORIOLIS};
use crate::health::Counters;
use crate::params::{BoardParams, Shape};
use core::sync::atomic::{AtomicBool, Ordering};
use gyroemu_core::{Complex64, ParamError, ParamResult, Stage};
use gyroemu_pll::Pll;

/// How a lock run ended.
#[derive(Clone, Debug, PartialEq)]
pub struct LockRun {
    /// The carrier at the end, Hz.
    pub carrier_hz: f64,
    /// The PLL reported lock at the end.
    pub locked: bool,
    /// When the lock indicator came on for good (it stayed on to the end), s.
    pub lock_time_s: Option<f64>,
    /// The cancel flag stopped the run before its last block (`locked` is then false).
    pub cancelled: bool,
}

/// Runs the board `p` (its shape replaced by a Coriolis run at zero rate, one operating
/// point) for `blocks` decimation blocks with `pll` steering its carrier from the demodulated
/// output of `mode` (0 or 1) after each block. Returns where it ended; a value that stops
/// being finite is an error naming the stage, as in a run. A raised `cancel` (Ctrl-C) stops it
/// after the block in progress: a lock run can be as long as the user's `pll.lock_s`. It keeps
/// nothing per block, so its memory does not grow with its length (a kept trace, which nothing
/// read, grew by 24 bytes a block: gigabytes for a lock of days).
pub fn lock_carrier(
    p: &BoardParams,
    pll: &mut Pll,
    mode: usize,
    blocks: u64,
    cancel: Option<&AtomicBool>,
) -> ParamResult<Result<LockRun, crate::NonFinite>> {
    if mode > 1 {
        return Err(ParamError::new(
            crate::params::STAGE,
            "lock mode",
            mode,
            "must be 0 (mode 1) or 1 (mode 2)",
        ));
    }
    let params = BoardParams {
        shape: Shape::Coriolis,
        ..*p
    };
    let mut board = Board::<f64>::new(&params, &[0.0], &[0])?;
    Ok(board.run_lock(pll, mode, blocks, cancel))
}

impl Board<f64> {
    fn run_lock(
        &mut self,
        pll: &mut Pll,
        mode: usize,
        blocks: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<LockRun, crate::NonFinite> {
        macro_rules! by_plant {
            ($($noisy:literal, $dec:literal);*) => {
                match (self.imperfect, self.plant_decoupled()) {
                    $(($noisy, $dec) => self.lock_loop::<$noisy, $dec>(pll, mode, blocks, cancel),)*
                }
            };
        }
        by_plant!(false, false; false, true; true, false; true, true)
            .map_err(|k| self.locate_fault(k, &[]))
    }

    fn lock_loop<const NOISY: bool, const DECOUPLED: bool>(
        &mut self,
        pll: &mut Pll,
        mode: usize,
        blocks: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<LockRun, u64> {
        let m = self.decimation as u64;
        let mut counts = Counters::<f64>::default();
        let mut locked_since: Option<f64> = None;
        for k in 0..blocks {
            if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                return Ok(LockRun {
                    carrier_hz: pll.frequency_hz(),
                    locked: false,
                    lock_time_s: None,
                    cancelled: true,
                });
            }
            let n0 = k * m;
            let (z, _) = self.block::<CORIOLIS, NOISY, DECOUPLED>(n0, None, &mut counts);
            if ![z[0].i, z[0].q, z[1].i, z[1].q]
                .iter()
                .all(|v| v.is_finite())
            {
                return Err(k);
            }
            let f = pll.tick(Complex64::new(z[mode].i, z[mode].q));
            // The new frequency acts from the next block on (the loop's timing contract).
            self.carrier
                .set_frequency_hz(0, f)
                .expect("the PLL's limits keep the carrier below Nyquist");
            let time_s = (n0 + m - 1) as f64 / self.fs_hz;
            locked_since = match (pll.is_locked(), locked_since) {
                (true, None) => Some(time_s),
                (true, since) => since,
                (false, _) => None,
            };
        }
        Ok(LockRun {
            carrier_hz: pll.frequency_hz(),
            locked: pll.is_locked(),
            lock_time_s: locked_since,
            cancelled: false,
        })
    }
}
