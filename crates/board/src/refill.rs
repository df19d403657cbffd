//! Lane refill: a lane whose point has ended takes another between two decimation blocks, so
//! a group's lanes can run points of unequal lengths back to back instead of idling until the
//! longest ends. A refilled lane holds the bits of a board built for its new point alone:
//! its plant, TIA and low-pass start from rest, its oscillator is re-set from the new point's
//! phase word exactly where a fresh board's would be (an exact re-set), and its average
//! starts anew. Noiseless boards only (a lane's noise streams belong to its first point).

use crate::board::{lane_modulation, lane_table, own_table_hz, Board};
use crate::fault::NonFinite;
use crate::params::{Shape, STAGE};
use crate::point::{Point, RunOptions, RunOutput};
use gyroemu_core::{ParamError, Sample};
use gyroemu_nco::{Nco, RESYNC};

/// Another point for a lane of a running board (see [`Board::run_refilled`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refill {
    /// The lane (below the board's points).
    pub lane: usize,
    /// The decimation block at which the lane starts the point (its settling starts at
    /// input sample `at_block * decimation`): after the lane's previous point has ended,
    /// at an exact re-set of the oscillators, where the carrier's phase is the one the
    /// point's start gives it.
    pub at_block: u64,
    /// The point, settled and averaged as the run's first points are.
    pub point: Point,
    /// Where the point starts on its own time axis, input samples ([`Board::with_starts`]).
    pub start: u64,
    /// Its rate table's frequency, Hz, on a rate-table board (`None`: the board's own).
    pub table_hz: Option<f64>,
}

