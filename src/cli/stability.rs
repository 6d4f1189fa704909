//! `rshape stability CONFIG --controller K.toml [--r-json r.json] [--fit] [--out DIR]
//! [--json]`: Theorem 1 of Boulet & Francis for a controller (GitHub issue 10).
//! Exit 0 robustly stable for every bound given, 1 not (including a controller that does
//! not stabilize the nominal plant), 2 error.

use super::common::InputArgs;
use crate::fit::{run_fit, FitSettings, OrderChoice};
use crate::model::controller::Controller;
use crate::model::Config;
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
    /// A fitted r (the r.json written by `rshape run` or `rshape fit`).
    #[arg(long)]
    pub r_json: Option<PathBuf>,
    /// Fit r from the config's data first (as `rshape fit`; exports go to --out).
    #[arg(long, conflicts_with = "r_json")]
    pub fit: bool,
    /// Data file overriding the one in the config (with --fit).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Directory for stability.svg and stability.json.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `rshape stability`.
pub fn run(a: &StabilityArgs) -> Result<i32> {
    let config = Config::load(&a.config)?;
    let controller = Controller::load(&a.controller)?;
    if config.closed_loop.is_some() && a.fit {
        return Err(anyhow!(
            "{}: --fit on a [closed_loop] config would fit its weight V, not a factor bound r: give --r-json r.json",
            a.config.display()
        ));
    }
    let given = a
        .r_json
        .as_deref()
        .map(stability::read_r_json)
        .transpose()?;
    let mut rs = stability::bounds(&config, given);
    // The controller's size is checked before anything is written.
    stability::check_controller(&config, &controller)?;
    // With --fit, the data are read and the envelope computed before the folder is touched.
    let fit_input = if a.fit {
        if a.out.is_none() {
            return Err(anyhow!(
                "--fit writes r.json and its exports: give --out DIR"
            ));
        }
        let input = InputArgs {
            config: a.config.clone(),
            data: a.data.clone(),
            noise_radius: None,
        };
        Some(input.envelope()?)
    } else {
        None
    };
    // The output folder policy of every subcommand (see `prepare_out`): not a file, not an
    // input's folder; the previous run's listed files are cleared.
    let inputs: Vec<&Path> = [
        Some(a.config.as_path()),
        Some(a.controller.as_path()),
        a.r_json.as_deref(),
        a.data.as_deref(),
        config.data.as_deref(),
    ]
    .into_iter()
    .flatten()
    .collect();
    let _manifest = match &a.out {
        Some(out) => Some(super::common::prepare_out(out, &inputs)?),
        None => None,
    };
    let mut fit_text = String::new();
    if let (Some((inputs, env)), Some(out)) = (&fit_input, &a.out) {
        let f = &inputs.config.factorization;
        let a1 = |w: f64| f.a1_limit(w);
        let view = super::progress::FitProgressView::new("stability --fit");
        let progress = |p| view.update(p);
        let outcome = run_fit(
            env,
            Some(&a1),
            &FitSettings::default(),
            OrderChoice::Auto { max: 8 },
            out,
            Some(&progress),
        )?;
        view.finish();
        fit_text = outcome.text + &crate::fit::run::work_line(&outcome.result, outcome.seconds);
        rs.push(("fitted".into(), outcome.result.r.clone()));
    }
    let outcome = stability::run(&config, &controller, &rs, a.data.as_deref())?;
    let written = match &a.out {
        Some(out) => {
            let k = a
                .controller
                .file_name()
                .map_or(String::new(), |n| n.to_string_lossy().into_owned());
            let title = stability::figure_title(&config, &format!("K = {k}"));
            stability::write_outputs(out, &outcome, &title)?
        }
        None => Vec::new(),
    };
    let code = if outcome.robust { 0 } else { 1 };
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&outcome.report)?);
        return Ok(code);
    }
    print!("{fit_text}");
    print!("{}", stability::text(&outcome));
    if outcome.report.internally_stable {
        for f in &written {
            outln!("wrote {}", f.display());
        }
    }
    Ok(code)
}
