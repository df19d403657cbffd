//! A value that stopped being finite: found cheaply on the decimated outputs during the run,
//! then located exactly (stage and input sample) by replaying the board with a checking probe
//! (`Board::locate_fault` in `kernel.rs`).

/// A value that stopped being finite inside the chain: where and when.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("non-finite value at the output of stage `{stage}` at input sample {sample} (t = {time_s} s) of the operating point at {rate_dps} deg/s: the chain overflowed; check the drive amplitudes, the gains and the full scales")]
pub struct NonFinite {
    /// The first stage (in chain order) whose output was not finite.
    pub stage: &'static str,
    /// Input sample index from the start of the run (of the point's time axis, for a lane
    /// that started late: `Board::with_starts`).
    pub sample: u64,
    /// The same as a time, s.
    pub time_s: f64,
    /// The operating point's rate, deg/s.
    pub rate_dps: f64,
}
