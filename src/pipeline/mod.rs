//! The `rshape run` pipeline: envelope → check of the configured `r` → fit → certificate →
//! exports → figures → `report.json`.  [`run`] computes, [`outputs::write_outputs`]
//! writes; neither prints.
pub mod a1_conflict;
pub mod closed_loop;
pub mod envelope;
pub mod integration;
pub mod outputs;
pub mod stability;
pub mod synthesize;

use crate::consistency::{check, CheckReport, Envelope};
use crate::data::FrfData;
use crate::error::Result;
use crate::model::Config;
use integration::FittedR;
pub use integration::{explain as explain_fit_failure, write_fit_exports, A1Model, FitFailure};
use std::collections::BTreeMap;
use std::time::Instant;

/// Wall-clock time per stage in milliseconds, keyed by stage name.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Timings(pub BTreeMap<String, f64>);

impl Timings {
    /// Runs `f` and records its duration under `name`.
    pub fn time<T>(&mut self, name: &str, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let out = f();
        self.0
            .insert(name.to_string(), t.elapsed().as_secs_f64() * 1e3);
        out
    }
}

/// Everything the pipeline computed.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// Per-datum smallest consistent `|r|` and the A1 limit.
    pub envelope: Envelope,
    /// Per-datum noise radii, for noisy data.
    pub noise_radii: Option<Vec<f64>>,
    /// The check of the configured `r` (`None` when the config has no `[r]`).
    pub check: Option<CheckReport>,
    /// The fitted `r`, or why the fit failed (a failed fit does not stop the run).
    pub fit: std::result::Result<FittedR, integration::FitFailure>,
    /// `μ_Γ` per datum for the configured `r` (noisy data, when available).
    pub mu: Option<Vec<f64>>,
    /// Warnings for the reader.
    pub warnings: Vec<String>,
    /// Time per stage.
    pub timings: Timings,
    /// Per-datum closed-loop diagnostics (closed-loop configs only).
    pub closed_loop: Option<crate::consistency::closed_loop::ClosedLoopReport>,
}

/// What the caller adds to a config and its data at the pipeline's entry points
/// ([`envelope::envelope`], [`run`]): a global noise radius, and who hears of the progress of
/// the long stages.  `RunOptions::default()` is a noise radius from the config or the data,
/// and no progress.
#[derive(Clone, Copy, Default)]
pub struct RunOptions<'a> {
    /// A global noise radius overriding the config's (`--noise-radius`, or a batch
    /// manifest's per-dataset radius).
    pub noise_radius: Option<f64>,
    /// Hears of the data done by a noisy envelope (Theorem 4's μ search per datum, the long
    /// stage of a large physical model).
    pub envelope_progress: Option<crate::consistency::DatumProgressFn<'a>>,
    /// Hears of each order of the fit as it starts (see [`crate::fit::FitProgress`]).
    pub fit_progress: Option<crate::fit::ProgressFn<'a>>,
}

impl RunOptions<'_> {
    /// No progress, the given global noise radius (`None`: the config's or the data's).
    pub fn noise_radius(noise_radius: Option<f64>) -> Self {
        Self {
            noise_radius,
            ..Self::default()
        }
    }
}

/// The warning [`run`] adds when the fit fails (one line), so that a caller printing the
/// failure elsewhere can leave this one out.
pub fn fit_failure_warning(e: &integration::FitFailure) -> String {
    format!(
        "fit failed: {}",
        crate::report::fmt::one_line(&e.to_string())
    )
}

/// Runs the computations of the pipeline on loaded inputs.  Only an envelope failure (bad
/// sizes, a failed assumption at a datum) is an error; the fit and μ failures are kept in
/// the outcome.  `options` give the global noise radius and the progress callbacks.
pub fn run(
    config: &Config,
    data: &FrfData,
    order: crate::fit::OrderChoice,
    options: &RunOptions<'_>,
) -> Result<RunOutcome> {
    let mut timings = Timings::default();
    let envelope::EnvelopeOutcome {
        envelope,
        noise_radii: radii,
        mut warnings,
        closed_loop,
    } = timings.time("envelope", || envelope::envelope(config, data, options))?;
    let check = timings.time("check", || config.r.as_ref().map(|r| check(r, &envelope)));
    let fit = timings.time("fit", || {
        integration::fit_r(
            &envelope,
            closed_loop::a1_factorization(config),
            order,
            options.fit_progress,
        )
    });
    if let Err(e) = &fit {
        warnings.push(fit_failure_warning(e));
    }
    let mu = match (&radii, &config.r) {
        (Some(rad), Some(r)) => {
            timings.time("mu", || match closed_loop::mu(config, data, rad, r) {
                Some(Ok(v)) => Some(v),
                Some(Err(e)) => {
                    warnings.push(format!("μ per datum failed: {e}"));
                    None
                }
                None => None,
            })
        }
        _ => None,
    };
    if let Some(c) = &check {
        if !c.a1_violations.is_empty() {
            warnings.push(format!(
                "A1 fails for the configured r at {} datum(s): |r| ≥ σ_min(M̃), so r is not admissible there (verdict not_admissible)",
                c.a1_violations.len()
            ));
        }
    }
    Ok(RunOutcome {
        envelope,
        noise_radii: radii,
        check,
        fit,
        mu,
        warnings,
        timings,
        closed_loop,
    })
}
