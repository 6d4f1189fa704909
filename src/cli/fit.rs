//! `rshape fit CONFIG [--data FILE] [--noise-radius X] [--order N|auto] [--objective
//! area|minimax] [--margin X] --out DIR`, or `rshape fit --envelope ENVELOPE.csv …`: the
//! smallest certified unit r(s) above the envelope (GitHub issue 4).  A thin wrapper over
//! [`crate::fit::run_fit`].

use super::common::InputArgs;
use crate::data::read_envelope_csv;
use crate::fit::{events_text, work_line};
use crate::fit::{run_fit, FitSettings, Objective, OrderChoice};
use anyhow::{anyhow, Result};
use clap::{Args, ValueEnum};
use std::path::PathBuf;

/// `--objective`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ObjectiveArg {
    /// Smallest max |r|/r_min over the data (log-Chebyshev), then smallest area.
    Minimax,
    /// Smallest log-frequency-weighted Σ|r|²/r_min².
    Area,
}

/// Arguments of `rshape fit`.
#[derive(Debug, Args)]
pub struct FitArgs {
    /// The TOML config (model and data); omit it with --envelope.
    pub config: Option<PathBuf>,
    /// Data file overriding the one named in the config.
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Global noise-disk radius L_a overriding the config.
    #[arg(long, allow_negative_numbers = true)]
    pub noise_radius: Option<f64>,
    /// Fit this envelope file (omega_rad_s,r_min[,a1_limit]) instead of a config.
    #[arg(long, conflicts_with_all = ["config", "data", "noise_radius"])]
    pub envelope: Option<PathBuf>,
    /// Order of r, or `auto` (sweep 0..8, print the table, pick the smallest good order).
    #[arg(long, default_value = "auto", allow_negative_numbers = true)]
    pub order: OrderChoice,
    /// What to minimize.
    #[arg(long, value_enum, default_value = "minimax")]
    pub objective: ObjectiveArg,
    /// Relative margin: |r| ≥ (1 + margin)·r_min at every datum.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub margin: f64,
    /// Output directory for r.json, r.m, r.py, r.jl.
    #[arg(long)]
    pub out: PathBuf,
    /// Also list the solver events (solves short of `Solved`, discarded candidates).
    #[arg(long, short)]
    pub verbose: bool,
}

/// Runs `rshape fit`.
pub fn run(a: &FitArgs) -> Result<i32> {
    if !(a.margin.is_finite() && a.margin >= 0.0) {
        return Err(anyhow!(
            "--margin {}: must be a finite number ≥ 0 (|r| ≥ (1 + margin)·r_min; a negative margin would let r fall below r_min, where it no longer explains the data)",
            a.margin
        ));
    }
    let settings = FitSettings {
        objective: match a.objective {
            ObjectiveArg::Minimax => Objective::Minimax,
            ObjectiveArg::Area => Objective::Area,
        },
        margin: a.margin,
        ..Default::default()
    };
    let view = super::progress::FitProgressView::new("fit");
    let progress = |p| view.update(p);
    let progress: crate::fit::ProgressFn<'_> = &progress;
    // The config's [scaling], recorded in r.json (r is then that of the scaled plant).
    let mut scaling = None;
    // `--verbose`: the proven gap of the chosen order (a bisection of checked certificates).
    let mut gap_line = None;
    let outcome = match (&a.envelope, &a.config) {
        (Some(path), _) => {
            let env = read_envelope_csv(path)?;
            let _manifest = super::common::prepare_out(&a.out, &[path])?;
            let out = run_fit(&env, None, &settings, a.order, Some(progress));
            if let (true, Ok(o)) = (a.verbose, &out) {
                gap_line = crate::fit::proven_gap_line(&env, None, &settings, &o.result);
            }
            out.map_err(anyhow::Error::from)
        }
        (None, Some(config)) => {
            let input = InputArgs {
                config: config.clone(),
                data: a.data.clone(),
                noise_radius: a.noise_radius,
            };
            let inputs = input.load()?;
            scaling.clone_from(&inputs.config.scaling);
            // `--out` is checked before the work: a refusal must not cost the user the envelope.
            let _manifest = super::common::prepare_out(&a.out, &[config, &inputs.data.path])?;
            let env = input.envelope_of(&inputs)?;
            // A1 as `run` imposes it: none for closed-loop data (the pipeline's rule).
            let model = crate::pipeline::A1Model::of_config(&inputs.config);
            let (f, a1) = (model.factorization(), model.limit());
            let settings = model.settings(settings);
            let out = run_fit(&env, a1, &settings, a.order, Some(progress));
            if let (true, Ok(o)) = (a.verbose, &out) {
                gap_line = crate::fit::proven_gap_line(&env, a1, &settings, &o.result);
            }
            out.map_err(|e| {
                // Why no order can pass, when the envelope shows it (the words of `run`).
                match crate::pipeline::explain_fit_failure(e, &env, f) {
                    crate::pipeline::FitFailure::A1Conflict { message, .. } => anyhow!(message),
                    crate::pipeline::FitFailure::Fit(e) => e.into(),
                    other => other.into(),
                }
            })
        }
        (None, None) => return Err(anyhow!("give a CONFIG or --envelope FILE")),
    };
    view.finish();
    let outcome = outcome?;
    print!("{}", outcome.text);
    let written = crate::pipeline::write_fit_exports(&outcome, &a.out, scaling.as_ref())?;
    for f in written {
        println!("wrote {}", f.display());
    }
    print!("{}", work_line(&outcome.result, outcome.seconds));
    if a.verbose {
        print!("{}", gap_line.unwrap_or_default());
        print!("{}", events_text(&outcome.result));
    }
    Ok(0)
}