/// Why a refilled run did not give its results.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RefillError {
    /// A refill broke a rule (checked before the first sample).
    #[error(transparent)]
    Refused(#[from] ParamError),
    /// A value stopped being finite.
    #[error(transparent)]
    NonFinite(#[from] NonFinite),
}

/// A checked refill with the oscillator its lane takes over (the modulation's on a rotating
/// board, the table's on a rate table).
#[derive(Clone, Debug)]
pub(crate) struct Prepared {
    pub(crate) r: Refill,
    pub(crate) nco: Nco,
}

fn refuse<T>(key: &'static str, value: impl ToString, rule: &str) -> Result<T, ParamError> {
    Err(ParamError::new(STAGE, key, value.to_string(), rule))
}

impl<S: Sample> Board<S> {
    /// [`Board::run`] with `refills`, ascending by block: at each, its lane takes its point
    /// as a board of that point alone would run it (the same bits), and the lane's previous
    /// point's result goes to [`RunOutput::refilled`]. Refills need a noiseless board
    /// without converters or rails (their counts and noise streams are a point's own), of a
    /// rotating or rate-table shape (a Coriolis lane's plant depends on its rate), and a run
    /// without probe, early reads or series. A refusal names the refill's rule; a non-finite
    /// value is located as [`Board::run`] locates it.
    pub fn run_refilled(
        &mut self,
        n_settle: u64,
        points: &[Point],
        refills: &[Refill],
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<RunOutput, RefillError> {
        let prepared = self.check_refills(n_settle, points, refills)?;
        if !prepared.is_empty() && self.shape.is_rate_table() {
            // Lanes that change tables mid-run follow their own.
            self.table_shared = false;
        }
        self.dispatch(n_settle, points, RunOptions::default(), &prepared, progress)
            .map_err(|k| self.locate_fault(k, &prepared).into())
    }

    /// The refills of a run of `points` after `n_settle` blocks of settling, checked and
    /// with their oscillators built, before any sample.
    fn check_refills(
        &self,
        n_settle: u64,
        points: &[Point],
        refills: &[Refill],
    ) -> Result<Vec<Prepared>, ParamError> {
        if refills.is_empty() {
            return Ok(Vec::new());
        }
        if matches!(self.shape, Shape::Coriolis) {
            return refuse(
                "refills",
                refills.len(),
                "a Coriolis lane's plant depends on its rate: refill rotating or rate-table boards",
            );
        }
        if self.ran {
            return refuse(
                "refills",
                refills.len(),
                "refill a board on its first run (the refills' blocks count from where it was built)",
            );
        }
        if self.imperfect {
            return refuse(
                "refills",
                refills.len(),
                "refill a board without noise, converters or rails (their streams and counts are a point's own)",
            );
        }
        if points.len() < self.lanes {
            return refuse(
                "points",
                points.len(),
                "must give every lane its first point",
            );
        }
        let m = self.decimation as u64;
        // A point from block `at` ends at block `at + n_settle + samples`, its input sample
        // within 2^53 (the kernel's block and sample counts then stay exact, far from u64's end).
        let end_of = |at: u64, p: &Point, key: &'static str| -> Result<u64, ParamError> {
            p.window.check()?;
            at.checked_add(n_settle)
                .and_then(|e| e.checked_add(p.window.samples()))
                .filter(|e| e.checked_mul(m).is_some_and(|n| n <= crate::MAX_START))
                .map_or_else(
                    || {
                        refuse(
                            key,
                            p.window.samples(),
                            "the point must end within 2^53 input samples of the run",
                        )
                    },
                    Ok,
                )
        };
        // Each lane's block where its current point ends.
        let mut end = points[..self.lanes]
            .iter()
            .map(|p| end_of(0, p, "points.window"))
            .collect::<Result<Vec<u64>, _>>()?;
        let mut last = 0;
        let mut out = Vec::with_capacity(refills.len());
        for r in refills {
            if r.lane >= self.lanes {
                return refuse("refill.lane", r.lane, "must be below the board's points");
            }
            if r.at_block < last {
                return refuse(
                    "refill.at_block",
                    r.at_block,
                    "refills must be in block order",
                );
            }
            last = r.at_block;
            if r.at_block < end[r.lane] {
                return refuse(
                    "refill.at_block",
                    r.at_block,
                    &format!(
                        "must not precede the end of the lane's point (block {})",
                        end[r.lane]
                    ),
                );
            }
            let n0 = r.at_block.checked_mul(m).filter(|&n| n <= crate::MAX_START);
            let Some(n0) = n0.filter(|&n| n > 0 && n % u64::from(RESYNC) == 0) else {
                return refuse(
                    "refill.at_block",
                    r.at_block,
                    &format!("must start an input sample past 0, within 2^53 and a multiple of the oscillators' re-set interval ({RESYNC})"),
                );
            };
            if r.start > crate::MAX_START {
                return refuse("refill.start", r.start, "at most 2^53 input samples");
            }
            // The shared carrier's phase word where the lane starts, against the point's own.
            let step = self.carrier.step_word(0);
            let here = step.wrapping_mul(self.starts[0].wrapping_add(n0));
            if here != step.wrapping_mul(r.start) {
                return refuse(
                    "refill.start",
                    r.start,
                    "the carrier's phase at the refill must be the one the point's start gives it (a whole number of carrier turns apart)",
                );
            }
            if !r.point.rate_rad_s.is_finite() {
                return refuse("refill.rate_rad_s", r.point.rate_rad_s, "must be finite");
            }
            let ends = end_of(r.at_block, &r.point, "refill.window")?;
            // The oscillator the lane takes over, built as a board of the point alone builds it.
            let nco = if self.shape.is_rate_table() {
                let f = match r.table_hz {
                    Some(f) => gyroemu_core::error::positive(STAGE, "table_freq_hz", f)?,
                    None => own_table_hz(self.shape),
                };
                lane_table(f, self.fs_hz, r.start)?
            } else {
                lane_modulation(self.shape, r.point.rate_rad_s, self.fs_hz, r.start)?
            };
            end[r.lane] = ends;
            out.push(Prepared { r: *r, nco });
        }
        Ok(out)
    }

    /// Lane `r.lane` takes its refill's point at input sample `n0` (an exact re-set, as
    /// checked): its plant, TIA and low-pass back to rest, its rate and oscillator the
    /// point's, its time axis the point's own.
    pub(crate) fn refill_lane(&mut self, p: &Prepared, n0: u64) {
        let i = p.r.lane;
        self.plant.reset_lane(i);
        for t in &mut self.tia {
            t.reset_lane(i);
        }
        self.lp.reset_lane(i);
        self.rate = self.rate.with_lane(i, p.r.point.rate_rad_s);
        let osc = if self.shape.is_rate_table() {
            self.table_f_hz[i] = p.nco.f_hz();
            &mut self.table_lanes
        } else {
            &mut self.modulation
        };
        osc.set_lane_at_resync(i, &p.nco)
            .expect("refills are checked to fall on an exact re-set");
        // The lane's time axis: its input sample `n` of the run is `n + starts[i]` of its own.
        self.starts[i] = p.r.start.wrapping_sub(n0);
    }
}
