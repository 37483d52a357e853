//! Progress of a long experiment on stderr: a bar with an ETA on a terminal, plain lines
//! (about every 5 % of the work) when stderr is a file or a pipe (a log, a Slurm job).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::Instant;

/// Progress through a fixed number of units of work, shown on stderr; the bar is cleared when dropped.
pub struct Progress {
    label: String,
    total: u64,
    done: u64,
    start: Instant,
    bar: Option<ProgressBar>,
    next_line: u64,
}

impl Progress {
    /// Starts counting `total` units of work under `label`.
    pub fn new(label: &str, total: u64) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {elapsed} elapsed, ETA {eta}")
                    .expect("a valid template")
                    .progress_chars("=> "),
            );
            bar.set_prefix(label.to_owned());
            bar
        });
        if bar.is_none() {
            eprintln!("{label}: 0/{total}");
        }
        Self {
            label: label.to_owned(),
            total,
            done: 0,
            start: Instant::now(),
            bar,
            next_line: 0,
        }
    }

    /// One more unit of work done.
    pub fn inc(&mut self) {
        self.done += 1;
        match &self.bar {
            Some(bar) => bar.inc(1),
            None if self.done >= self.next_line || self.done == self.total => {
                let elapsed = self.start.elapsed().as_secs_f64();
                let eta = elapsed / self.done as f64 * (self.total - self.done) as f64;
                eprintln!(
                    "{}: {}/{} done, {elapsed:.0} s elapsed, ETA {eta:.0} s",
                    self.label, self.done, self.total
                );
                self.next_line = self.done + (self.total / 20).max(1);
            }
            None => {}
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
