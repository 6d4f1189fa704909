//! Command-line interface.  Each subcommand lives in its own file and is a thin layer over
//! the library: parse, load, compute, print, write (atomically).
//!
//! Exit codes: 0 success (and consistent, for `check`; robustly stable, for `stability`),
//! 1 a negative verdict (`check`: inconsistent or not admissible; `stability`), 2 any error
//! (bad input, usage), 3 some datasets failed (`batch`, `merge`).  Each subcommand's
//! `--help` states its own.

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
pub mod synthesize;

use clap::{Parser, Subcommand};

/// rshape: consistency of frequency-response data with coprime-factor models, the smallest
/// uncertainty bound r(s) that explains them, robust-stability proofs and controller
/// synthesis (Glover–McFarlane, H∞), and discovery of missing effects.
#[derive(Debug, Parser)]
#[command(
    name = "rshape",
    version,
    about = "Consistency of frequency-response data with coprime-factor models, the smallest uncertainty bound r(s) that explains them, robust-stability proofs, controller synthesis (Glover–McFarlane, H∞) and discovery of missing effects",
    long_about = None,
    after_help = "Exit codes: 0 success; 1 a negative verdict (check: inconsistent or not admissible; stability: not robustly stable; synthesize: not proven robust); 2 error (bad input, usage); 3 some datasets failed (batch, merge).  `rshape help SUBCOMMAND` gives each subcommand's."
)]
pub struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Per-datum smallest |r| consistent with the data (the lower envelope) and the A1 limit.
    #[command(after_help = "Exit codes: 0 envelope written, 2 error (bad input, usage).")]
    Envelope(envelope::EnvelopeArgs),
    /// Check the configured r (or --r-num/--r-den) against every datum.
    #[command(
        after_help = "Exit codes: 0 consistent (|r| > r_min and A1 holds at every datum), 1 inconsistent or not admissible (A1 fails: |r| >= sigma_min(M~) at some datum), 2 error (bad input, usage)."
    )]
    Check(check::CheckArgs),
    /// The whole pipeline: envelope, check, fit, certificate, exports, figures, report.json.
    #[command(
        after_help = "Exit codes: 0 the pipeline completed, whatever the verdict (read `verdict` in DIR/report.json, or gate on `rshape check`), 2 error (bad input, usage; no half-written file is left)."
    )]
    Run(run::RunArgs),
    /// Many datasets on one model, in parallel: per-dataset envelopes, summary.csv, one r.
    #[command(
        after_help = "Exit codes: 0 every dataset processed, 3 some datasets failed (listed in summary.csv; the others are complete), 2 error (bad config, manifest or usage)."
    )]
    Batch(batch::BatchArgs),
    /// Combine the outputs of `batch --shard K/N` runs.
    #[command(
        after_help = "Exit codes: 0 every merged dataset succeeded, 3 some failed or shards are missing, 2 error (bad input, usage)."
    )]
    Merge(merge::MergeArgs),
    /// Compare the model with the data: misfit per frequency, failing bands, error measures.
    #[command(
        after_help = "Exit codes: 0 comparison printed (whatever the verdict; read `verdict` with --json), 2 error (bad input, usage)."
    )]
    Compare(compare::CompareArgs),
    /// Rank candidate missing effects (delay, lag, mode, …) by how much each lowers the error.
    #[command(
        after_help = "Exit codes: 0 ranking printed (or --write done), 2 error (bad input, usage)."
    )]
    Diagnose(diagnose::DiagnoseArgs),
    /// Error measures across model revisions (table and error-vs-revision SVG).
    #[command(after_help = "Exit codes: 0 table printed, 2 error (bad input, usage).")]
    History(history::HistoryArgs),
    /// Fit the smallest certified unit r(s) above the envelope (or an envelope file).
    #[command(
        after_help = "Exit codes: 0 r fitted and certified, 2 error (bad input, usage, or no certified r)."
    )]
    Fit(fit::FitArgs),
    /// Theorem 1: does a controller stabilize every plant of the set (margin with each r)?
    #[command(
        after_help = "Exit codes: 0 robustly stable for every bound given, 1 not (including a controller that does not stabilize the nominal plant), 2 error (bad input, usage)."
    )]
    Stability(stability::StabilityArgs),
    /// Synthesize a controller (Glover–McFarlane, or H∞ with r as weight) and prove it with Theorem 1.
    #[command(
        after_help = "Exit codes: 0 proven robust for every bound given (and stabilizing), 1 not proven robust for some bound (the controller and reports are still written), 2 error (bad input, usage; nothing is written)."
    )]
    Synthesize(synthesize::SynthesizeArgs),
}

