//! Command-line interface.  Each subcommand lives in its own file and is a thin layer over
//! the library: parse, load, compute, print, write (atomically).
//!
//! Exit codes: 0 success (and consistent, for `check`), 1 inconsistent data (`check`),
//! 2 any error (bad input, usage), 3 some datasets failed (`batch`).

/// `println!` that ignores a closed stdout (`rshape ... | head` must not panic).
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

pub mod batch;
pub mod check;
pub mod common;
pub mod compare;
pub mod diagnose;
pub mod envelope;
pub mod fit;
pub mod history;
pub mod merge;
pub mod progress;
pub mod run;
pub mod stability;

use clap::{Parser, Subcommand};

/// rshape: consistency of frequency-response data with coprime-factor models, and the
/// smallest uncertainty bound r(s) that explains them.
#[derive(Debug, Parser)]
#[command(name = "rshape", version, about, long_about = None)]
pub struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Per-datum smallest |r| consistent with the data (the lower envelope) and the A1 limit.
    Envelope(envelope::EnvelopeArgs),
    /// Check the configured r (or --r-num/--r-den) against every datum.
    Check(check::CheckArgs),
    /// The whole pipeline: envelope, check, fit, certificate, exports, figures, report.json.
    Run(run::RunArgs),
    /// Many datasets on one model, in parallel: per-dataset envelopes, summary.csv, one r.
    Batch(batch::BatchArgs),
    /// Combine the outputs of `batch --shard K/N` runs.
    Merge(merge::MergeArgs),
    /// Compare the model with the data: misfit per frequency, failing bands, error measures.
    Compare(compare::CompareArgs),
    /// Rank candidate missing effects (delay, lag, mode, …) by how much each lowers the error.
    Diagnose(diagnose::DiagnoseArgs),
    /// Error measures across model revisions (table and error-vs-revision SVG).
    History(history::HistoryArgs),
    /// Fit the smallest certified unit r(s) above the envelope (or an envelope file).
    Fit(fit::FitArgs),
    /// Theorem 1: does a controller stabilize every plant of the set (margin with each r)?
    Stability(stability::StabilityArgs),
}

/// Runs the CLI and returns the process exit code.
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) if e.use_stderr() => {
            // One line, like every other error: clap's message, tip and usage joined.
            let text = e.render().to_string();
            let parts: Vec<&str> = (text.lines())
                .map(|l| l.trim().trim_start_matches("error: "))
                .filter(|l| !l.is_empty() && !l.starts_with("For more information"))
                .collect();
            eprintln!("error: {}", one_line(&parts.join("; ")));
            return 2;
        }
        Err(e) => {
            let _ = e.print();
            return 0;
        }
    };
    let result = match cli.command {
        Command::Envelope(a) => envelope::run(&a),
        Command::Check(a) => check::run(&a),
        Command::Run(a) => run::run(&a),
        Command::Batch(a) => batch::run(&a),
        Command::Merge(a) => merge::run(&a),
        Command::Compare(a) => compare::run(&a),
        Command::Diagnose(a) => diagnose::run(&a),
        Command::History(a) => history::run(&a),
        Command::Fit(a) => fit::run(&a),
        Command::Stability(a) => stability::run(&a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", one_line(&format!("{e:#}")));
            2
        }
    }
}

pub use crate::report::fmt::one_line;
