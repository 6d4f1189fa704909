//! Batch: many datasets on one model ([`rshape::batch`]): the datasets of a folder or a
//! manifest, one dataset at a time (for Dask and other engines), `summary.csv` from rows,
//! and the whole batch in rayon threads with the combined envelope and one fitted `r`.

use crate::core::{noise_arg, order_arg, Envelope, FitHandle};
use crate::data::Config;
use crate::errors::{guarded, input, OrRaise};
use pyo3::prelude::*;
use rshape::batch::{self, BatchSettings, Dataset, DatasetResult, SummaryRow};
use rshape::consistency::Verdict;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

/// `(index, name, path, noise_radius)` of a dataset.
type DatasetTuple = (usize, String, PathBuf, Option<f64>);
/// A `summary.csv` row: index, name, ok, n_data, max_r_min, consistent, verdict, n_failing,
/// data, error.
type RowTuple = (
    usize,
    String,
    bool,
    usize,
    Option<f64>,
    Option<bool>,
    Option<String>,
    usize,
    String,
    String,
);

/// The datasets of `--data-dir DIR` or `--manifest FILE`, as `rshape batch` finds them.
#[pyfunction]
#[pyo3(signature = (data_dir=None, manifest=None))]
pub fn _discover(
    py: Python<'_>,
    data_dir: Option<PathBuf>,
    manifest: Option<PathBuf>,
) -> PyResult<Vec<DatasetTuple>> {
    guarded(py, || {
        let list = match (data_dir, manifest) {
            (Some(d), None) => batch::discover_dir(&d).py()?,
            (None, Some(m)) => batch::discover_manifest(&m).py()?,
            _ => return Err(input("discover: give data_dir or manifest (one of them)")),
        };
        Ok(list
            .into_iter()
            .map(|d| (d.index, d.name, d.path, d.noise_radius))
            .collect())
    })
}

/// The directory-safe dataset name of a file stem (as `rshape batch` names datasets).
#[pyfunction]
pub fn _safe_name(s: &str) -> String {
    batch::safe_name(s)
}

fn dataset((index, name, path, noise_radius): DatasetTuple) -> Dataset {
    Dataset {
        index,
        name,
        path,
        noise_radius,
    }
}

/// A dataset's result: its JSON (`datasets/NAME/result.json`), its envelope, its
/// `summary.csv` row (kept exact: JSON has no `inf`).
type ResultOut = (String, Option<Envelope>, RowTuple);

fn row_tuple(r: &SummaryRow) -> RowTuple {
    (
        r.index,
        r.name.clone(),
        r.ok,
        r.n_data,
        r.max_r_min,
        r.consistent,
        r.verdict.map(|v| v.as_str().to_string()),
        r.n_failing,
        r.data.clone(),
        r.error.clone(),
    )
}

fn result_out(r: DatasetResult, config: &Arc<rshape::Config>) -> PyResult<ResultOut> {
    let json = serde_json::to_string(&r).map_err(|e| input(e.to_string()))?;
    let row = row_tuple(&SummaryRow::from(&r));
    let env = r.envelope.map(|e| Envelope {
        inner: Arc::new(e),
        config: Some(config.clone()),
        noise_radii: None,
        warnings: r.warnings.clone(),
    });
    Ok((json, env, row))
}

/// One dataset as `rshape batch` processes it (envelope and check of the configured r; a
/// failure is a failed result, not an exception): the result's JSON and its envelope.
#[pyfunction]
#[pyo3(signature = (config, dataset, noise_radius=None))]
pub fn _run_dataset(
    py: Python<'_>,
    config: &Config,
    dataset: DatasetTuple,
    noise_radius: Option<f64>,
) -> PyResult<ResultOut> {
    noise_arg(noise_radius)?;
    let cfg = config.inner.clone();
    guarded(py, move || {
        let opts = BatchSettings {
            noise_radius,
            per_dataset_files: false,
        };
        let r = batch::run_one(
            &cfg,
            &self::dataset(dataset),
            &opts,
            std::path::Path::new("."),
        );
        result_out(r, &cfg)
    })
}

/// The verdict named as `report.json` names it (`Verdict::as_str`).
fn verdict_of(name: &str) -> Option<Verdict> {
    [
        Verdict::Consistent,
        Verdict::Inconsistent,
        Verdict::NotAdmissible,
    ]
    .into_iter()
    .find(|v| v.as_str() == name)
}

/// `summary.csv` of rows (in the order given).
#[pyfunction]
pub fn _summary_csv(rows: Vec<RowTuple>) -> String {
    let rows: Vec<SummaryRow> = rows
        .into_iter()
        .map(
            |(index, name, ok, n_data, max_r_min, consistent, verdict, n_failing, data, error)| {
                SummaryRow {
                    index,
                    name,
                    ok,
                    n_data,
                    max_r_min,
                    consistent,
                    verdict: verdict.as_deref().and_then(verdict_of),
                    n_failing,
                    data,
                    error,
                }
            },
        )
        .collect();
    batch::render_summary(&rows)
}

