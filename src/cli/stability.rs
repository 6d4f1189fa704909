//! `rshape stability CONFIG --controller K.toml [--r-json r.json] [--fit] [--out DIR]
//! [--json]`: Theorem 1 of Boulet & Francis for a controller (GitHub issue 10).
//! Exit 0 robustly stable for every bound given, 1 not (including a controller that does
//! not stabilize the nominal plant), 2 error.

use super::common::InputArgs;
use crate::fit::{run_fit, FitSettings, OrderChoice};
use crate::model::controller::Controller;
use crate::model::{Config, FactorizationKind};
use crate::plot::stability::{stability_svg, StabilityInput};
use crate::report::fmt::fmt_g;
use crate::stability::analyze;
use crate::system::{logspace, TransferFunction};
use anyhow::{anyhow, Context, Result};
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

#[derive(serde::Deserialize)]
struct RFile {
    num: Vec<f64>,
    den: Vec<f64>,
}

fn read_r_json(path: &Path) -> Result<TransferFunction> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let r: RFile = serde_json::from_str(&text).map_err(|e| {
        anyhow!(
            "{}: {e}; expected the r.json of `rshape fit` (keys num, den)",
            path.display()
        )
    })?;
    if r.num.iter().chain(&r.den).any(|v| !v.is_finite()) || r.den.iter().all(|v| *v == 0.0) {
        return Err(anyhow!(
            "{}: num/den must be finite, den non-zero",
            path.display()
        ));
    }
    Ok(TransferFunction::new(r.num, r.den))
}

fn grid_for(config: &Config, poles: &[num_complex::Complex64]) -> Vec<f64> {
    let data_range = config
        .data
        .as_ref()
        .and_then(|p| crate::data::read_frf_csv(p).ok())
        .map(|d| (d.omega[0], d.omega[d.omega.len() - 1]));
    let (lo, hi) = match data_range {
        Some((a, b)) => (a / 10.0, b * 10.0),
        None => {
            let mags: Vec<f64> = poles
                .iter()
                .map(|z| z.norm())
                .filter(|w| *w > 0.0)
                .collect();
            let lo = mags.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = mags.iter().copied().fold(0.0, f64::max);
            if lo.is_finite() && hi > 0.0 {
                (lo / 100.0, hi * 100.0)
            } else {
                (1e-3, 1e3)
            }
        }
    };
    logspace(lo, hi, 1000)
}

