//! Batch runs over many datasets measured on one nominal model (e.g. repeated experiments):
//! per dataset the envelope and the check of the configured `r`; over all of them the
//! combined envelope (pointwise maximum) and one `r` fitted above it.
//!
//! Output directory `OUT/`:
//! - `summary.csv`: one row per dataset ([`SummaryRow`]);
//! - `datasets/NAME/envelope.csv`, `datasets/NAME/result.json`: per dataset;
//! - `combined_envelope.csv`: the combined envelope ([`combine`]);
//! - `r.json` (and the other exports of the fit): one `r` covering every dataset;
//! - `batch.json`: counts, shard, fitted `r`, certificate, timings ([`BatchReport`]).
//!
//! Datasets come from a directory or a manifest ([`discover_dir`], [`discover_manifest`]),
//! can be split into shards ([`Shard`]) and the shard outputs recombined ([`merge`]).
//!
//! What is here (the submodules are private; everything below is re-exported here):
//! * the datasets: [`Dataset`], found by [`discover_dir`] (every `*.csv` of a folder) or
//!   [`discover_manifest`] (a CSV `name,data,noise_radius`, only `data` required);
//! * the parallel run: [`run_all`] (and [`run_one`]) with [`BatchSettings`], one
//!   [`DatasetResult`] per dataset, one [`SummaryRow`] of `summary.csv` each;
//! * the batch-wide stage: [`combine`] (the combined envelope, the pointwise maximum) and
//!   [`finish`] ([`FinishInput`]; one `r` fitted above it, the exports and [`BatchReport`]);
//! * shards: [`Shard`] (`--shard K/N`), recombined by [`merge`] or [`merge_then`]
//!   ([`MergeOutcome`]), guarded by [`config_digest`];
//! * exit codes [`EXIT_OK`] and [`EXIT_SOME_FAILED`].
pub(crate) mod combine;
pub(crate) mod discover;
pub(crate) mod merge;
pub(crate) mod runner;
pub(crate) mod shard;
pub(crate) mod summary;

pub use combine::combine;
pub use discover::{discover_dir, discover_manifest, safe_name, Dataset};
pub use merge::{merge, merge_then, MergeOutcome};
pub use runner::{run_all, run_one, BatchSettings, DatasetResult};
pub use shard::Shard;
/// `summary.csv`'s text from its rows (for callers that run the datasets themselves).
pub use summary::render as render_summary;
pub use summary::SummaryRow;

use crate::consistency::{check, Envelope};
use crate::error::{Error, Result};
use crate::pipeline::integration;
use crate::report::envelope_csv;
use crate::report::run_report::Coeffs;
use crate::system::TransferFunction;
use crate::util::write_atomic;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Exit code when every dataset succeeded.
pub const EXIT_OK: i32 = 0;
/// Exit code when some datasets failed (the others completed).
pub const EXIT_SOME_FAILED: i32 = 3;

/// `batch.json`: what a batch (or a merge of shards) did.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BatchReport {
    /// Version of rshape.
    pub rshape_version: String,
    /// The config file.
    pub config: PathBuf,
    /// FNV-1a digest of the config file's bytes (`merge` refuses shards of different
    /// configs); absent in outputs of older versions.
    #[serde(default)]
    pub config_digest: Option<String>,
    /// The config's `[scaling]`: every `r` and `r_min` here is that of the scaled plant.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scaling: Option<crate::report::ScalingNote>,
    /// The configured `r`, if any.
    pub r_configured: Option<CoeffsOwned>,
    /// Datasets in the full (unsharded) list.
    pub n_total: usize,
    /// The shard this output covers (`0/1` for a whole batch or a merge).
    pub shard: Shard,
    /// Datasets processed here.
    pub n_datasets: usize,
    /// Datasets that succeeded.
    pub n_ok: usize,
    /// Datasets that failed.
    pub n_failed: usize,
    /// Datasets the configured `r` explains.
    pub n_consistent: usize,
    /// Frequencies of the combined envelope.
    pub n_frequencies: usize,
    /// Largest finite `r_min` of the combined envelope.
    pub max_r_min: Option<f64>,
    /// True when the configured `r` explains every datum of every successful dataset and A1
    /// holds at each (false when `r` is not admissible somewhere).
    pub consistent_all: Option<bool>,
    /// The `r` fitted above the combined envelope, as in `r.json`.
    pub r_fitted: Option<Value>,
    /// Its certificate.
    pub certificate: Option<Value>,
    /// Why the fit failed.
    pub fit_error: Option<String>,
    /// Shard directories merged into this output (`rshape merge`).
    pub merged_from: Vec<PathBuf>,
    /// Milliseconds per stage.
    pub timings_ms: BTreeMap<String, f64>,
    /// True for closed-loop data (the weight is `V`, not `r`; see [`crate::plot::Symbols`]).
    #[serde(default)]
    pub closed_loop: bool,
}

