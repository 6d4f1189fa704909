//! `rshape synthesize CONFIG [--r-json r.json | --fit] [--weights W.toml] [--gamma-factor F] [--reduce N]
//! --out DIR [--json]`: the Glover–McFarlane controller of the config's plant, proved by Theorem 1
//! (issue 22). Exit 0 proven robust for every bound given, 1 not, 2 error.

use crate::pipeline::synthesize;
use anyhow::Result;
use clap::Args;
use std::path::{Path, PathBuf};

/// Arguments of `rshape synthesize`.
#[derive(Debug, Args)]
pub struct SynthesizeArgs {
    /// The TOML config ([plant], or [model]/[physical] factors; its [r] is the configured bound).
    pub config: PathBuf,
    /// `--r-json`, `--fit`, `--data`: the bounds besides the config's `[r]`.
    #[command(flatten)]
    pub bounds: super::common::BoundArgs,
    /// Suboptimality: the central controller at gamma = F * gamma_min (F > 1).
    #[arg(long, default_value_t = 1.1)]
    pub gamma_factor: f64,
    /// Loop-shaping weights: a TOML file with [weights] w1 = [...] (plant inputs), w2 = [...]
    /// (plant outputs); the controller is W1*Kinf*W2 with Kinf designed for W2*G*W1.
    #[arg(long)]
    pub weights: Option<PathBuf>,
    /// Reduce the controller to N states by balanced truncation (stable controllers; the
    /// margin is re-proved on the reduced controller).
    #[arg(long)]
    pub reduce: Option<usize>,
    /// Method: `gm` (Glover–McFarlane, the default) or `hinf` (the H∞ optimum with the fitted
    /// r, else the configured r, as weight when that r is frequency dependent; Glover–McFarlane
    /// otherwise).
    #[arg(long, value_enum, default_value = "gm")]
    pub method: MethodArg,
    /// Output directory (created if needed).
    #[arg(long)]
    pub out: PathBuf,
    /// Print synthesis.json's content instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// From this many (approximate) plant states on, stage lines on stderr (a test lowers it
    /// to see them on a small model).
    #[arg(long, default_value_t = LARGE_PLANT_STATES, hide = true)]
    pub progress_from_states: usize,
}

/// `--method`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum MethodArg {
    /// Glover–McFarlane.
    Gm,
    /// H∞ with a frequency-dependent r as weight, else Glover–McFarlane.
    Hinf,
}

/// From this many plant states on, `synthesize` announces its stages (a 50-mode structure,
/// 100 states, takes about 30 s before its first answer).
const LARGE_PLANT_STATES: usize = 100;

/// Runs `rshape synthesize`.
pub fn run(a: &SynthesizeArgs) -> Result<i32> {
    crate::synthesis::check_gamma_factor(a.gamma_factor)?;
    let config = super::common::load_config(&a.config)?;
    // A large model's synthesis is dense linear algebra of O(n³) for minutes, silent while it
    // runs: say what is going on (issue 34: 200 modes ran minutes without a line).
    let f = &config.factorization;
    let states = f
        .realization
        .as_ref()
        .map_or(2 * f.states(), |n| n.plant.states());
    let view = (states >= a.progress_from_states).then(|| {
        let v = super::progress::FitProgressView::new("synthesize");
        v.stage(&format!(
            "normalized coprime factors of a plant with about {states} states (realization, Riccati equation: dense, O(n³))"
        ));
        v
    });
    synthesize::plant_factors(&config, &a.config)?;
    let (mut rs, fit_input) = a.bounds.bounds(&a.config, &config)?;
    let inputs: Vec<&Path> = std::iter::once(a.config.as_path())
        .chain(a.bounds.files())
        .chain(a.weights.as_deref())
        .chain(config.data.as_deref())
        .collect();
    // Everything that can fail on bad input is checked before the folder is touched: the
    // synthesis itself runs in memory first; a bad `--out` is refused before that work.
    super::common::check_out(&a.out, &inputs)?;
    let settings = synthesize::SynthesisSettings {
        gamma_factor: a.gamma_factor,
        reduce: a.reduce,
        method: match a.method {
            MethodArg::Hinf => synthesize::Method::Hinf,
            MethodArg::Gm => synthesize::Method::GloverMcfarlane,
        },
        weights: match &a.weights {
            Some(w) => Some(crate::synthesis::Weights::load(
                w,
                config.factorization.inputs(),
                config.factorization.outputs(),
            )?),
            None => None,
        },
    };
    let controller_path = a.out.join("controller.toml");
    let data = a.bounds.data.as_deref();
    let stage = |what: &str| {
        if let Some(v) = &view {
            v.stage(what);
        }
    };
    let prove = |rs: &[(String, crate::system::TransferFunction)]| {
        synthesize::run_with_stages(
            &config,
            &a.config,
            rs,
            &settings,
            data,
            &controller_path,
            &stage,
        )
    };
    let dry = prove(&rs)?;
    // The bar cleared for the fit's own display (a second proof with the fitted r still
    // prints its stage lines when stderr is not a terminal).
    if let Some(v) = &view {
        v.finish();
    }
    // Without --fit the run above is the outcome; with it, r is fitted in memory and the
    // proof repeated with the fitted r added, all before anything is written (a refusal,
    // e.g. --reduce on an unstable H∞ controller, leaves no r.json behind).
    let (outcome, fit) = match &fit_input {
        None => (dry, None),
        Some(input) => {
            let fit = super::common::fit_bound_in_memory("synthesize --fit", input)?;
            rs.push(("fitted".into(), fit.result.r.clone()));
            (prove(&rs)?, Some(fit))
        }
    };
    let _manifest = super::common::prepare_out(&a.out, &inputs)?;
    let mut fit_text = String::new();
    if let Some(fit) = fit {
        fit_text = super::common::write_fit_text(fit, &a.out, config.scaling.as_ref())?.0;
    }
    let written = synthesize::write_outputs(&a.out, &outcome)?;
    let code = if outcome.robust { 0 } else { 1 };
    if a.json {
        let text = std::fs::read_to_string(a.out.join("synthesis.json"))?;
        outln!("{text}");
        return Ok(code);
    }
    print!("{fit_text}");
    print!("{}", synthesize::text(&outcome));
    for f in &written {
        outln!("wrote {}", f.display());
    }
    Ok(code)
}
