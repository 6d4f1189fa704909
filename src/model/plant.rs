//! The `[plant]` table ([`PlantSection`]).

use super::config::TfEntry;
use super::factorization::Factorization;
use crate::system::ncf::NormalizedLcf;
use crate::system::{StateSpace, TfMatrix};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `[plant]` table: a plain plant whose normalized left coprime factors rshape computes
/// (see [`NormalizedLcf`] for the formulas and why this normalization is canonical).
///
/// ```toml
/// [plant]                       # one of the three forms:
/// tf = [[{ num = [1], den = [1, 0.2, 4] }, 0.5]]   # a transfer-function matrix, or
/// # a = [[0, 1], [-4, -0.2]]    # inline state space (rows), with b, c, d, or
/// # b = [[0], [1]]
/// # c = [[1, 0]]
/// # d = [[0]]
/// # file = "model.json"         # JSON {"A": [[..]], "B": .., "C": .., "D": ..}
/// # reduce_order = 20           # optional: balanced truncation of a stable plant first
/// ```
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PlantSection {
    /// Transfer-function matrix, rows of entries (same syntax as `[model]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tf: Option<Vec<Vec<TfEntry>>>,
    /// State matrix `A`, rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a: Option<Vec<Vec<f64>>>,
    /// Input matrix `B`, rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b: Option<Vec<Vec<f64>>>,
    /// Output matrix `C`, rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub c: Option<Vec<Vec<f64>>>,
    /// Feedthrough `D`, rows (default zero).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d: Option<Vec<Vec<f64>>>,
    /// A JSON file with keys `A`, `B`, `C`, `D` (row-major lists), relative to the config.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// Reduce a stable plant to this many states by balanced truncation before factoring.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reduce_order: Option<usize>,
}

/// The JSON state-space file (`../shared/data/slicot-*/model.json`).
#[derive(Debug, Deserialize)]
#[allow(non_snake_case)]
struct SsFile {
    A: Vec<Vec<f64>>,
    B: Vec<Vec<f64>>,
    C: Vec<Vec<f64>>,
    #[serde(default)]
    D: Option<Vec<Vec<f64>>>,
}

/// A dense matrix from rows; `cols_if_empty` sizes an empty list.
pub(crate) fn matrix(
    rows: &[Vec<f64>],
    name: &str,
    cols_if_empty: usize,
) -> std::result::Result<DMatrix<f64>, String> {
    if rows.is_empty() {
        return Ok(DMatrix::zeros(0, cols_if_empty));
    }
    let cols = rows[0].len();
    if let Some(i) = rows.iter().position(|r| r.len() != cols) {
        return Err(format!(
            "{name}: row {} has {} entries, row 1 has {cols}",
            i + 1,
            rows[i].len()
        ));
    }
    Ok(DMatrix::from_fn(rows.len(), cols, |i, j| rows[i][j]))
}

/// `A, B, C, D` from rows; `D` defaults to zero.
pub(crate) fn state_space(
    a: &[Vec<f64>],
    b: &[Vec<f64>],
    c: &[Vec<f64>],
    d: Option<&[Vec<f64>]>,
    what: &str,
) -> std::result::Result<StateSpace, String> {
    let a = matrix(a, &format!("{what} a"), 0)?;
    let d_given = match d {
        Some(d) => Some(matrix(d, &format!("{what} d"), 0)?),
        None => None,
    };
    // With no states, `b = []` has D's columns (a static controller as exported).
    let b = matrix(
        b,
        &format!("{what} b"),
        d_given.as_ref().map_or(0, |d| d.ncols()),
    )?;
    let c = matrix(c, &format!("{what} c"), a.nrows())?;
    let d = match d_given {
        Some(d) => d,
        None => DMatrix::zeros(c.nrows(), b.ncols()),
    };
    let ss = StateSpace { a, b, c, d };
    ss.validate(what).map_err(|e| e.to_string())?;
    Ok(ss)
}

