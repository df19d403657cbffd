//! Where long work reports its progress: the library calls these, the program decides how to
//! show them (a bar on a terminal, a periodic log line, or nothing).

/// Progress callback of one running task: (input samples done, total).
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// One reported task.
pub trait Task: Sync {
    /// `done` of `total` units (input samples unless the task says otherwise).
    fn update(&self, done: u64, total: u64);
    /// The task ended; `point_samples` when its work is counted in operating-point samples
    /// (the emulation's throughput unit), `None` otherwise.
    fn finish(&self, point_samples: Option<u64>);
    /// The task ended after writing files besides its results (signal dumps): `written`
    /// says how many, how large and how long they took, which the closing line reports apart
    /// from the emulation's throughput. By default the same as [`finish`](Self::finish).
    fn finish_writing(&self, point_samples: Option<u64>, written: Written) {
        let _ = written;
        self.finish(point_samples);
    }
}

/// Files a task wrote besides its results, and the time that took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Written {
    /// Files written.
    pub files: usize,
    /// Their total size, bytes.
    pub bytes: u64,
    /// Wall time spent writing them, s.
    pub seconds: f64,
}

/// A source of tasks, and where the library's notes to the user go.
pub trait Reporter: Sync {
    /// Starts a task named `label`.
    fn task(&self, label: &str) -> Box<dyn Task + '_>;
    /// A line for the user (what is being resumed, a file ignored, what to do next).
    fn note(&self, text: &str);
    /// A warning: the run goes on, but something deserves the user's attention.
    fn warn(&self, text: &str);
}

/// Reports nothing (tests, embedded use).
#[derive(Clone, Copy, Debug, Default)]
pub struct Quiet;

impl Task for Quiet {
    fn update(&self, _: u64, _: u64) {}
    fn finish(&self, _: Option<u64>) {}
}

impl Reporter for Quiet {
    fn task(&self, _: &str) -> Box<dyn Task + '_> {
        Box::new(Quiet)
    }
    fn note(&self, _: &str) {}
    fn warn(&self, _: &str) {}
}
