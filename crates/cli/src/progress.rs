//! Progress on long runs: a bar on a terminal, a periodic log line otherwise (CI, pipes).

use gyroemu_core::sig3;
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
/// CSV can take longer to write than the emulation that produced it. A rate whose time is
/// not positive (the writing's time covered the whole run) is said to be unmeasured rather
/// than divided by a floor into a figure no run reached.
pub fn counted_line(label: &str, point_samples: u64, emulation_s: f64, written: Written) -> String {
    let mut line = format!(
        "{label}: {point_samples} point-samples in {} s ({})",
        sig3(emulation_s),
        rate(point_samples as f64 / 1e6, emulation_s, "M point-samples/s")
    );
    if written.files > 0 {
        let mb = written.bytes as f64 / 1e6;
        line.push_str(&format!(
            "; writing dumps: {} MB in {} files in {} s ({})",
            sig3(mb),
            written.files,
            sig3(written.seconds),
            rate(mb, written.seconds, "MB/s")
        ));
    }
    line
}

/// `amount / seconds` to three significant figures with its `unit`, or a note that no time
/// was measured to divide by.
fn rate(amount: f64, seconds: f64, unit: &str) -> String {
    if seconds > 0.0 && seconds.is_finite() {
        format!("{} {unit}", sig3(amount / seconds))
    } else {
        format!("{unit}: no time measured")
    }
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

#[cfg(test)]
mod tests {
    use super::counted_line;
    use gyroemu_experiment::Written;

    /// Every figure of the line to three significant figures whatever its size (an emulated
    /// CPU's 0.14 M point-samples/s once read as `0 M`, a slow disk's 0.4 MB/s as `0 MB/s`).
    #[test]
    fn the_counted_line_gives_slow_and_fast_rates_their_figures() {
        let none = Written::default();
        let slow = counted_line("run", 548_400, 3.91, none);
        assert_eq!(
            slow,
            "run: 548400 point-samples in 3.91 s (0.140 M point-samples/s)"
        );
        let fast = counted_line("reproduce", 1_297_000_000, 1.3, none);
        assert!(
            fast.ends_with("in 1.30 s (998 M point-samples/s)"),
            "{fast}"
        );
        let dumps = Written {
            files: 3,
            bytes: 2_500_000,
            seconds: 0.5,
        };
        let with = counted_line("run", 1000, 0.0104, dumps);
        assert!(
            with.ends_with("in 0.0104 s (0.0962 M point-samples/s); writing dumps: 2.50 MB in 3 files in 0.500 s (5.00 MB/s)"),
            "{with}"
        );
    }

    /// A time of zero gives no rate: a floor under it once printed 1e9 times the count.
    #[test]
    fn a_time_of_zero_gives_no_rate() {
        let dumps = Written {
            files: 2,
            bytes: 1_000_000,
            seconds: 0.0,
        };
        let line = counted_line("run", 5_000_000, 0.0, dumps);
        assert_eq!(
            line,
            "run: 5000000 point-samples in 0 s (M point-samples/s: no time measured); \
             writing dumps: 1.00 MB in 2 files in 0 s (MB/s: no time measured)"
        );
    }
}
