//! Progress on long runs: a bar on a terminal, a periodic log line otherwise (CI, pipes).

use gyroemu_experiment::{Reporter, Task, Written};
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
            note!(
                "{}: {:.0}% ({done} of {total} samples, {:.0} s)",
                self.label,
                100.0 * done as f64 / total.max(1) as f64,
                self.start.elapsed().as_secs_f64()
            );
        }
    }

    /// Closes the bar and prints the emulation's throughput, then what writing the dumps
    /// took (its time is not counted as emulation).
    fn finish_counted(&self, point_samples: u64, written: Written) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
        let s = (self.start.elapsed().as_secs_f64() - written.seconds).max(0.0);
        note!("{}", counted_line(&self.label, point_samples, s, written));
    }

    /// Closes the bar and prints the elapsed time (for runs whose size is not in point-samples).
    fn finish_elapsed(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
        note!(
            "{}: done in {:.1} s",
            self.label,
            self.start.elapsed().as_secs_f64()
        );
    }
}

/// `label: N point-samples in T s (R M point-samples/s)`, then `; writing dumps: X MB in
/// Y s (Z MB/s)` when files were written. Emulation and writing are timed apart: a dump's
/// CSV can take longer to write than the emulation that produced it.
pub fn counted_line(label: &str, point_samples: u64, emulation_s: f64, written: Written) -> String {
    let mut line = format!(
        "{label}: {point_samples} point-samples in {emulation_s:.1} s ({:.0} M point-samples/s)",
        point_samples as f64 / emulation_s.max(1e-9) / 1e6
    );
    if written.files > 0 {
        let mb = written.bytes as f64 / 1e6;
        line.push_str(&format!(
            "; writing dumps: {mb:.1} MB in {} files in {:.2} s ({:.0} MB/s)",
            written.files,
            written.seconds,
            mb / written.seconds.max(1e-9)
        ));
    }
    line
}

impl Task for Progress {
    fn update(&self, done: u64, total: u64) {
        self.update_now(done, total);
    }
    fn finish(&self, point_samples: Option<u64>) {
        self.finish_writing(point_samples, Written::default());
    }
    fn finish_writing(&self, point_samples: Option<u64>, written: Written) {
        match point_samples {
            Some(n) => self.finish_counted(n, written),
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
        note!("{text}");
    }
    fn warn(&self, text: &str) {
        note!("warning: {text}");
    }
}