/// Runs the CLI and returns the process exit code.
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) if e.use_stderr() => {
            // One line, like every other error: clap's message with the missing or wrong
            // arguments named inline, then the usage.
            let mut text = e.render().to_string();
            if let Some(better) = suggestion(&e) {
                // clap's "to pass '--ouput' as a value, use '-- --ouput'" misleads: a
                // mistyped option is far likelier.
                text = match text.find("tip:") {
                    Some(k) => {
                        let end = text[k..].find('\n').map_or(text.len(), |n| k + n);
                        format!("{}tip: did you mean {better}?{}", &text[..k], &text[end..])
                    }
                    None => format!("{text}\ntip: did you mean {better}?"),
                };
            }
            let lines: Vec<&str> = (text.lines())
                .map(|l| l.trim().trim_start_matches("error: "))
                .filter(|l| !l.is_empty() && !l.starts_with("For more information"))
                .collect();
            let (usage, rest): (Vec<&str>, Vec<&str>) =
                lines.into_iter().partition(|l| l.starts_with("Usage:"));
            let mut msg = match rest.split_first() {
                // "the following required arguments were not provided:" + one per line
                Some((head, args)) if head.ends_with(':') && !args.is_empty() => {
                    format!("{head} {}", args.join(", "))
                }
                _ => rest.join(" "),
            };
            if let Some(u) = usage.first() {
                msg = format!("{msg} ({})", u.replacen("Usage:", "usage:", 1));
            }
            let parts = [msg];
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
        Command::Synthesize(a) => synthesize::run(&a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!(
                "error: {}",
                capped(&crate::report::fmt::short_numbers(&one_line(&format!(
                    "{e:#}"
                ))))
            );
            2
        }
    }
}

pub use crate::report::fmt::one_line;

/// For an unknown `--option`: the subcommand's long option nearest to it (edit distance at
/// most 2, or a prefix either way), when clap offered none.
fn suggestion(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() != ErrorKind::UnknownArgument {
        return None;
    }
    if let Some(ContextValue::Strings(s)) = e.get(ContextKind::SuggestedArg) {
        if !s.is_empty() {
            return None;
        }
    }
    if let Some(ContextValue::String(_)) = e.get(ContextKind::SuggestedArg) {
        return None;
    }
    let Some(ContextValue::String(bad)) = e.get(ContextKind::InvalidArg) else {
        return None;
    };
    let bad = bad.strip_prefix("--")?.split('=').next()?.to_string();
    let sub = std::env::args().skip(1).find(|a| !a.starts_with('-'))?;
    let cmd = <Cli as clap::CommandFactory>::command();
    let sub = cmd.find_subcommand(&sub)?;
    sub.get_arguments()
        .filter_map(|a| a.get_long())
        .map(|l| (edit_distance(&bad, l), l))
        .filter(|(d, l)| *d <= 2 || (bad.len() >= 3 && (l.starts_with(&bad) || bad.starts_with(l))))
        .min_by_key(|(d, _)| *d)
        .map(|(_, l)| format!("--{l}"))
}

/// Levenshtein distance (characters).
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Longest error message printed, in characters: the start (what and where) and the end
/// (what to do) are kept, a middle that quotes input at length is cut.
pub const MAX_MESSAGE_CHARS: usize = 600;

fn capped(msg: &str) -> String {
    let n = msg.chars().count();
    if n <= MAX_MESSAGE_CHARS {
        return msg.to_string();
    }
    let head: String = msg.chars().take(MAX_MESSAGE_CHARS - 160).collect();
    let tail: String = msg.chars().skip(n - 150).collect();
    format!(
        "{head} … [{} characters cut] … {tail}",
        n - (MAX_MESSAGE_CHARS - 160) - 150
    )
}
