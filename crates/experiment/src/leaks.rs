//! The stage-2 window leaks of a rotating sweep, computed apart from its read-out.
//!
//! A leak ([`ChainResponse::stage2_leak`]) depends on the config and the point alone, not on
//! what the board measured, yet it is a sum over every averaged sample of the window: 30 ms
//! of one thread for Fig. 9's seven 500 s windows. Computed beside the sweep, on a thread the
//! sweep leaves idle, it no longer delays the read-out at the run's end.

use gyroemu_board::{ChainResponse, Point, Shape};
use gyroemu_config::Config;
use gyroemu_core::{Complex64, ParamError};

/// Precomputed stage-2 leaks, each kept with everything it was computed from, so the read-out
/// takes one only for the very point, settling and chain rates it describes.
#[derive(Clone, Debug, Default)]
pub struct Stage2Leaks {
    entries: Vec<Entry>,
}

#[derive(Clone, Debug)]
struct Entry {
    point: Point,
    n_settle: u64,
    fs_hz: f64,
    decimation: usize,
    leak: Complex64,
}

impl Stage2Leaks {
    /// The leaks of every point `cfg`'s read-out compensates (none unless the sweep is
    /// rotating), as [`post_process`](crate::post_process) computes them.
    pub fn of_sweep(cfg: &Config) -> Result<Self, ParamError> {
        if cfg.shape() != Shape::Rotating {
            return Ok(Self::default());
        }
        let chain = ChainResponse::new(&cfg.board_params())?;
        let n_settle = cfg.n_settle_out();
        let mut entries = Vec::new();
        // The points `finish_sweep` reads out.
        for rate in cfg.emulated_rates_dps() {
            let point = cfg.plan_point(rate);
            let leak = chain.stage2_leak(&point, n_settle)?;
            entries.push(Entry::new(&chain, point, n_settle, leak));
        }
        Ok(Self { entries })
    }

    /// The leak of `point` after `n_settle` decimated samples on `chain`, if one was kept.
    pub fn get(&self, chain: &ChainResponse, point: &Point, n_settle: u64) -> Option<Complex64> {
        let (fs_hz, decimation) = chain.rates();
        self.entries
            .iter()
            .find(|e| {
                e.point == *point
                    && e.n_settle == n_settle
                    && e.fs_hz == fs_hz
                    && e.decimation == decimation
            })
            .map(|e| e.leak)
    }

    /// The leak of `point`: the kept one, else computed now.
    pub fn get_or_compute(
        &self,
        chain: &ChainResponse,
        point: &Point,
        n_settle: u64,
    ) -> Result<Complex64, ParamError> {
        match self.get(chain, point, n_settle) {
            Some(l) => Ok(l),
            None => chain.stage2_leak(point, n_settle),
        }
    }

    /// How many leaks are kept.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether none is kept.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// A set holding `leak` for `point` on `chain`, whatever its true value (tests: it shows
    /// whether a read-out took a kept leak).
    #[doc(hidden)]
    pub fn with_entry(
        mut self,
        chain: &ChainResponse,
        point: Point,
        n_settle: u64,
        leak: Complex64,
    ) -> Self {
        self.entries.push(Entry::new(chain, point, n_settle, leak));
        self
    }
}

impl Entry {
    fn new(chain: &ChainResponse, point: Point, n_settle: u64, leak: Complex64) -> Self {
        let (fs_hz, decimation) = chain.rates();
        Self {
            point,
            n_settle,
            fs_hz,
            decimation,
            leak,
        }
    }
}