/// Coefficients of `r` (owned, deserializable twin of [`Coeffs`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CoeffsOwned {
    /// Numerator, descending powers of `s`.
    pub num: Vec<f64>,
    /// Denominator, descending powers of `s`.
    pub den: Vec<f64>,
}

impl From<&TransferFunction> for CoeffsOwned {
    fn from(r: &TransferFunction) -> Self {
        let c = Coeffs {
            num: r.num.coeffs().to_vec(),
            den: r.den.coeffs().to_vec(),
        };
        CoeffsOwned {
            num: c.num,
            den: c.den,
        }
    }
}

/// `batch.svg`: every dataset's envelope, the combined one and the configured and fitted `r`.
fn figure(
    config: &Path,
    datasets: &[&Envelope],
    combined: &Envelope,
    r_configured: Option<&TransferFunction>,
    r_fitted: Option<&TransferFunction>,
    closed_loop: bool,
    factorization: Option<&crate::model::Factorization>,
) -> Result<String> {
    let name = config
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned());
    let title = if datasets.is_empty() {
        format!("Batch: combined envelope and one r — {name}")
    } else {
        format!(
            "Batch: {} datasets, combined envelope and one r — {name}",
            datasets.len()
        )
    };
    let per: Vec<(&[f64], &[f64])> = datasets
        .iter()
        .map(|e| (e.omega.as_slice(), e.r_min.as_slice()))
        .collect();
    // The figure spans every dataset's frequencies, not only the combined envelope's.
    let mut all: Vec<f64> = combined
        .omega
        .iter()
        .chain(datasets.iter().flat_map(|e| e.omega.iter()))
        .copied()
        .filter(|w| w.is_finite() && *w > 0.0)
        .collect();
    all.sort_by(f64::total_cmp);
    all.dedup();
    let grid = crate::pipeline::outputs::dense_grid(&all);
    let a1: Option<Vec<f64>> = factorization.map(|f| grid.iter().map(|w| f.a1_limit(*w)).collect());
    crate::plot::batch_svg(
        &crate::plot::BatchFigureInput {
            title: &title,
            datasets: &per,
            combined: (&combined.omega, &combined.r_min),
            r_configured,
            r_fitted,
            grid: &grid,
            a1_on_grid: a1.as_deref(),
        },
        &crate::plot::Symbols::of(closed_loop),
    )
}

/// What the batch-wide stage needs besides the rows and the combined envelope.
pub struct FinishInput<'a> {
    /// The config file.
    pub config: PathBuf,
    /// Digest of the config file ([`config_digest`]).
    pub config_digest: Option<String>,
    /// The config's `[scaling]`, noted in `r.json` and `batch.json`.
    pub scaling: Option<crate::report::ScalingNote>,
    /// The configured `r`.
    pub r_configured: Option<&'a TransferFunction>,
    /// Datasets in the full list.
    pub n_total: usize,
    /// The shard.
    pub shard: Shard,
    /// Shard directories merged.
    pub merged_from: Vec<PathBuf>,
    /// Timings so far.
    pub timings_ms: BTreeMap<String, f64>,
    /// Order of the fitted `r` (or automatic).
    pub order: crate::fit::OrderChoice,
    /// The model, for the A1 limit `σ_min(M̃(jω))` the fitted `r` must stay below.
    pub factorization: Option<&'a crate::model::Factorization>,
    /// Closed-loop data (the weight is `V`).
    pub closed_loop: bool,
    /// Per-dataset envelopes for `batch.svg` (empty after `merge`, which has only the
    /// combined one).
    pub datasets: Vec<&'a Envelope>,
}

