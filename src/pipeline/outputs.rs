//! Writing the outputs of `rshape run` into a directory, each file atomically:
//! `envelope.csv`, the exports of the fitted `r` (`r.json`, ...), the figures
//! (`r_vs_delta.svg`, `bode.svg`, `mu.svg`) and, last, `report.json`.

use super::RunOutcome;
use crate::consistency::EnvelopeMethod;
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::model::Config;
use crate::plot::{
    bode_svg, mu_svg_with, r_vs_delta_svg_with, BodeInput, MuInput, RVsDeltaInput, Symbols,
};
use crate::report::envelope_csv;
use crate::report::run_report::RunReport;
use crate::system::logspace;
use crate::util::write_atomic;
use std::path::{Path, PathBuf};

/// Number of points of the dense grid of the curves.
pub const DENSE_POINTS: usize = 800;

/// The dense grid: a quarter decade beyond the data on each side.
pub fn dense_grid(omega: &[f64]) -> Vec<f64> {
    let lo = omega.first().copied().unwrap_or(0.1);
    let hi = omega.last().copied().unwrap_or(10.0);
    let pad = 10f64.powf(0.25);
    logspace(lo / pad, hi * pad, DENSE_POINTS)
}

/// Label of the per-datum smallest `|r|` for a method.
pub fn r_min_label(m: EnvelopeMethod) -> &'static str {
    match m {
        EnvelopeMethod::Theorem2 => "‖Δᵢ‖, min-norm perturbation (Thm 2, eq. 8)",
        EnvelopeMethod::Theorem3 => "smallest |r| per datum (Thm 3)",
        EnvelopeMethod::Theorem4Mu => "smallest |r| per datum, μ bisection (Thm 4)",
        EnvelopeMethod::File => "smallest |r| per datum",
        EnvelopeMethod::ClosedLoopTheorem1 => "|Δ̄ᵢ| from the closed-loop datum (Thm 1, Cor. 1–2)",
        EnvelopeMethod::ClosedLoopTheorem2 => {
            "smallest |V| per datum: min |Δ̄ᵢ| over the noise (Thm 2)"
        }
    }
}

/// Writes every output of a run into `dir` and returns the report and the files written
/// (`report.json` last).
pub fn write_outputs(
    dir: &Path,
    config: &Config,
    data: &FrfData,
    out: &mut RunOutcome,
) -> Result<(RunReport, Vec<PathBuf>)> {
    let mut files = Vec::new();
    let env = &out.envelope;
    let p = dir.join("envelope.csv");
    write_atomic(&p, envelope_csv(env).as_bytes())?;
    files.push(p);
    if let Ok(fit) = &out.fit {
        let written = out.timings.time("exports", || {
            super::integration::export_r(fit, dir, config.scaling.as_ref())
        })?;
        files.extend(written);
    }
    let t = std::time::Instant::now();
    let svgs = figures(config, data, out)?;
    out.timings
        .0
        .insert("figures".into(), t.elapsed().as_secs_f64() * 1e3);
    for (name, text) in svgs {
        let p = dir.join(name);
        write_atomic(&p, text.as_bytes())?;
        files.push(p);
    }
    let report_path = dir.join("report.json");
    files.push(report_path.clone());
    let report = RunReport::new(config, data, out, &files);
    let text = serde_json::to_string_pretty(&report)
        .map_err(|e| Error::Invalid(format!("report.json: {e}")))?;
    write_atomic(&report_path, text.as_bytes())?;
    Ok((report, files))
}

/// Renders the figures: `(file name, SVG text)`.
pub fn figures(config: &Config, data: &FrfData, out: &RunOutcome) -> Result<Vec<(String, String)>> {
    let env = &out.envelope;
    let grid = dense_grid(&env.omega);
    let a1: Option<Vec<f64>> = super::closed_loop::a1_factorization(config)
        .map(|f| grid.iter().map(|w| f.a1_limit(*w)).collect());
    let failing: Vec<bool> = match &out.check {
        Some(c) => c.rows.iter().map(|r| !r.covers).collect(),
        None => vec![false; env.len()],
    };
    let a1_failing: Vec<bool> = match &out.check {
        Some(c) => c.rows.iter().map(|r| !r.a1_ok).collect(),
        None => Vec::new(),
    };
    let name = config
        .raw
        .name
        .clone()
        .unwrap_or_else(|| config.path.display().to_string());
    // Titles must fit on one line of the figure.
    let name = if name.chars().count() > 64 {
        format!("{}…", name.chars().take(63).collect::<String>())
    } else {
        name
    };
    // The figures of a scaled config show the scaled plant and data (D_o·G·D_i).
    let name = match &config.scaling {
        Some(_) if !name.contains("scaled") => format!("{name} (scaled units)"),
        _ => name,
    };
    let mut svgs = Vec::new();
    let cl = config.closed_loop.is_some();
    let title = if cl {
        format!("Closed loop: |Δ̄| per datum vs |V(jω)| — {name}")
    } else {
        format!("Smallest consistent |r| per datum vs |r(jω)| — {name}")
    };
    svgs.push((
        "r_vs_delta.svg".to_string(),
        r_vs_delta_svg_with(
            &RVsDeltaInput {
                title: &title,
                omega: &env.omega,
                r_min: &env.r_min,
                r_min_label: r_min_label(env.method),
                failing: &failing,
                a1_failing: &a1_failing,
                r_configured: config.r.as_ref(),
                r_fitted: out.fit.as_ref().ok().map(|f| &f.r),
                grid: &grid,
                a1_on_grid: a1.as_deref(),
            },
            &Symbols::of(cl),
        )?,
    ));
    let model: Vec<_> = grid
        .iter()
        .map(|w| super::closed_loop::nominal_response(config, *w))
        .collect();
    let title = if cl {
        format!("Bode: closed-loop data vs nominal (I + P̂C̄)⁻¹P̂ — {name}")
    } else {
        format!("Bode: data vs nominal model — {name}")
    };
    svgs.push((
        "bode.svg".to_string(),
        bode_svg(&BodeInput {
            title: &title,
            omega: &data.omega,
            data: &data.response,
            noise_radius: out.noise_radii.as_deref(),
            grid: &grid,
            model: &model,
            symbol: if cl { "Φ" } else { "G" },
        })?,
    ));
    if let Some(mu) = &out.mu {
        let title = if cl {
            format!("μ_Δs per datum, configured V (Thm 2) — {name}")
        } else {
            format!("μ_Γ per datum, configured r (Fig. 8) — {name}")
        };
        svgs.push((
            "mu.svg".to_string(),
            mu_svg_with(
                &MuInput {
                    title: &title,
                    omega: &env.omega,
                    mu,
                    a1_failing: &a1_failing,
                },
                &Symbols::of(cl),
            )?,
        ));
    }
    Ok(svgs)
}
