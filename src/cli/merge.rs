//! `rshape merge SHARD_DIR... --out OUT`: combines the outputs of `rshape batch --shard`.
//! Exit 0 when every merged dataset succeeded, 3 when some failed or are missing, 2 on an
//! error.

use crate::batch::{self, merge_then};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `rshape merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Output directories of the shards.
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Output directory of the merged batch.
    #[arg(long)]
    pub out: PathBuf,
    /// Order of the r fitted above the merged envelope, or `auto` (sweep 0..8).
    #[arg(long, default_value = "auto", allow_negative_numbers = true)]
    pub order: crate::fit::OrderChoice,
}

/// Runs `rshape merge`.
pub fn run(a: &MergeArgs) -> Result<i32> {
    let t = std::time::Instant::now();
    // The shards are inputs: --out may not be one of them (nor a file); the previous
    // merge's files in --out are cleared once every shard has been read.
    let mut guard = None;
    let shards: Vec<&std::path::Path> = a.shards.iter().map(|p| p.as_path()).collect();
    let m = merge_then(&a.shards, &a.out, a.order, &mut || {
        guard = Some(
            super::common::prepare_out(&a.out, &shards)
                .map_err(|e| crate::error::Error::Invalid(e.to_string()))?,
        );
        Ok(())
    })?;
    drop(guard);
    super::batch::print_summary(&m.report, &m.rows, &a.out, t.elapsed().as_secs_f64());
    if !m.missing.is_empty() {
        outln!(
            "  MISSING {} dataset(s) of {} (indices {}): merge every shard",
            m.missing.len(),
            m.report.n_total,
            m.missing
                .iter()
                .take(20)
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(if m.report.n_failed > 0 || !m.missing.is_empty() {
        batch::EXIT_SOME_FAILED
    } else {
        batch::EXIT_OK
    })
}