/// A 64-bit FNV-1a digest (hex) of the config file's bytes: shards whose configs differ in
/// any byte are not merged.  `None` when the file cannot be read.
pub fn config_digest(path: &Path) -> Option<String> {
    let bytes = std::fs::read(path).ok()?;
    let h = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0000_0100_0000_01b3)
    });
    Some(format!("{h:016x}"))
}

/// The batch-wide stage, shared by `batch` and `merge`: fits one `r` above the combined
/// envelope, writes `combined_envelope.csv`, the exports, `summary.csv` and, last,
/// `batch.json` into `out`.
pub fn finish(
    out: &Path,
    rows: &[SummaryRow],
    combined: Option<&Envelope>,
    inp: FinishInput,
) -> Result<BatchReport> {
    let mut timings = inp.timings_ms;
    let t = std::time::Instant::now();
    let fit = combined.map(|env| integration::fit_r(env, inp.factorization, inp.order, None));
    timings.insert("fit".into(), t.elapsed().as_secs_f64() * 1e3);
    let t = std::time::Instant::now();
    if let Some(env) = combined {
        write_atomic(
            &out.join("combined_envelope.csv"),
            envelope_csv(env).as_bytes(),
        )?;
    }
    if let Some(Ok(f)) = &fit {
        crate::report::write_fit_exports(&f.result, f.table.as_deref(), out, inp.scaling.as_ref())?;
    }
    write_atomic(&out.join("summary.csv"), summary::render(rows).as_bytes())?;
    if let Some(env) = combined {
        let fitted = fit.as_ref().and_then(|f| f.as_ref().ok()).map(|f| &f.r);
        let svg = figure(
            &inp.config,
            &inp.datasets,
            env,
            inp.r_configured,
            fitted,
            inp.closed_loop,
            inp.factorization,
        )?;
        write_atomic(&out.join("batch.svg"), svg.as_bytes())?;
    }
    timings.insert("write".into(), t.elapsed().as_secs_f64() * 1e3);
    let ok = rows.iter().filter(|r| r.ok).count();
    let report = BatchReport {
        rshape_version: env!("CARGO_PKG_VERSION").to_string(),
        config: inp.config,
        config_digest: inp.config_digest,
        scaling: inp.scaling,
        r_configured: inp.r_configured.map(CoeffsOwned::from),
        n_total: inp.n_total,
        shard: inp.shard,
        n_datasets: rows.len(),
        n_ok: ok,
        n_failed: rows.len() - ok,
        n_consistent: rows.iter().filter(|r| r.consistent == Some(true)).count(),
        n_frequencies: combined.map_or(0, |e| e.len()),
        max_r_min: combined.and_then(|e| {
            e.r_min
                .iter()
                .copied()
                .filter(|x| x.is_finite())
                .reduce(f64::max)
        }),
        consistent_all: match (inp.r_configured, combined) {
            (Some(r), Some(env)) => Some(check(r, env).consistent),
            _ => None,
        },
        r_fitted: fit
            .as_ref()
            .and_then(|f| f.as_ref().ok())
            .map(|f| f.json.clone()),
        certificate: fit
            .as_ref()
            .and_then(|f| f.as_ref().ok())
            .map(|f| f.certificate.clone()),
        fit_error: match &fit {
            Some(Err(e)) => Some(crate::report::fmt::one_line(&e.to_string())),
            None => Some("no dataset succeeded: nothing to fit".into()),
            _ => None,
        },
        merged_from: inp.merged_from,
        timings_ms: timings,
        closed_loop: inp.closed_loop,
    };
    let text = serde_json::to_string_pretty(&report)
        .map_err(|e| Error::Invalid(format!("batch.json: {e}")))?;
    write_atomic(&out.join("batch.json"), text.as_bytes())?;
    Ok(report)
}
