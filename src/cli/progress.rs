//! Progress of a long fit (or run) on stderr, rendered from the library's [`FitProgress`]
//! reports and per-datum counts of the noisy envelope: an indicatif spinner on a terminal,
//! otherwise (a log, CI) one line every few seconds, and nothing at all for a job that ends
//! within those seconds.

use crate::fit::FitProgress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Seconds between two progress lines when stderr is not a terminal.
const LINE_EVERY: Duration = Duration::from_secs(5);

/// A progress display for one fit.
pub struct FitProgressView {
    bar: Option<ProgressBar>,
    start: Instant,
    last_line: Mutex<Instant>,
    label: String,
}

impl FitProgressView {
    /// A display labelled `label` (`fit`, `stability --fit`, …).
    pub fn new(label: &str) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template("{spinner} {msg}  {elapsed_precise}")
                    .expect("valid template"),
            );
            b.enable_steady_tick(Duration::from_millis(200));
            b
        });
        Self {
            bar,
            start: Instant::now(),
            last_line: Mutex::new(Instant::now()),
            label: label.into(),
        }
    }

    /// Renders one report of the library.
    pub fn update(&self, p: FitProgress) {
        let msg = format!(
            "{}: order {} of 0..{}, {} LPs so far",
            self.label, p.order, p.last_order, p.lp_solves
        );
        self.show(msg);
    }

    /// Renders the library's report of a per-datum stage (`what`: `envelope`, …): `done` of
    /// `total` data.
    pub fn data(&self, what: &str, done: usize, total: usize) {
        self.show(format!(
            "{}: {what}, {done} of {total} data",
            self.stage_label()
        ));
    }

    /// Renders a count inside a long stage (`what`: `search level 2, joint refits`), at most
    /// one line every few seconds when stderr is not a terminal.
    pub fn count(&self, what: &str, done: usize, total: usize) {
        self.show(format!("{}: {what} {done} of {total}", self.stage_label()));
    }

    /// Announces a long stage at once (a line even when stderr is not a terminal): a large
    /// model's loop, whose dense eigenvalue problems give no report while they run.
    pub fn stage(&self, what: &str) {
        let msg = format!("{}: {what}", self.stage_label());
        match &self.bar {
            Some(b) => b.set_message(msg),
            None => eprintln!("{msg} ({:.0} s)", self.start.elapsed().as_secs_f64()),
        }
    }

    /// `run: fit` → `run` (the label of the whole command, for its other stages).
    fn stage_label(&self) -> &str {
        self.label.split(':').next().unwrap_or(&self.label)
    }

    fn show(&self, msg: String) {
        match &self.bar {
            Some(b) => b.set_message(msg),
            None => {
                let Ok(mut last) = self.last_line.lock() else {
                    return;
                };
                if last.elapsed() >= LINE_EVERY {
                    *last = Instant::now();
                    eprintln!("{msg} ({:.0} s)", self.start.elapsed().as_secs_f64());
                }
            }
        }
    }

    /// Clears the bar (the final report is printed by the caller).
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl Drop for FitProgressView {
    fn drop(&mut self) {
        self.finish();
    }
}
