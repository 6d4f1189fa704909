//! Exports of a fitted `r(s)`: `r.json` (coefficients, zeros, poles, gain, a state-space
//! realization, the certificate, the order and the objective) and ready-to-paste snippets
//! `r.m` (MATLAB `tf`), `r.py` (python-control `ct.tf`) and `r.jl` (Julia ControlSystems
//! `tf`).  Every file is written atomically.

use crate::error::Result;
use crate::fit::{FitResult, OrderRow};
use crate::util::write_atomic;
use serde::Serialize;
use std::path::{Path, PathBuf};

#[derive(Serialize)]
struct Complex {
    re: f64,
    im: f64,
}

#[derive(Serialize)]
struct RJson<'a> {
    num: &'a [f64],
    den: &'a [f64],
    zeros: Vec<Complex>,
    poles: Vec<Complex>,
    gain: f64,
    a: Vec<Vec<f64>>,
    b: Vec<Vec<f64>>,
    c: Vec<Vec<f64>>,
    d: Vec<Vec<f64>>,
    // Where the description of r ends and the fit's record begins: r is that of the
    // scaled plant.
    #[serde(skip_serializing_if = "Option::is_none")]
    scaling: Option<&'a super::ScalingNote>,
    order: usize,
    objective: crate::fit::Objective,
    objective_value: f64,
    certificate: &'a crate::fit::Certificate,
    origin: String,
    floor: f64,
    solver_events: &'a [crate::fit::SolverEvent],
    lp_solves: usize,
    order_table: Option<&'a [OrderRow]>,
}

fn rows(m: &nalgebra::DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect())
        .collect()
}

/// A coefficient with full precision (round-trips exactly).
fn num(x: f64) -> String {
    format!("{x:.17e}")
}

fn list(v: &[f64], sep: &str) -> String {
    v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(sep)
}

/// The JSON text of `r.json`, with the `scaling` entry of a scaled config.
pub fn r_json(
    fit: &FitResult,
    table: Option<&[OrderRow]>,
    scaling: Option<&super::ScalingNote>,
) -> String {
    let ss = crate::fit::realization::realize(&crate::fit::Zpk {
        gain: fit.gain,
        zeros: fit.zeros.clone(),
        poles: fit.poles.clone(),
    });
    let cx = |v: &[num_complex::Complex64]| {
        v.iter()
            .map(|z| Complex { re: z.re, im: z.im })
            .collect::<Vec<_>>()
    };
    let j = RJson {
        num: fit.r.num.coeffs(),
        den: fit.r.den.coeffs(),
        zeros: cx(&fit.zeros),
        poles: cx(&fit.poles),
        gain: fit.gain,
        a: rows(&ss.a),
        b: rows(&ss.b),
        c: rows(&ss.c),
        d: rows(&ss.d),
        scaling,
        order: fit.order,
        objective: fit.objective,
        objective_value: fit.objective_value,
        certificate: &fit.certificate,
        origin: fit.origin.to_string(),
        floor: fit.floor,
        solver_events: &fit.solver_events,
        lp_solves: fit.lp_solves,
        order_table: table,
    };
    // serde_json writes non-finite numbers as null; the certificate uses them only for
    // "not applicable" (no A1, order 0).
    serde_json::to_string_pretty(&j).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}

fn header(fit: &FitResult, comment: &str) -> String {
    let c = &fit.certificate;
    format!(
        "{comment} rshape fit: order {}, worst |r|/r_min = {:.6} at {:.4e} rad/s, mean log10(|r|/r_min) = {:.4}\n",
        fit.order, c.worst_ratio, c.worst_ratio_omega, c.mean_log10_ratio
    )
}

/// `r.m`: MATLAB.
pub fn r_matlab(fit: &FitResult) -> String {
    format!(
        "{}r = tf([{}], [{}]);\n",
        header(fit, "%"),
        list(fit.r.num.coeffs(), " "),
        list(fit.r.den.coeffs(), " ")
    )
}

/// `r.py`: python-control.
pub fn r_python(fit: &FitResult) -> String {
    format!(
        "{}import control as ct\n\nr = ct.tf([{}], [{}])\n",
        header(fit, "#"),
        list(fit.r.num.coeffs(), ", "),
        list(fit.r.den.coeffs(), ", ")
    )
}

/// `r.jl`: Julia ControlSystems.
pub fn r_julia(fit: &FitResult) -> String {
    format!(
        "{}using ControlSystems\n\nr = tf([{}], [{}])\n",
        header(fit, "#"),
        list(fit.r.num.coeffs(), ", "),
        list(fit.r.den.coeffs(), ", ")
    )
}

/// Writes `r.json`, `r.m`, `r.py` and `r.jl` into `dir`; returns the paths.  With the
/// `scaling` of a scaled config, `r.json` carries it and the others say it in a first
/// comment line.
pub fn write_fit_exports(
    fit: &FitResult,
    table: Option<&[OrderRow]>,
    dir: &Path,
    scaling: Option<&super::ScalingNote>,
) -> Result<Vec<PathBuf>> {
    let note = |comment: &str, text: String| match scaling {
        Some(s) => format!("{comment} {}\n{text}", s.comment()),
        None => text,
    };
    let files = [
        ("r.json", r_json(fit, table, scaling)),
        ("r.m", note("%", r_matlab(fit))),
        ("r.py", note("#", r_python(fit))),
        ("r.jl", note("#", r_julia(fit))),
    ];
    let mut out = Vec::new();
    for (name, text) in files {
        let p = dir.join(name);
        write_atomic(&p, text.as_bytes())?;
        out.push(p);
    }
    Ok(out)
}
