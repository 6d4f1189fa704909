//! The files `synthesize` writes: `controller.toml` (the `[controller]` table that
//! `stability --controller` reads), `controller.json`, `.m`/`.py`/`.jl`, `synthesis.json`,
//! and the proof's `stability.svg`/`.json`, each written atomically.

use super::{stab, SynthesisOutcome};
use crate::error::{Error, Result};
use crate::report::fmt::fmt_g;
use crate::system::StateSpace;
use nalgebra::DMatrix;
use std::path::{Path, PathBuf};

fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| m.row(i).iter().copied().collect())
        .collect()
}

fn toml_matrix(m: &DMatrix<f64>) -> String {
    let r: Vec<String> = rows(m)
        .iter()
        .map(|r| {
            let v: Vec<String> = r.iter().map(|x| format!("{x:?}")).collect();
            format!("[{}]", v.join(", "))
        })
        .collect();
    format!("[{}]", r.join(",\n     "))
}

/// The method of the controller as the outputs name it, and its `γ` line: `H∞ (the fitted r
/// as weight)` with the H∞ `γ` and `γ_opt`, or `Glover–McFarlane` with its `γ`, `γ_min` and
/// `b_opt`.
pub fn method_label(o: &SynthesisOutcome) -> (String, String) {
    match &o.hinf {
        Some((label, h)) => (
            format!("H∞ (the {label} r as weight)"),
            format!(
                "gamma = {:?} (gamma_opt = {:?}, ||r*T||_inf = {:?})",
                h.gamma, h.gamma_opt, h.gamma_achieved
            ),
        ),
        None => (
            "Glover–McFarlane".to_string(),
            format!(
                "b_opt = {:?}, gamma = {:?} (gamma_min = {:?})",
                o.gm.b_opt, o.gm.gamma, o.gm.gamma_min
            ),
        ),
    }
}

/// `controller.toml`: the `[controller]` table (`u = −K·y`) that `stability --controller`
/// reads, headed by the method and its `γ` ([`method_label`]).
pub fn controller_toml(k: &StateSpace, (method, gamma): &(String, String)) -> String {
    format!(
        "# {method} central controller from rshape synthesize:\n# {gamma}; loop u = -K y\n[controller]\nfeedback = \"negative\"\na = {}\nb = {}\nc = {}\nd = {}\n",
        toml_matrix(&k.a),
        toml_matrix(&k.b),
        toml_matrix(&k.c),
        toml_matrix(&k.d)
    )
}

/// A matrix literal for MATLAB/Julia (`[1 2; 3 4]`) or numpy (`np.array([[1, 2], [3, 4]])`).
fn literal(m: &DMatrix<f64>, python: bool) -> String {
    if m.nrows() == 0 || m.ncols() == 0 {
        return if python {
            format!("np.zeros(({}, {}))", m.nrows(), m.ncols())
        } else {
            format!("zeros({}, {})", m.nrows(), m.ncols())
        };
    }
    let r = rows(m);
    if python {
        let v: Vec<String> = r
            .iter()
            .map(|row| {
                let e: Vec<String> = row.iter().map(|x| format!("{x:?}")).collect();
                format!("[{}]", e.join(", "))
            })
            .collect();
        format!("np.array([{}])", v.join(", "))
    } else {
        let v: Vec<String> = r
            .iter()
            .map(|row| {
                let e: Vec<String> = row.iter().map(|x| format!("{x:?}")).collect();
                e.join(" ")
            })
            .collect();
        format!("[{}]", v.join("; "))
    }
}

fn script(
    k: &StateSpace,
    (method, gamma): &(String, String),
    comment: &str,
    preamble: &str,
    call: &str,
    python: bool,
) -> String {
    let end = if python || comment == "#" { "" } else { ";" };
    format!(
        "{comment} {method} controller from rshape synthesize; loop u = -K y\n{comment} {gamma}\n{preamble}A = {}{end}\nB = {}{end}\nC = {}{end}\nD = {}{end}\nK = {call}{end}\n",
        literal(&k.a, python),
        literal(&k.b, python),
        literal(&k.c, python),
        literal(&k.d, python)
    )
}