/// What `_batch` returns: per-dataset results, summary.csv, the combined envelope, the fit
/// (or why it failed), batch.json when written.
type BatchOut = (
    Vec<ResultOut>,
    String,
    Option<Envelope>,
    Option<FitHandle>,
    Option<String>,
);

/// `rshape batch` on a list of datasets: rayon threads (`jobs`, default all cores), the
/// combined envelope and one `r` fitted above it; with `out`, every file the CLI writes.
#[pyfunction]
#[pyo3(signature = (config, datasets, order, out=None, noise_radius=None, jobs=None, max_order=8))]
#[allow(clippy::too_many_arguments)]
pub fn _batch(
    py: Python<'_>,
    config: &Config,
    datasets: Vec<DatasetTuple>,
    order: &Bound<'_, PyAny>,
    out: Option<PathBuf>,
    noise_radius: Option<f64>,
    jobs: Option<usize>,
    max_order: usize,
) -> PyResult<BatchOut> {
    noise_arg(noise_radius)?;
    let order = order_arg(order, max_order)?;
    if jobs == Some(0) {
        return Err(input(
            "jobs=0: give a number of worker threads ≥ 1 (default: all cores)",
        ));
    }
    let cfg = config.inner.clone();
    guarded(py, move || {
        let sets: Vec<Dataset> = datasets.into_iter().map(dataset).collect();
        if sets.is_empty() {
            return Err(input("batch: no dataset given"));
        }
        let opts = BatchSettings {
            noise_radius,
            per_dataset_files: out.is_some(),
        };
        let dir = out.clone().unwrap_or_else(|| PathBuf::from("."));
        let _manifest = match &out {
            Some(o) => Some(rshape::util::OutputManifest::begin(o).py()?),
            None => None,
        };
        let work = || batch::run_all(&cfg, &sets, &opts, &dir, &|| {});
        let results = match jobs {
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(n.min(sets.len()).max(1))
                .build()
                .map_err(|e| input(e.to_string()))?
                .install(work),
            None => work(),
        };
        let combined = batch::combine(results.iter().filter_map(|r| r.envelope.as_ref()));
        let rows: Vec<SummaryRow> = results.iter().map(SummaryRow::from).collect();
        let summary = batch::render_summary(&rows);
        let wrap = |e: rshape::consistency::Envelope| Envelope {
            inner: Arc::new(e),
            config: Some(cfg.clone()),
            noise_radii: None,
            warnings: Vec::new(),
        };
        let (fit, fit_error) = match &out {
            Some(o) => {
                let rep = batch::finish(
                    o,
                    &rows,
                    combined.as_ref(),
                    batch::FinishInput {
                        config: cfg.path.clone(),
                        config_digest: batch::config_digest(&cfg.path),
                        scaling: rshape::report::ScalingNote::of_opt(cfg.scaling.as_ref()),
                        r_configured: cfg.r.as_ref(),
                        n_total: sets.len(),
                        shard: batch::Shard::ALL,
                        merged_from: Vec::new(),
                        timings_ms: BTreeMap::new(),
                        order,
                        factorization: rshape::pipeline::closed_loop::a1_factorization(&cfg),
                        closed_loop: cfg.closed_loop.is_some(),
                        datasets: results.iter().filter_map(|r| r.envelope.as_ref()).collect(),
                    },
                )
                .py()?;
                let fit = rep.r_fitted.as_ref().map(fit_from_json).transpose()?;
                (fit, rep.fit_error)
            }
            None => match &combined {
                None => (
                    None,
                    Some("no dataset succeeded: nothing to fit".to_string()),
                ),
                Some(c) => match crate::core::fit_envelope(&wrap(c.clone()), order) {
                    Ok(f) => (Some(f), None),
                    Err(e) => (None, Some(e.to_string())),
                },
            },
        };
        let per = results
            .into_iter()
            .map(|r| result_out(r, &cfg))
            .collect::<PyResult<Vec<_>>>()?;
        Ok((per, summary, combined.map(wrap), fit, fit_error))
    })
}

/// The fit handle of an `r.json` document (the batch's, already certified).
fn fit_from_json(j: &serde_json::Value) -> PyResult<FitHandle> {
    let coeffs = |k: &str| -> PyResult<Vec<f64>> {
        j.get(k)
            .and_then(|v| v.as_array())
            .map(|a| a.iter().filter_map(|x| x.as_f64()).collect())
            .ok_or_else(|| input(format!("r.json: no {k}")))
    };
    Ok(FitHandle {
        r: rshape::TransferFunction::new(coeffs("num")?, coeffs("den")?),
        json: serde_json::to_string(j).map_err(|e| input(e.to_string()))?,
    })
}
