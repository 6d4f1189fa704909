//! `rshape stability CONFIG --controller K.toml [--r-json r.json] [--fit] [--out DIR]
//! [--json]`: Theorem 1 of Boulet & Francis for a controller (GitHub issue 10).
//! Exit 0 robustly stable for every bound given, 1 not (including a controller that does
//! not stabilize the nominal plant), 2 error.

use crate::model::Controller;
use crate::pipeline::stability;
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::{Path, PathBuf};

/// Arguments of `rshape stability`.
#[derive(Debug, Args)]
pub struct StabilityArgs {
    /// The TOML config (any factorization: [model] standard or special, [physical], [plant];
    /// its [r] is the configured bound).
    pub config: PathBuf,
    /// The controller file (a [controller] table).
    #[arg(long)]
    pub controller: PathBuf,
    /// `--r-json`, `--fit`, `--data`: the bounds besides the config's `[r]`.
    #[command(flatten)]
    pub bounds: super::common::BoundArgs,
    /// Directory for stability.svg and stability.json.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// From this many (approximate) loop states on, stage lines on stderr (a test lowers it
    /// to see them on a small model).
    #[arg(long, default_value_t = LARGE_MODEL_STATES, hide = true)]
    pub progress_from_states: usize,
}

/// From this many states on, `stability` announces its long stage (issue 34: a 200-mode
/// model ran minutes without output).
const LARGE_MODEL_STATES: usize = 200;

/// Runs `rshape stability`.
pub fn run(a: &StabilityArgs) -> Result<i32> {
    let config = super::common::load_config(&a.config)?;
    let controller = Controller::load(&a.controller)?;
    if a.bounds.fit && a.out.is_none() {
        return Err(anyhow!(
            "--fit writes r.json and its exports: give --out DIR"
        ));
    }
    // The controller's size is checked before anything is written (the loop itself, dear on
    // a large model, is built once, by `stability::run`).
    crate::stability::controller_fits(&config.factorization, &controller)?;
    // With [scaling] the loop is that of G_s = D_o·G·D_i and K_s = D_i⁻¹·K·D_o⁻¹.
    let controller = crate::pipeline::stability::scaled_controller(&config, controller);
    // The output folder policy of every subcommand (see `prepare_out`): not a file, not an
    // input's folder (refused before any work); the previous run's listed files are cleared.
    let inputs: Vec<&Path> = [a.config.as_path(), a.controller.as_path()]
        .into_iter()
        .chain(a.bounds.files())
        .chain(config.data.as_deref())
        .collect();
    if let Some(out) = &a.out {
        super::common::check_out(out, &inputs)?;
    }
    // With --fit, the data are read and the envelope computed before the folder is touched.
    let (mut rs, fit_input) = a.bounds.bounds(&a.config, &config)?;
    let _manifest = match &a.out {
        Some(out) => Some(super::common::prepare_out(out, &inputs)?),
        None => None,
    };
    let mut fit_text = String::new();
    if let (Some(input), Some(out)) = (&fit_input, &a.out) {
        let (text, r) = super::common::fit_bound("stability --fit", input, out)?;
        fit_text = text;
        rs.push(("fitted".into(), r));
    }
    // A large model's loop is an eigenvalue problem of O(n³) (and the exact norms a
    // certified sweep or Hamiltonians of twice its size), silent while it runs: say what is
    // going on.
    let f = &config.factorization;
    let states = f
        .realization
        .as_ref()
        .map_or(2 * f.states(), |n| n.plant.states());
    let view = (states >= a.progress_from_states).then(|| {
        let v = super::progress::FitProgressView::new("stability");
        v.stage(&format!(
            "the loop of a model with about {states} states: closed-loop poles, the grid, then the exact H∞ norms"
        ));
        v
    });
    let stage = |what: &str| {
        if let Some(v) = &view {
            v.stage(what);
        }
    };
    let outcome =
        stability::run_with_stages(&config, &controller, &rs, a.bounds.data.as_deref(), &stage)?;
    drop(view);
    let written = match &a.out {
        Some(out) => {
            let k = a
                .controller
                .file_name()
                .map_or(String::new(), |n| n.to_string_lossy().into_owned());
            let title = stability::figure_title(&config, &format!("K = {k}"));
            stability::write_outputs(out, &outcome, &title, &[])?
        }
        None => Vec::new(),
    };
    let code = if outcome.robust { 0 } else { 1 };
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&outcome.report)?);
        return Ok(code);
    }
    print!("{fit_text}");
    if let Some(s) = &config.scaling {
        outln!(
            "scaling: {}; the loop of G_s = D_o·G·D_i and K_s = D_i^-1·K·D_o^-1 (the same loop as G and K)",
            s.describe()
        );
    }
    print!("{}", stability::text(&outcome));
    if outcome.report.internally_stable {
        for f in &written {
            outln!("wrote {}", f.display());
        }
    }
    Ok(code)
}
