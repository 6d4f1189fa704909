//! Theorem 1 (robust stability of a controller with each bound `r`) and the synthesis of a
//! controller (Glover–McFarlane, or H∞ with `r` as weight), through
//! [`rshape::pipeline::stability::run`] and [`rshape::pipeline::synthesize::run`]; the
//! reports go to Python as the JSON the CLI writes (`--json`, `synthesis.json`).

use crate::core::unit;
use crate::data::Config;
use crate::errors::{guarded, input, OrRaise};
use nalgebra::DMatrix;
use pyo3::prelude::*;
use rshape::model::{Controller, Feedback};
use rshape::pipeline::{stability as stab, synthesize as syn};
use rshape::system::StateSpace;
use rshape::TransferFunction;
use std::path::PathBuf;

/// A state-space matrix from rows, `r×c` (an empty list is a 0×c or r×0 matrix).
fn matrix(name: &str, rows: &[Vec<f64>], r: usize, c: usize) -> PyResult<DMatrix<f64>> {
    if rows.len() != r || rows.iter().any(|row| row.len() != c) {
        return Err(input(format!(
            "controller: {name} must be {r}×{c} (A n×n, B n×p, C m×n, D m×p for a plant with p outputs and m inputs)"
        )));
    }
    if rows.iter().flatten().any(|x| !x.is_finite()) {
        return Err(input(format!(
            "controller: {name} has a value that is not finite"
        )));
    }
    Ok(DMatrix::from_fn(r, c, |i, j| rows[i][j]))
}

/// Matrices as rows.
pub fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect())
        .collect()
}

type Abcd = (Vec<Vec<f64>>, Vec<Vec<f64>>, Vec<Vec<f64>>, Vec<Vec<f64>>);

fn controller(path: Option<PathBuf>, abcd: Option<Abcd>, feedback: &str) -> PyResult<Controller> {
    let feedback = match feedback {
        "negative" => Feedback::Negative,
        "positive" => Feedback::Positive,
        f => {
            return Err(input(format!(
                "feedback={f:?}: give \"negative\" (u = −K·y) or \"positive\" (u = +K·y)"
            )))
        }
    };
    match (path, abcd) {
        (Some(p), None) => Controller::load(&p).py(),
        (None, Some((a, b, c, d))) => {
            let n = a.len();
            let p = b.first().map_or(d.first().map_or(0, |r| r.len()), |r| r.len());
            let m = d.len();
            let k = StateSpace {
                a: matrix("A", &a, n, n)?,
                b: matrix("B", &b, n, p)?,
                c: matrix("C", &c, m, n)?,
                d: matrix("D", &d, m, p)?,
            };
            Ok(Controller {
                path: PathBuf::from("<python controller>"),
                k,
                feedback,
            })
        }
        _ => Err(input(
            "controller: give a controller TOML file, a Synthesis, a control.StateSpace/TransferFunction or (A, B, C, D)",
        )),
    }
}

/// Labelled bounds: the config's `[r]` as `configured` (as the CLI), then those given.
fn bounds(
    config: &rshape::Config,
    given: Vec<(String, Vec<f64>, Vec<f64>)>,
) -> PyResult<Vec<(String, TransferFunction)>> {
    let mut rs = stab::bounds(config, None);
    for (label, num, den) in given {
        let r = unit(num, den, &format!("the {label} r"))?;
        rs.push((label, r));
    }
    Ok(rs)
}

/// Theorem 1 for a controller: JSON of the report (as `rshape stability --json`), the text
/// the CLI prints, and whether every bound is proven robust.
#[pyfunction]
#[pyo3(signature = (config, rs, path=None, abcd=None, feedback="negative", data=None))]
pub fn _stability(
    py: Python<'_>,
    config: &Config,
    rs: Vec<(String, Vec<f64>, Vec<f64>)>,
    path: Option<PathBuf>,
    abcd: Option<Abcd>,
    feedback: &str,
    data: Option<PathBuf>,
) -> PyResult<(String, String, bool)> {
    let cfg = config.inner.clone();
    let feedback = feedback.to_string();
    guarded(py, move || {
        let k = controller(path, abcd, &feedback)?;
        stab::check_controller(&cfg, &k).py()?;
        let rs = bounds(&cfg, rs)?;
        let out = stab::run(&cfg, &k, &rs, data.as_deref()).py()?;
        let json = serde_json::to_string(&out.report).map_err(|e| input(e.to_string()))?;
        Ok((json, stab::text(&out), out.robust))
    })
}

/// What `_synthesize` returns: synthesis.json, the stability report, controller.toml, the
/// controller's A, B, C, D, the text the CLI prints.
type SynthesisOut = (String, String, String, Abcd, String);

/// The synthesis of `rshape synthesize` (its settings' defaults), in memory.
#[pyfunction]
#[pyo3(signature = (config, rs, method="gm", gamma_factor=1.1, reduce=None, weights=None, data=None))]
#[allow(clippy::too_many_arguments)]
pub fn _synthesize(
    py: Python<'_>,
    config: &Config,
    rs: Vec<(String, Vec<f64>, Vec<f64>)>,
    method: &str,
    gamma_factor: f64,
    reduce: Option<usize>,
    weights: Option<PathBuf>,
    data: Option<PathBuf>,
) -> PyResult<SynthesisOut> {
    let cfg = config.inner.clone();
    let method = match method {
        "gm" => syn::Method::GloverMcfarlane,
        "hinf" => syn::Method::Hinf,
        m => {
            return Err(input(format!(
                "method={m:?}: give \"gm\" (Glover–McFarlane) or \"hinf\" (H∞ with r as weight)"
            )))
        }
    };
    if !(gamma_factor.is_finite() && gamma_factor > 1.0) {
        return Err(input(format!(
            "gamma_factor={gamma_factor}: must be a number > 1 (gamma = F * gamma_min; the central controller is undefined at gamma_min)"
        )));
    }
    guarded(py, move || {
        let path = cfg.path.clone();
        syn::plant_factors(&cfg, &path).py()?;
        let rs = bounds(&cfg, rs)?;
        let settings = syn::SynthesisSettings {
            gamma_factor,
            reduce,
            method,
            weights: match &weights {
                Some(w) => Some(
                    rshape::synthesis::Weights::load(
                        w,
                        cfg.factorization.inputs(),
                        cfg.factorization.outputs(),
                    )
                    .py()?,
                ),
                None => None,
            },
        };
        let out = syn::run(
            &cfg,
            &path,
            &rs,
            &settings,
            data.as_deref(),
            std::path::Path::new("controller.toml"),
        )
        .py()?;
        let j = |v: &serde_json::Value| serde_json::to_string(v).map_err(|e| input(e.to_string()));
        let synthesis = j(&syn::synthesis_json(&out))?;
        let report =
            serde_json::to_string(&out.stability.report).map_err(|e| input(e.to_string()))?;
        let k = &out.gm.k;
        let toml = syn::controller_toml(k, &syn::method_label(&out));
        Ok((
            synthesis,
            report,
            toml,
            (rows(&k.a), rows(&k.b), rows(&k.c), rows(&k.d)),
            syn::text(&out),
        ))
    })
}