/// A second route for the minimal realization of a tf plant: every pole of every entry
/// that no zero of the same entry cancels must be an eigenvalue of the realization. A pole
/// the staircase dropped anyway is an error naming it, never a silent change of plant.
fn check_no_pole_lost(g: &TfMatrix, min: &StateSpace) -> std::result::Result<(), String> {
    let eigs = crate::system::eig::eigenvalues(&min.balanced().a, "[plant] tf realization")
        .map_err(|e| e.to_string())?;
    let cols = g.cols();
    // Absolute scale of the poles: a pole at 0 is matched within 1e-11 of it.
    let scale = eigs.iter().map(|z| z.norm()).fold(0.0, f64::max);
    for (k, t) in g.entries().iter().enumerate() {
        if t.num.is_zero() {
            continue;
        }
        let poles = t.den.roots();
        if !poles.converged {
            continue;
        }
        let zeros = t.num.roots().roots;
        let rho = poles.roots.iter().map(|p| p.norm()).fold(0.0, f64::max);
        for p in &poles.roots {
            // Loose enough for the √ε accuracy of a double root.
            let tol = 1e-3 * p.norm().max(1e-8 * rho.max(scale)).max(f64::MIN_POSITIVE);
            let near = |z: &num_complex::Complex64| (z - p).norm() <= tol;
            if eigs.iter().any(near) || zeros.iter().any(near) {
                continue;
            }
            return Err(format!(
                "[plant] tf[{}][{}]: the pole at {:.6e}{:+.6e}j was lost in the minimal realization (a numerically unobservable or uncontrollable state); write the plant as a state space (a, b, c, d) or rescale it",
                k / cols + 1,
                k % cols + 1,
                p.re,
                p.im
            ));
        }
    }
    Ok(())
}

impl PlantSection {
    /// The plant as a state-space model (`base` resolves `file`).
    pub fn state_space(&self, base: &Path) -> std::result::Result<StateSpace, String> {
        let inline = self.a.is_some() || self.b.is_some() || self.c.is_some() || self.d.is_some();
        let forms = [self.tf.is_some(), inline, self.file.is_some()];
        if forms.iter().filter(|f| **f).count() != 1 {
            return Err(
                "[plant]: give exactly one of tf = [[...]], a/b/c/d, or file = \"model.json\""
                    .into(),
            );
        }
        let ss = if let Some(rows) = &self.tf {
            let cols = rows.first().map_or(0, |r| r.len());
            if cols == 0 {
                return Err("[plant] tf is empty".into());
            }
            let mut tfs = Vec::with_capacity(rows.len());
            for (i, row) in rows.iter().enumerate() {
                if row.len() != cols {
                    return Err(format!(
                        "[plant] tf: row {} has {} entries, row 1 has {cols}",
                        i + 1,
                        row.len()
                    ));
                }
                let r: std::result::Result<Vec<_>, String> = row
                    .iter()
                    .enumerate()
                    .map(|(j, e)| e.to_tf(&format!("[plant] tf[{}][{}]", i + 1, j + 1)))
                    .collect();
                tfs.push(r?);
            }
            for (k, t) in tfs.iter().flatten().enumerate() {
                if !t.is_proper() {
                    return Err(format!(
                        "[plant] tf[{}][{}] is improper (deg num > deg den); a plant must be proper",
                        k / cols + 1,
                        k % cols + 1
                    ));
                }
            }
            let g = TfMatrix::from_rows(tfs).ok_or("[plant] tf is not rectangular")?;
            let min = StateSpace::from_tf_matrix(&g).minimal(1e-10);
            check_no_pole_lost(&g, &min)?;
            min
        } else if inline {
            match (&self.a, &self.b, &self.c, &self.d) {
                (Some(a), Some(b), Some(c), d) => state_space(a, b, c, d.as_deref(), "[plant]")?,
                // A static gain: d alone.
                (None, None, None, Some(d)) => {
                    let d = matrix(d, "[plant] d", 0)?;
                    let ss = StateSpace {
                        a: DMatrix::zeros(0, 0),
                        b: DMatrix::zeros(0, d.ncols()),
                        c: DMatrix::zeros(d.nrows(), 0),
                        d,
                    };
                    ss.validate("[plant]").map_err(|e| e.to_string())?;
                    ss
                }
                _ => {
                    return Err(
                        "[plant]: a state space needs a, b and c (d defaults to zero), or d alone for a static gain"
                            .into(),
                    )
                }
            }
        } else {
            let path = base.join(self.file.as_ref().expect("checked"));
            let text =
                crate::util::read_text_file(&path).map_err(|e| format!("[plant] file {e}"))?;
            let f: SsFile = serde_json::from_str(&text).map_err(|e| {
                format!(
                    "[plant] file {}: {e}; expected {{\"A\": [[..]], \"B\": [[..]], \"C\": [[..]], \"D\": [[..]]}}",
                    path.display()
                )
            })?;
            state_space(
                &f.A,
                &f.B,
                &f.C,
                f.D.as_deref(),
                &format!("[plant] file {}", path.display()),
            )?
        };
        match self.reduce_order {
            Some(k) if k < ss.states() => ss
                .balanced_truncation(k)
                .map(|(r, _)| r)
                .map_err(|e| format!("[plant] reduce_order = {k}: {e}")),
            Some(k) if k > ss.states() => Err(format!(
                "[plant] reduce_order = {k} exceeds the {} states of the plant",
                ss.states()
            )),
            _ => Ok(ss),
        }
    }

