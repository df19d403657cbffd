//! A lane group's board in the lane type picked at run time: [`Board`] in `f64x4` lanes, or
//! in eight `F64x8` lanes on a CPU with AVX-512 (`lanes.rs` says when). Every lane is its
//! point alone, so the results are the same bits in either.

use crate::board::Board;
#[cfg(target_arch = "x86_64")]
use crate::f64x8::F64x8;
use crate::fault::NonFinite;
use crate::lanes::{eight_lanes_available, max_lanes};
use crate::params::{BoardParams, STAGE};
use crate::point::{Point, RunOptions, RunOutput};
use crate::refill::{Refill, RefillError};
use gyroemu_core::{f64x4, ParamError};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// The board of one lane group of up to [`max_lanes`] points.
#[derive(Clone)]
pub struct GroupBoard(Lanes);

#[derive(Clone)]
enum Lanes {
    Four(Box<Board<f64x4>>),
    #[cfg(target_arch = "x86_64")]
    Eight(Box<Board<F64x8>>),
}

/// The lanes [`GroupBoard::new`] runs `n` points in: four for up to four, else the widest
/// this process runs. The sweeps size their groups by the chain's width
/// ([`crate::max_lanes_for`]), so a group of more than four reaches here only where eight are
/// the chain's width; five to eight points handed in by other callers (tests) get eight
/// lanes on any chain rather than a refusal.
fn width_for(n: usize) -> usize {
    if n <= 4 {
        4
    } else {
        max_lanes()
    }
}

/// `Board::$ctor(args)` in the lanes [`width_for`] picks for `$n` points, as a group.
macro_rules! in_lanes_for {
    ($n:expr, $ctor:ident($($arg:expr),* $(,)?)) => {
        Ok(Self(match width_for($n) {
            #[cfg(target_arch = "x86_64")]
            8 => Lanes::Eight(Box::new(Board::$ctor($($arg),*)?)),
            _ => Lanes::Four(Box::new(Board::$ctor($($arg),*)?)),
        }))
    };
}

/// The same call on whichever board the group holds.
macro_rules! on_board {
    ($self:expr, $b:ident => $e:expr) => {
        match $self {
            Lanes::Four($b) => $e,
            #[cfg(target_arch = "x86_64")]
            Lanes::Eight($b) => $e,
        }
    };
}

impl GroupBoard {
    /// The board for `rates_rad_s.len()` points, as [`Board::new`] takes them: four lanes for
    /// up to four points, eight for more (up to [`max_lanes`]).
    pub fn new(p: &BoardParams, rates_rad_s: &[f64], streams: &[u64]) -> Result<Self, ParamError> {
        Self::with_width(width_for(rates_rad_s.len()), p, rates_rad_s, streams)
    }

    /// [`Board::with_starts`] (lane `i` starting at input sample `starts[i]`) in the lanes
    /// [`GroupBoard::new`] picks.
    pub fn with_starts(
        p: &BoardParams,
        rates_rad_s: &[f64],
        streams: &[u64],
        starts: &[u64],
    ) -> Result<Self, ParamError> {
        in_lanes_for!(
            rates_rad_s.len(),
            with_starts(p, rates_rad_s, streams, starts)
        )
    }

    /// [`Board::with_table_hz`] (a rate table per lane) in the lanes [`GroupBoard::new`]
    /// picks.
    pub fn with_table_hz(
        p: &BoardParams,
        rates_rad_s: &[f64],
        table_hz: &[f64],
        streams: &[u64],
    ) -> Result<Self, ParamError> {
        in_lanes_for!(
            rates_rad_s.len(),
            with_table_hz(p, rates_rad_s, table_hz, streams)
        )
    }

    /// [`Board::with_table_hz_starts`] (a rate table per lane, each lane starting at its
    /// input sample of the time axis) in the lanes [`GroupBoard::new`] picks.
    pub fn with_table_hz_starts(
        p: &BoardParams,
        rates_rad_s: &[f64],
        table_hz: &[f64],
        streams: &[u64],
        starts: &[u64],
    ) -> Result<Self, ParamError> {
        in_lanes_for!(
            rates_rad_s.len(),
            with_table_hz_starts(p, rates_rad_s, table_hz, streams, starts)
        )
    }

    /// The board in lanes of `width` (4 or 8) whatever the points (benchmarks, and tests that
    /// compare the widths). Eight lanes on a CPU without AVX-512 are refused.
    pub fn with_width(
        width: usize,
        p: &BoardParams,
        rates_rad_s: &[f64],
        streams: &[u64],
    ) -> Result<Self, ParamError> {
        match width {
            4 => Ok(Self(Lanes::Four(Box::new(Board::new(
                p,
                rates_rad_s,
                streams,
            )?)))),
            #[cfg(target_arch = "x86_64")]
            8 if eight_lanes_available() => Ok(Self(Lanes::Eight(Box::new(Board::new(
                p,
                rates_rad_s,
                streams,
            )?)))),
            8 => Err(ParamError::new(
                STAGE,
                "lanes",
                width,
                "eight lanes need a CPU with AVX-512 (F, VL, DQ and BW)",
            )),
            _ => Err(ParamError::new(STAGE, "lanes", width, "must be 4 or 8")),
        }
    }

    /// Lanes of the group's sample type (4 or 8).
    pub fn width(&self) -> usize {
        match &self.0 {
            Lanes::Four(_) => 4,
            #[cfg(target_arch = "x86_64")]
            Lanes::Eight(_) => 8,
        }
    }

    /// The operating points this board runs (lanes in use).
    pub fn lanes(&self) -> usize {
        on_board!(&self.0, b => b.lanes())
    }

    /// See [`Board::set_cancel`].
    pub fn set_cancel(&mut self, flag: Arc<AtomicBool>) {
        on_board!(&mut self.0, b => b.set_cancel(flag))
    }

    /// See [`Board::run`].
    pub fn run(
        &mut self,
        n_settle: u64,
        points: &[Point],
        opts: RunOptions,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, NonFinite> {
        on_board!(&mut self.0, b => b.run(n_settle, points, opts, progress))
    }

    /// See [`Board::run_refilled`].
    pub fn run_refilled(
        &mut self,
        n_settle: u64,
        points: &[Point],
        refills: &[Refill],
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, RefillError> {
        on_board!(&mut self.0, b => b.run_refilled(n_settle, points, refills, progress))
    }

    /// See [`Board::plant_decoupled`].
    pub fn plant_decoupled(&self) -> bool {
        on_board!(&self.0, b => b.plant_decoupled())
    }

    /// See [`Board::table_per_lane`].
    pub fn table_per_lane(&self) -> bool {
        on_board!(&self.0, b => b.table_per_lane())
    }
}
