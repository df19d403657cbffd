//! Progress on long runs: a bar on a terminal, a periodic log line otherwise (CI, pipes).

use gyroemu_experiment::{Reporter, Task};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Reports emulated samples against the total.
pub struct Progress {
    bar: Option<ProgressBar>,
    label: String,
    last_log: Mutex<Instant>,
    start: Instant,
}

impl Progress {
    /// A reporter for one sweep named `label`.
    pub fn new(label: &str) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::new(1);
            b.set_style(
                ProgressStyle::with_template(
                    "{msg:>18} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            b.set_message(label.to_string());
            b
        });
        Self {
            bar,
            label: label.to_string(),
            last_log: Mutex::new(Instant::now()),
            start: Instant::now(),
        }
    }

    /// Called from the sweep threads with (samples done, total samples).
    fn update_now(&self, done: u64, total: u64) {
        if let Some(b) = &self.bar {
            b.set_length(total);
            b.set_position(done);
            return;
        }
        let Ok(mut last) = self.last_log.lock() else {
            return;
        };
        if last.elapsed() >= Duration::from_secs(10) {
            *last = Instant::now();
            eprintln!(
                "{}: {:.0}% ({done} of {total} samples, {:.0} s)",
                self.label,
                100.0 * done as f64 / total.max(1) as f64,
                self.start.elapsed().as_secs_f64()
            );
        }
    }

    /// Closes the bar and prints the throughput.
    fn finish_counted(&self, point_samples: u64) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
        let s = self.start.elapsed().as_secs_f64();
        eprintln!(
            "{}: {point_samples} point-samples in {s:.1} s ({:.0} M point-samples/s)",
            self.label,
            point_samples as f64 / s.max(1e-9) / 1e6
        );
    }

    /// Closes the bar and prints the elapsed time (for runs whose size is not in point-samples).
    fn finish_elapsed(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
        eprintln!(
            "{}: done in {:.1} s",
            self.label,
            self.start.elapsed().as_secs_f64()
        );
    }
}

impl Task for Progress {
    fn update(&self, done: u64, total: u64) {
        self.update_now(done, total);
    }
    fn finish(&self, point_samples: Option<u64>) {
        match point_samples {
            Some(n) => self.finish_counted(n),
            None => self.finish_elapsed(),
        }
    }
}

/// The program's reporter: a [`Progress`] per task, notes and warnings on stderr.
pub struct Terminal;

impl Reporter for Terminal {
    fn task(&self, label: &str) -> Box<dyn Task + '_> {
        Box::new(Progress::new(label))
    }
    fn note(&self, text: &str) {
        eprintln!("{text}");
    }
    fn warn(&self, text: &str) {
        eprintln!("warning: {text}");
    }
}
