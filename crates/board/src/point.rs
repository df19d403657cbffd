//! What a run is asked (operating points and their averaging windows, optional extra reads)
//! and what it returns.

use crate::health::Health;
use crate::probe::Probe;
use gyroemu_core::Complex64;
use gyroemu_lpf::Window;
use gyroemu_mixer::TABLE_HARMONICS;

/// One operating point: the rate in rad/s (rotation rate, excitation rate, or rate-table
/// amplitude) and its averaging window in decimated samples after settling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Rate, rad/s.
    pub rate_rad_s: f64,
    /// The averaging window.
    pub window: Window,
}

impl Point {
    /// Whole decimated samples of the window (its fractional or zero end sample excluded).
    pub fn n_avg(&self) -> u64 {
        self.window.samples() - 1
    }

    /// The averaged span in decimated samples.
    pub fn span_samples(&self) -> f64 {
        self.window.span()
    }
}

/// What one lane measured, averaged after settling.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LaneResult {
    /// Mean stage-1 phasor per mode (Coriolis, constant rate).
    pub z: [Complex64; 2],
    /// Stage-2 averages C per mode (rotating).
    pub c: [Complex64; 2],
    /// Stage-2 averages S per mode (rotating).
    pub s: [Complex64; 2],
    /// Rate-table run: the mean of `z e^{-j n theta}` per mode at every table harmonic
    /// `n = -MAX ..= MAX` (index `n + MAX`, `MAX` = [`gyroemu_mixer::MAX_TABLE_HARMONIC`];
    /// zero beyond the board's `table_harmonics`), `theta` the table phase.
    pub table_z: [[Complex64; TABLE_HARMONICS]; 2],
    /// The converters' and rails' counts over the point's run.
    pub health: Health,
}

/// Optional work of a run beyond each lane's average.
#[derive(Default)]
pub struct RunOptions<'a> {
    /// Records the dump window of one lane (see [`Probe`]).
    pub probe: Option<&'a mut Probe>,
    /// Per lane, ascending: early reads `(n, frac)` of the lane's boxcar window (weight 1 on
    /// `n` samples and `frac` on the next); each yields the average as if the window had ended
    /// there (the averaging-time analysis). Needs a boxcar window at least as long.
    pub early_reads: Vec<Vec<(u64, f64)>>,
    /// Decimated samples per row of the recorded series (0: no series). Each row holds the
    /// mean over its block of the averaged channels (after settling).
    pub series_block: u64,
    /// Called once with `probe` as soon as both its windows have ended, from the run's thread
    /// (so a dump can be written while the run goes on); the run then records no more.
    pub on_probe_recorded: Option<&'a (dyn Fn(&Probe) + Sync)>,
}

/// What a run returns.
#[derive(Clone, Debug, Default)]
pub struct RunOutput {
    /// Per lane: the average over the point's window.
    pub lanes: Vec<LaneResult>,
    /// Per lane: one result per early read.
    pub early_reads: Vec<Vec<LaneResult>>,
    /// Per lane: the series rows (Coriolis: I1, Q1, I2, Q2 of the low-passed stage-1 outputs;
    /// rotating: C and S of both modes as in [`LaneResult`], 8 values).
    pub series: Vec<Vec<[f64; 8]>>,
    /// Per lane: its window ended before the run stopped (always, unless a cancel flag
    /// stopped it), so its entry of `lanes` is the point's final result; the other lanes'
    /// entries are meaningless.
    pub complete: Vec<bool>,
    /// Per lane: the results of the points it ran before its last, in order, when the run
    /// refilled it ([`crate::Board::run_refilled`]); `lanes` holds its last point's.
    pub refilled: Vec<Vec<LaneResult>>,
}
