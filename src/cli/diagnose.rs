//! `rshape diagnose CONFIG [--data FILE] [--noise-radius X] [--channel OUT,IN] [--json]
//! [--apply K --write NEW.toml]`.

use super::common::{fmt_g, InputArgs};
use super::compare::channel_arg;
use crate::diagnose::candidates::sig;
use crate::diagnose::{apply_candidate, diagnose, prepare, refit_nominal};
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::{Path, PathBuf};

/// Arguments of `rshape diagnose`.
#[derive(Debug, Args)]
pub struct DiagnoseArgs {
    /// Model and data.
    #[command(flatten)]
    pub input: InputArgs,
    /// SISO channel of MIMO data, `OUT,IN` (1-based).
    #[arg(long, value_delimiter = ',')]
    pub channel: Option<Vec<usize>>,
    /// Most effects to add greedily.
    #[arg(long, default_value_t = 3)]
    pub max_effects: usize,
    /// Add the K-th ranked candidate (1-based) and write the revised config (with --write).
    #[arg(long, requires = "write")]
    pub apply: Option<usize>,
    /// Where to write the revised config.
    #[arg(long, requires = "apply")]
    pub write: Option<PathBuf>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

fn rel_to(target: &Path, from_dir: &Path) -> PathBuf {
    let (Ok(t), Ok(f)) = (target.canonicalize(), from_dir.canonicalize()) else {
        return target.to_path_buf();
    };
    let tc: Vec<_> = t.components().collect();
    let fc: Vec<_> = f.components().collect();
    let common = tc.iter().zip(&fc).take_while(|(a, b)| a == b).count();
    let mut p = PathBuf::new();
    for _ in common..fc.len() {
        p.push("..");
    }
    for c in &tc[common..] {
        p.push(c);
    }
    p
}

/// Runs `rshape diagnose`.
pub fn run(a: &DiagnoseArgs) -> Result<i32> {
    let inputs = a.input.load()?;
    // Closed-loop data (issue 9, item 6): diagnose the plant P₀ recovered from Φ and C̄.
    let inputs = crate::pipeline::closed_loop::discovery_inputs(
        inputs.config,
        inputs.data,
        a.input.noise_radius,
    )?;
    let config = &inputs.config;
    let base = config.physical.clone().ok_or_else(|| {
        anyhow!(
            "{}: diagnose needs the model as [physical] (modes, rigid bodies, effects); see configs/robot_physical.toml",
            config.path.display()
        )
    })?;
    let siso = prepare(
        config,
        &inputs.data,
        channel_arg(&a.channel)?,
        inputs.noise_radius,
    )?;
    let d = diagnose(&base, &siso, a.max_effects.max(1))?;
    if let (Some(k), Some(out)) = (a.apply, &a.write) {
        // The candidate, then a joint refit of every parameter (the configured ones too).
        let applied = apply_candidate(&base, &d, k)?;
        let radius = siso.radius.clone().unwrap_or_default();
        let revised = refit_nominal(&applied, &siso.omega, &siso.g, &radius).model;
        let gm: Vec<_> = siso.omega.iter().map(|w| revised.eval_siso(*w)).collect();
        let (_, rms_refit, _, inv_refit) = crate::diagnose::compare::misfit(&siso, &gm);
        let mut raw = inputs.raw.clone();
        let c = &d.candidates[k - 1];
        raw.physical = Some(revised);
        raw.name = Some(format!(
            "{} + {}",
            raw.name
                .clone()
                .unwrap_or_else(|| config.path.display().to_string()),
            c.effect
        ));
        let out_dir = out
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        std::fs::create_dir_all(out_dir)?;
        let base_dir = config.path.parent().unwrap_or(Path::new("."));
        if let Some(dp) = &raw.data {
            raw.data = Some(rel_to(&base_dir.join(dp), out_dir));
        }
        if let Some(sf) = &raw.noise.std_file {
            raw.noise.std_file = Some(rel_to(&base_dir.join(sf), out_dir));
        }
        let text = toml::to_string_pretty(&raw)?;
        let header = format!(
            "# Revised by `rshape diagnose {} --apply {k}`: added {} ({}), then every parameter refit jointly.\n# {}\n# Error on {}: misfit_rms {} -> {} (effect alone) -> {} (joint refit), invalid_fraction {:.1} % -> {:.1} % -> {:.1} %.\n",
            config.path.display(),
            c.effect,
            c.params
                .iter()
                .map(|(n, v)| format!("{n} = {}", sig(*v)))
                .collect::<Vec<_>>()
                .join(", "),
            c.explanation,
            siso.path.display(),
            sig(c.misfit_rms_before),
            sig(c.misfit_rms_after),
            sig(rms_refit),
            100.0 * c.invalid_fraction_before,
            100.0 * c.invalid_fraction_after,
            100.0 * inv_refit.unwrap_or(f64::NAN)
        );
        let full = format!("{header}{text}");
        // The written file must load back.
        crate::model::Config::parse(&full, out)
            .map_err(|e| anyhow!("internal: the revised config does not parse: {e}"))?;
        crate::util::write_atomic(out, full.as_bytes())?;
        if !a.json {
            println!("wrote {} (candidate {k}: {})", out.display(), c.effect);
        }
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&d)?);
        return Ok(0);
    }
    println!(
        "model: {}   data: {} (channel {},{}; {} data; noise: {})",
        config.path.display(),
        siso.path.display(),
        siso.channel.0,
        siso.channel.1,
        d.n_data,
        siso.radius_source
    );
    println!(
        "before: misfit_rms = {}, invalid_fraction = {:.1} %",
        fmt_g(d.before.misfit_rms),
        100.0 * d.before.invalid_fraction
    );
    if !d.candidates.is_empty() {
        println!("\ncandidates (ranked by ΔBIC = 2ΔV − n·ln 2F; pass = ΔBIC > 10, no more invalid data, holdout ok):");
        for c in &d.candidates {
            let params = c
                .params
                .iter()
                .map(|(n, v)| match c.uncertainty_2sigma.get(n) {
                    Some(u) if u.is_finite() => format!("{n} = {} ± {}", sig(*v), sig(*u)),
                    _ => format!("{n} = {}", sig(*v)),
                })
                .collect::<Vec<_>>()
                .join(", ");
            println!(
                "{:>2}. {:<12} ΔBIC {:>10}  misfit_rms {} → {}  invalid {:.1} % → {:.1} %  {}{}",
                c.rank,
                c.effect,
                sig(c.delta_bic),
                sig(c.misfit_rms_before),
                sig(c.misfit_rms_after),
                100.0 * c.invalid_fraction_before,
                100.0 * c.invalid_fraction_after,
                if c.passes { "pass" } else { "-" },
                if c.tie_with_best {
                    "  (tie with #1)"
                } else {
                    ""
                }
            );
            println!("    {params}");
            println!("    {}", c.explanation);
        }
    }
    for t in &d.ties {
        println!(
            "\ntie: {} and {} (BIC gap {}): {}",
            t.effects[0],
            t.effects[1],
            sig(t.bic_gap),
            t.disambiguation
        );
    }
    if !d.steps.is_empty() {
        println!("\ngreedy path (joint refit after each step):");
        for s in &d.steps {
            println!(
                "  step {}: + {} ({}) → misfit_rms {}, invalid {:.1} % (joint refit of {} parameters; effect alone: {}, {:.1} %)",
                s.step,
                s.effect,
                s.params
                    .iter()
                    .map(|(n, v)| format!("{n} = {}", sig(*v)))
                    .collect::<Vec<_>>()
                    .join(", "),
                sig(s.misfit_rms),
                100.0 * s.invalid_fraction,
                s.n_refit,
                sig(s.misfit_rms_before_refit),
                100.0 * s.invalid_fraction_before_refit
            );
        }
    }
    println!("\nverdict: {}: {}", d.verdict, d.message);
    if !d.candidates.is_empty() && a.apply.is_none() {
        println!(
            "add candidate K with: rshape diagnose {} --apply K --write NEW.toml",
            config.path.display()
        );
    }
    Ok(0)
}
