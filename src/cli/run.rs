//! `rshape run CONFIG [--data FILE] [--noise-radius X] --out DIR`: the whole pipeline
//! (envelope, check of the configured r, fit, certificate, exports, figures) with
//! `DIR/report.json` and a summary on the terminal.

use super::common::{fmt_g, InputArgs};
use crate::consistency::Verdict;
use crate::pipeline::{self, outputs::write_outputs};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `rshape run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Model and data.
    #[command(flatten)]
    pub input: InputArgs,
    /// Output directory (created if needed).
    #[arg(long)]
    pub out: PathBuf,
    /// Order of the fitted r, or `auto` (sweep 0..8 and pick the smallest good order).
    #[arg(long, default_value = "auto", allow_negative_numbers = true)]
    pub order: crate::fit::OrderChoice,
}

/// `order N, certificate passed` for an `r.json` document (or its `method`, if it names one).
pub fn fit_tag(j: &serde_json::Value) -> String {
    if let Some(m) = j.get("method").and_then(|m| m.as_str()) {
        return m.to_string();
    }
    format!(
        "order {}, certificate {}",
        j.get("order").map_or("?".into(), |o| o.to_string()),
        match j.pointer("/certificate/passed").and_then(|p| p.as_bool()) {
            Some(true) => "passed",
            Some(false) => "FAILED",
            None => "-",
        }
    )
}

/// At most 8 frequencies with their unit, then how many in all.
fn list(v: &[f64]) -> String {
    let head = v
        .iter()
        .take(8)
        .map(|w| fmt_g(*w))
        .collect::<Vec<_>>()
        .join(", ");
    if v.len() > 8 {
        format!("{head}, … rad/s ({} in all)", v.len())
    } else {
        format!("{head} rad/s")
    }
}

/// Runs `rshape run`: exit 0 when the pipeline completed (whatever the verdict; see
/// `verdict` in report.json, or use `rshape check` to gate on it), 2 on an error.
pub fn run(a: &RunArgs) -> Result<i32> {
    let t = Instant::now();
    let inputs = a.input.load()?;
    let load_ms = t.elapsed().as_secs_f64() * 1e3;
    let (config, data) = (&inputs.config, &inputs.data);
    // Closed-loop configs shape the weight V of [v] (Crowder & de Callafon, eq. (2)).
    let sym = crate::plot::Symbols::of(config.closed_loop.is_some());
    let (w, wmin) = (sym.weight, sym.weight_min);
    let view = super::progress::FitProgressView::new("run: fit");
    let progress = |p| view.update(p);
    let envelope_progress = |done, total| view.data("envelope", done, total);
    let options = pipeline::RunOptions {
        noise_radius: a.input.noise_radius,
        envelope_progress: Some(&envelope_progress),
        fit_progress: Some(&progress),
    };
    // `--out` is checked before the work: a refusal must not cost the user the fit.
    let _manifest = super::common::prepare_out(&a.out, &[&a.input.config, &data.path])?;
    let mut out = pipeline::run(config, data, a.order, &options)?;
    view.finish();
    out.timings.0.insert("load".into(), load_ms);
    let (rep, files) = write_outputs(&a.out, config, data, &mut out)?;

    let name = rep
        .name
        .clone()
        .unwrap_or_else(|| config.path.display().to_string());
    outln!("rshape run: {name}");
    outln!(
        "  data      {} ({} points, {}×{}, {})",
        data.path.display(),
        rep.n_data,
        rep.size[0],
        rep.size[1],
        if rep.noisy { "noisy" } else { "noise-free" }
    );
    if let Some(ts) = rep.sample_time {
        // Said once: every frequency below and in the figures is the data's divided by Ts.
        outln!(
            "  frequency per sample in the data, divided by sample_time = {} s: rad/s and Hz here and in the figures",
            fmt_g(ts)
        );
    }
    if let Some(s) = &config.scaling {
        // Said once: every number below refers to the scaled plant D_o·G·D_i.
        outln!(
            "  scaling   {}{}: data, model and {w} in the scaled units (G_s = D_o·G·D_i)",
            s.describe(),
            if s.auto { " (auto)" } else { "" }
        );
        if s.auto {
            outln!(
                "            to fix them, replace scaling = \"auto\" by: {}",
                s.as_toml()
            );
        }
    }
    outln!(
        "  envelope  {}, max {wmin} = {}",
        // The name report.json and the docs use (`theorem4_mu`), not the Rust one.
        serde_json::to_value(rep.method)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_else(|| format!("{:?}", rep.method)),
        rep.max_r_min.map_or("-".into(), fmt_g)
    );
    if !rep.beyond_a1.is_empty() {
        outln!(
            "            r_min reaches the A1 limit at omega = {}: no admissible r explains these data",
            list(&rep.beyond_a1)
        );
    }
    match rep.verdict {
        Some(Verdict::Consistent) => outln!(
            "  check     CONSISTENT: the configured {w} explains all {} data",
            rep.n_data
        ),
        Some(Verdict::Inconsistent) => outln!(
            "  check     INCONSISTENT at {} of {} data: omega = {}",
            rep.failing_omegas.len(),
            rep.n_data,
            list(&rep.failing_omegas)
        ),
        Some(Verdict::NotAdmissible) => outln!(
            "  check     NOT ADMISSIBLE: A1 fails for the configured {w} (|{w}| ≥ σ_min(M̃)) at {} of {} data: omega = {}; no verdict on consistency there",
            rep.a1_violations.len(),
            rep.n_data,
            list(&rep.a1_violations)
        ),
        None => outln!(
            "  check     no [{}] in the config: nothing to check",
            w.to_lowercase()
        ),
    }
    let coeffs = |c: &[f64]| c.iter().map(|x| fmt_g(*x)).collect::<Vec<_>>().join(", ");
    match (&out.fit, &rep.r_fitted) {
        // Up to order 3 the coefficients fit on a line; beyond, r.json has them.
        (Ok(f), Some(j)) if f.r.den.degree() <= 3 => outln!(
            "  fit       {w} = ({})/({}) [{}]",
            coeffs(f.r.num.coeffs()),
            coeffs(f.r.den.coeffs()),
            fit_tag(j)
        ),
        (Ok(_), Some(j)) => outln!("  fit       {w}: {} (coefficients in r.json)", fit_tag(j)),
        _ => outln!(
            "  fit       failed: {}",
            rep.fit_error.clone().unwrap_or_default()
        ),
    }
    // The fit's failure is on the `fit` line already.
    let fit_warning = out
        .fit
        .as_ref()
        .err()
        .map(crate::pipeline::fit_failure_warning);
    for w in rep
        .warnings
        .iter()
        .filter(|w| Some(*w) != fit_warning.as_ref())
    {
        outln!("  warning   {w}");
    }
    outln!(
        "  time      {:.1} ms",
        rep.timings_ms.get("total").copied().unwrap_or(0.0)
    );
    outln!("  wrote     {}", a.out.display());
    for f in &files {
        if let Some(n) = f.file_name() {
            outln!("            {}", n.to_string_lossy());
        }
    }
    Ok(0)
}