    /// The standard factorization by the normalized left coprime factors of the plant,
    /// refused when the factors do not reproduce the plant (`‖M̃G − Ñ‖ ≤ 1e-5`).
    pub fn to_factorization(&self, base: &Path) -> std::result::Result<Factorization, String> {
        Ok(self.to_scaled_factorization(base, None)?.0)
    }

    /// [`PlantSection::to_factorization`] of the scaled plant `D_o·G·D_i` when a `scaling`
    /// is given (resolved against the plant's size; `"auto"` from the plant itself), with
    /// the scalings used.
    pub fn to_scaled_factorization(
        &self,
        base: &Path,
        scaling: Option<&super::scaling::ScalingSpec>,
    ) -> std::result::Result<(Factorization, Option<super::scaling::Scaling>), String> {
        let ss = self.state_space(base)?;
        let (ss, used) = match scaling {
            Some(spec) => {
                let s = spec.resolve(ss.d.nrows(), ss.d.ncols(), Some(&ss))?;
                (s.plant(&ss), Some(s))
            }
            None => (ss, None),
        };
        let scaled = used.is_some();
        let ncf = NormalizedLcf::new(ss).map_err(|e| format!("[plant]: {e}"))?;
        // The factors checked against the plant itself: a gain far from 1 leaves M̃ ≈ 1/G
        // without a correct digit, and every later answer wrong or a puzzling failure.
        let (w, res, gain) = ncf
            .reconstruction_residual()
            .map_err(|e| format!("[plant]: {e}"))?;
        if res.is_nan() || res > FACTOR_RESIDUAL_MAX {
            return Err(format!(
                "[plant]: its gain |G| ≈ {gain:.1e} at {w:.3e} rad/s is too far from 1 for normalized coprime factors in double precision (‖M̃G − Ñ‖ = {res:.1e}, needs ≤ {FACTOR_RESIDUAL_MAX:.0e}); rescale the plant (its output or input units) so that its gain is nearer 1{}",
                if scaled { " (after its [scaling])" } else { ": [scaling] outputs = [...], inputs = [...] in the config" }
            ));
        }
        Ok((Factorization::normalized(ncf), used))
    }
}

/// Largest reconstruction residual `‖M̃G − Ñ‖` of a plant's normalized factors
/// ([`NormalizedLcf::reconstruction_residual`]) accepted: five correct digits, which the
/// residual `≈ ε·|G|` keeps for plant gains up to about 1e10–1e11 (`1e10/(s(s+1))`: 2.2e-6;
/// `1e12/(s(s+1))`: 9.3e-5, its A1 limit already off in the fifth digit).
pub const FACTOR_RESIDUAL_MAX: f64 = 1e-5;