/// Runs `rshape stability`.
pub fn run(a: &StabilityArgs) -> Result<i32> {
    let config = Config::load(&a.config)?;
    let controller = Controller::load(&a.controller)?;
    let mut rs: Vec<(String, TransferFunction)> = Vec::new();
    // A [closed_loop] config holds the weight V of Crowder & de Callafon in `config.r`: it
    // bounds the dual-Youla perturbation, not the factor perturbation of Theorem 1, so it is
    // not a configured r here (its nominal factors are, with an r from --r-json).
    let closed_loop = config.closed_loop.is_some();
    if closed_loop && a.fit {
        return Err(anyhow!(
            "{}: --fit on a [closed_loop] config would fit its weight V, not a factor bound r: give --r-json r.json",
            a.config.display()
        ));
    }
    if let Some(r) = config.r.as_ref().filter(|_| !closed_loop) {
        rs.push(("configured".into(), r.clone()));
    }
    let mut fit_text = String::new();
    if let Some(p) = &a.r_json {
        rs.push(("fitted".into(), read_r_json(p)?));
    }
    // Grid from the data range, else from the plant's poles (via a first pass, which also
    // checks the controller's size before anything is written).
    let probe = analyze(&config.factorization, &controller, &[], &[1.0])?;
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
    let grid = grid_for(&config, &probe.0.closed_loop_poles);
    let (rep, curve) = analyze(&config.factorization, &controller, &rs, &grid)?;
    let robust = rep.internally_stable && rep.margins.iter().all(|m| m.robust);
    if let Some(out) = &a.out {
        let labelled: Vec<(String, Vec<f64>)> = rs
            .iter()
            .map(|(l, _)| l.clone())
            .zip(curve.r.iter().cloned())
            .collect();
        let svg = stability_svg(&StabilityInput {
            title: "Theorem 1: 1/σ_max(T) against |r|",
            omega: &curve.omega,
            inv_t: &curve.inv_t,
            r: &labelled,
        })?;
        crate::util::write_atomic(&out.join("stability.svg"), svg.as_bytes())?;
        let json = serde_json::json!({ "report": &rep, "grid": &curve, "robust": robust });
        crate::util::write_atomic(
            &out.join("stability.json"),
            serde_json::to_string_pretty(&json)?.as_bytes(),
        )?;
    }
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&rep)?);
        return Ok(if robust { 0 } else { 1 });
    }
    print!("{fit_text}");
    let n = rep.closed_loop_poles.len();
    if !rep.internally_stable {
        let unstable: Vec<String> = rep
            .closed_loop_poles
            .iter()
            .filter(|z| z.re >= 0.0)
            .map(|z| {
                let sign = if z.im < 0.0 { '-' } else { '+' };
                format!("{}{sign}{}j", fmt_g(z.re), fmt_g(z.im.abs()))
            })
            .collect();
        outln!(
            "NOT internally stable: {} of {n} closed-loop poles in the closed right half-plane: {}",
            unstable.len(),
            unstable.join(", ")
        );
        outln!("Theorem 1 condition 1 fails: K does not stabilize the nominal plant.");
        return Ok(1);
    }
    outln!(
        "internally stable: {n} closed-loop poles (the loop's and the factors' own), largest real part {}",
        fmt_g(rep.abscissa)
    );
    if let Some(t) = &rep.t_norm {
        let form = match config.factorization.kind {
            FactorizationKind::Standard => "T = [K; I](I+GK)^-1 M~^-1",
            FactorizationKind::Special => "T = [JKC; I](M~ + N~JKC)^-1, special factorization",
        };
        outln!(
            "||T||_inf = {} at omega = {} rad/s ({form})",
            fmt_g(t.gamma),
            fmt_g(t.omega)
        );
    }
    if let Some(b) = rep.b_gk {
        outln!(
            "b(G,K) = {} (normalized coprime-factor stability margin)",
            fmt_g(b)
        );
        if rep.normalized {
            if let Some(t) = &rep.t_norm {
                outln!(
                    "cross-check (normalized factors): 1/||T||_inf = {}, b(G,K) = {}, relative difference {:.1e}",
                    fmt_g(1.0 / t.gamma),
                    fmt_g(b),
                    ((1.0 / t.gamma) - b).abs() / b
                );
            }
        }
    }
    if rep.margins.is_empty() && closed_loop {
        outln!("no r given: the [v] of a [closed_loop] config is not a factor bound; give --r-json for the Theorem 1 margin");
    } else if rep.margins.is_empty() {
        outln!("no r given: add [r] to the config, --r-json or --fit for the Theorem 1 margin");
    } else {
        outln!(
            "{:<12} {:>12} {:>14} {:>12} {:>8}",
            "r",
            "alpha*",
            "binds at w",
            "alpha grid",
            "robust"
        );
        for m in &rep.margins {
            outln!(
                "{:<12} {:>12} {:>14} {:>12} {:>8}",
                m.label,
                fmt_g(m.alpha),
                fmt_g(m.omega),
                fmt_g(m.alpha_grid),
                if m.robust { "yes" } else { "NO" }
            );
        }
        if let [c, f, ..] = rep.margins.as_slice() {
            outln!(
                "what the tighter r buys: margin {} -> {} ({:+.1}%)",
                fmt_g(c.alpha),
                fmt_g(f.alpha),
                (f.alpha / c.alpha - 1.0) * 100.0
            );
        }
    }
    if let Some(out) = &a.out {
        outln!("wrote {}", out.join("stability.svg").display());
        outln!("wrote {}", out.join("stability.json").display());
    }
    Ok(if robust { 0 } else { 1 })
}
