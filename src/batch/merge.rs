//! `rshape merge`: combines the outputs of shards (`rshape batch --shard K/N`) into one:
//! the summary rows in dataset order, the pointwise maximum of the shards' combined
//! envelopes and one `r` fitted above it.  The per-dataset files stay in the shard
//! directories.

use super::combine::{combine, parse_envelope_csv};
use super::summary::{self, SummaryRow};
use super::{finish, BatchReport, FinishInput, Shard};
use crate::error::{Error, Result};
use crate::system::TransferFunction;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn read(path: &Path) -> Result<String> {
    crate::util::read_text_file(path)
}

/// What a merge found besides the report.
#[derive(Debug, Clone)]
pub struct MergeOutcome {
    /// The merged `batch.json`.
    pub report: BatchReport,
    /// The merged rows, in dataset order.
    pub rows: Vec<SummaryRow>,
    /// Indices of the full list that no shard covered.
    pub missing: Vec<usize>,
}

/// Merges shard directories into `out`.  Two shards holding the same dataset index, or
/// shards of different batches (different totals), are errors.
pub fn merge(
    shards: &[PathBuf],
    out: &Path,
    order: crate::fit::OrderChoice,
) -> Result<MergeOutcome> {
    merge_then(shards, out, order, &mut || Ok(()))
}

/// As [`merge`], calling `before_write` once every shard has been read and checked and
/// before anything is written (the CLI prepares the output folder there, so a bad shard
/// leaves no trace in `out`).
pub fn merge_then(
    shards: &[PathBuf],
    out: &Path,
    order: crate::fit::OrderChoice,
    before_write: &mut dyn FnMut() -> Result<()>,
) -> Result<MergeOutcome> {
    let t = std::time::Instant::now();
    if shards.is_empty() {
        return Err(Error::Invalid("give at least one shard directory".into()));
    }
    let mut rows: Vec<SummaryRow> = Vec::new();
    let mut envs = Vec::new();
    let mut first: Option<BatchReport> = None;
    for dir in shards {
        let bj = dir.join("batch.json");
        let rep: BatchReport = serde_json::from_str(&read(&bj)?).map_err(|e| Error::Input {
            path: bj.to_path_buf(),
            msg: format!("not a batch.json of rshape: {e}"),
        })?;
        if let Some(f) = &first {
            // Shards of different configs would mix two models' envelopes under one r.
            let differ = match (&f.config_digest, &rep.config_digest) {
                (Some(a), Some(b)) => a != b,
                _ => f.config != rep.config,
            } || f.closed_loop != rep.closed_loop;
            if differ {
                return Err(Error::Input {
                    path: dir.to_path_buf(),
                    msg: format!(
                        "this shard was made from the config {} ({}), the first one from {} ({}): merge only the shards of one batch (same config)",
                        rep.config.display(),
                        rep.config_digest.as_deref().unwrap_or("no digest"),
                        f.config.display(),
                        f.config_digest.as_deref().unwrap_or("no digest"),
                    ),
                });
            }
            if f.n_total != rep.n_total {
                return Err(Error::Input {
                    path: dir.to_path_buf(),
                    msg: format!(
                        "this shard comes from a batch of {} datasets, the first one from a batch of {}",
                        rep.n_total,
                        f.n_total,
                    ),
                });
            }
        }
        let sp = dir.join("summary.csv");
        rows.extend(summary::parse(&read(&sp)?, &sp.display().to_string())?);
        let ep = dir.join("combined_envelope.csv");
        if ep.exists() {
            envs.push(parse_envelope_csv(&read(&ep)?, &ep.display().to_string())?);
        }
        first.get_or_insert(rep);
    }
    let first = first.expect("at least one shard");
    rows.sort_by_key(|r| r.index);
    if let Some(w) = rows.windows(2).find(|w| w[0].index == w[1].index) {
        return Err(Error::Invalid(format!(
            "dataset {} (`{}`) appears in two shards: merge each shard once",
            w[0].index, w[0].name
        )));
    }
    let have: BTreeSet<usize> = rows.iter().map(|r| r.index).collect();
    let missing: Vec<usize> = (0..first.n_total).filter(|i| !have.contains(i)).collect();
    let combined = combine(envs.iter());
    let r = first
        .r_configured
        .as_ref()
        .map(|c| TransferFunction::new(c.num.clone(), c.den.clone()));
    // The model (for the A1 limit of the fit) from the config the shards ran with, if it
    // can still be read.
    let config = crate::model::Config::load(&first.config).ok();
    let mut timings = BTreeMap::new();
    timings.insert("read".into(), t.elapsed().as_secs_f64() * 1e3);
    before_write()?;
    let report = finish(
        out,
        &rows,
        combined.as_ref(),
        FinishInput {
            config: first.config.clone(),
            config_digest: first.config_digest.clone(),
            // The shards ran with the same config (its digest): the same scaling.
            scaling: first.scaling.clone(),
            r_configured: r.as_ref(),
            n_total: first.n_total,
            shard: Shard::ALL,
            merged_from: shards.to_vec(),
            timings_ms: timings,
            order,
            factorization: config
                .as_ref()
                .and_then(crate::pipeline::closed_loop::a1_factorization),
            closed_loop: first.closed_loop,
            datasets: Vec::new(),
        },
    )?;
    Ok(MergeOutcome {
        report,
        rows,
        missing,
    })
}
