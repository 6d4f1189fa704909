//! The parallel run over datasets: per dataset the envelope (Theorem 2/3, or Theorem 4 for
//! noisy data) and the check of the configured `r`, each written to
//! `OUT/datasets/NAME/`.  A failing dataset becomes a failed row; the others complete.
//! Results come back in dataset order whatever the scheduling (rayon's indexed collect).
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use super::discover::Dataset;
use crate::consistency::{check, Envelope};
use crate::error::{Error, Result};
use crate::model::Config;
use crate::report::envelope_csv;
use crate::util::write_atomic_nosync;
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// Outcome of one dataset.
#[derive(Debug, Clone, Serialize)]
pub struct DatasetResult {
    /// Position in the full list (the output order).
    pub index: usize,
    /// The dataset name.
    pub name: String,
    /// The data file.
    pub path: std::path::PathBuf,
    /// The config's `[scaling]`: `max_r_min` and the envelope are those of the scaled plant.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scaling: Option<crate::report::ScalingNote>,
    /// `None` on success, else the error on one line.
    pub error: Option<String>,
    /// Number of data.
    pub n_data: usize,
    /// Largest `r_min` (`inf` when a datum has no admissible `r`).
    pub max_r_min: Option<f64>,
    /// True when the configured `r` explains every datum and A1 holds at each.
    pub consistent: Option<bool>,
    /// Verdict on the configured `r` (`not_admissible` when A1 fails at some datum).
    pub verdict: Option<crate::consistency::Verdict>,
    /// Frequencies (rad/s) the configured `r` does not explain.
    pub failing_omegas: Vec<f64>,
    /// Warnings (e.g. a fallback envelope).
    pub warnings: Vec<String>,
    /// The envelope (kept for the combined envelope; not serialized).
    #[serde(skip)]
    pub envelope: Option<Envelope>,
}

impl DatasetResult {
    /// True when the dataset was processed.
    pub fn ok(&self) -> bool {
        self.error.is_none()
    }
}

/// Options of a batch run.
#[derive(Debug, Clone, Default)]
pub struct BatchSettings {
    /// Noise radius for every dataset without one in the manifest.
    pub noise_radius: Option<f64>,
    /// Write `OUT/datasets/NAME/{envelope.csv,result.json}`.
    pub per_dataset_files: bool,
}

/// Processes one dataset; never panics on bad input, returns the failure as a row.
pub fn run_one(config: &Config, d: &Dataset, opts: &BatchSettings, out: &Path) -> DatasetResult {
    let mut res = DatasetResult {
        index: d.index,
        name: d.name.clone(),
        path: d.path.clone(),
        scaling: crate::report::ScalingNote::of_opt(config.scaling.as_ref()),
        error: None,
        n_data: 0,
        max_r_min: None,
        consistent: None,
        verdict: None,
        failing_omegas: Vec::new(),
        warnings: Vec::new(),
        envelope: None,
    };
    if let Err(e) = fill(config, d, opts, out, &mut res) {
        res.error = Some(crate::report::fmt::one_line(&e.to_string()));
        res.envelope = None;
    }
    res
}

fn fill(
    config: &Config,
    d: &Dataset,
    opts: &BatchSettings,
    out: &Path,
    res: &mut DatasetResult,
) -> Result<()> {
    let data = crate::pipeline::envelope::load_data(config, &d.path)?;
    if data.is_empty() {
        return Err(Error::Input {
            path: d.path.to_path_buf(),
            msg: "no data rows".into(),
        });
    }
    res.n_data = data.len();
    let options = crate::pipeline::RunOptions::noise_radius(d.noise_radius.or(opts.noise_radius));
    let outcome = crate::pipeline::envelope::envelope(config, &data, &options)?;
    let env = outcome.envelope;
    res.warnings = outcome.warnings;
    res.max_r_min = env.r_min.iter().copied().reduce(f64::max);
    if let Some(r) = &config.r {
        let c = check(r, &env);
        res.consistent = Some(c.consistent);
        res.verdict = Some(c.verdict);
        res.failing_omegas = c.failing_omegas;
    }
    if opts.per_dataset_files {
        let dir = out.join("datasets").join(&d.name);
        write_atomic_nosync(&dir.join("envelope.csv"), envelope_csv(&env).as_bytes())?;
        let json =
            serde_json::to_string_pretty(&*res).map_err(|e| Error::Invalid(e.to_string()))?;
        write_atomic_nosync(&dir.join("result.json"), json.as_bytes())?;
    }
    res.envelope = Some(env);
    Ok(())
}

/// Runs every dataset in parallel (rayon) and returns the results in dataset order.
/// `tick` is called once per finished dataset (for a progress bar).
pub fn run_all(
    config: &Config,
    datasets: &[Dataset],
    opts: &BatchSettings,
    out: &Path,
    tick: &(dyn Fn() + Sync),
) -> Vec<DatasetResult> {
    datasets
        .par_iter()
        .map(|d| {
            let r = run_one(config, d, opts, out);
            tick();
            r
        })
        .collect()
}