/// Writes the controller and the reports into `out` (atomically) and returns the files.
pub fn write_outputs(out: &Path, o: &SynthesisOutcome) -> Result<Vec<PathBuf>> {
    let k = &o.gm.k;
    let state_space = serde_json::json!({
        "A": rows(&k.a), "B": rows(&k.b), "C": rows(&k.c), "D": rows(&k.d),
        "feedback": "negative",
    });
    let label = method_label(o);
    let synthesis = synthesis_json(o);
    let json = |v: &serde_json::Value| {
        serde_json::to_string_pretty(v).map_err(|e| Error::Invalid(format!("json: {e}")))
    };
    let files = [
        ("controller.toml", controller_toml(k, &label)),
        ("controller.json", json(&state_space)?),
        (
            "controller.m",
            script(k, &label, "%", "", "ss(A, B, C, D)", false),
        ),
        (
            "controller.py",
            script(
                k,
                &label,
                "#",
                "import numpy as np\nimport control as ct\n\n",
                "ct.ss(A, B, C, D)",
                true,
            ),
        ),
        (
            "controller.jl",
            script(
                k,
                &label,
                "#",
                "using ControlSystems\n\n",
                "ss(A, B, C, D)",
                false,
            ),
        ),
        ("synthesis.json", json(&synthesis)?),
    ];
    let mut written = Vec::new();
    for (name, text) in files {
        let p = out.join(name);
        crate::util::write_atomic(&p, text.as_bytes())?;
        written.push(p);
    }
    let head = match &o.hinf {
        Some((_, h)) => format!(
            "{} controller: γ = {} (γ_opt = {})",
            label.0,
            fmt_g(h.gamma),
            fmt_g(h.gamma_opt)
        ),
        None => format!(
            "Glover–McFarlane controller: γ = {} (γ_min = {}), b_opt = {}",
            fmt_g(o.gm.gamma),
            fmt_g(o.gm.gamma_min),
            fmt_g(o.gm.b_opt)
        ),
    };
    let title = match &o.hinf {
        Some(_) => "Theorem 1: 1/σ_max(T) vs |r| — the synthesized H∞ controller",
        None => "Theorem 1: 1/σ_max(T) vs |r| — the synthesized Glover–McFarlane controller",
    };
    written.extend(stab::write_outputs(out, &o.stability, title, &[head])?);
    Ok(written)
}

/// The content of `synthesis.json`: method, `b_opt`, `γ_min`, `γ`, residuals, the
/// controller's order and poles, the closed-loop poles, reduction, merit, one row per bound.
pub fn synthesis_json(o: &SynthesisOutcome) -> serde_json::Value {
    let k = &o.gm.k;
    let rep = &o.stability.report;
    let label = method_label(o);
    // `gamma` is the controller's: the H∞ γ (with `gamma_opt`) or Glover–McFarlane's (with
    // `gamma_min`); Glover–McFarlane's numbers stay under `glover_mcfarlane` either way.
    let (gamma, gamma_opt, gamma_min) = match &o.hinf {
        Some((_, h)) => (h.gamma, Some(h.gamma_opt), None),
        None => (o.gm.gamma, None, Some(o.gm.gamma_min)),
    };
    serde_json::json!({
        "method": if o.hinf.is_some() { "hinf_weighted" } else { "glover_mcfarlane" },
        "method_label": label.0,
        "hinf": o.hinf.as_ref().map(|(label, h)| serde_json::json!({"r": label, "synthesis": h})),
        "glover_mcfarlane": {"b_opt": o.gm.b_opt, "gamma_min": o.gm.gamma_min, "gamma": o.gm.gamma},
        "b_opt": o.gm.b_opt,
        "gamma": gamma,
        "gamma_opt": gamma_opt,
        "gamma_min": gamma_min,
        "gamma_factor": o.gm.gamma / o.gm.gamma_min,
        "rho_xz": o.gm.rho,
        "riccati_residuals": o.gm.riccati_residuals,
        "b_gk": rep.b_gk,
        "controller_order": k.states(),
        "controller_poles": o.controller_poles.iter().map(|z| [z.re, z.im]).collect::<Vec<_>>(),
        "closed_loop_poles": rep.closed_loop_poles.iter().map(|z| [z.re, z.im]).collect::<Vec<_>>(),
        "reduction": &o.reduction,
        "merit": &o.merit,
        "bounds": &o.bounds,
        "robust": o.robust,
        "notes": &o.notes,
    })
}
