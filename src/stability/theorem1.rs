//! The Theorem 1 test: closed-loop poles, exact margins, grid curves (see the module above).

use crate::error::{Error, Result};
use crate::model::controller::Controller;
use crate::model::{Factorization, FactorizationKind};
use crate::system::eig::{eigenvalues, spectral_abscissa};
use crate::system::freq_eval::FreqEvaluator;
use crate::system::hinf::{hinf_norm, HinfNorm};
use crate::system::interconnect::negative_feedback;
use crate::system::{StateSpace, TransferFunction};
use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::Serialize;

/// A realization of `[G  M̃⁻¹]` (inputs `[u; w]`), the system the factor perturbation sees.
/// For normalized state-space factors it shares the plant's states; for factors typed as
/// transfer functions it is the cascade `M̃⁻¹·[Ñ  I]`, whose hidden modes are poles of the
/// (stable) factors, so the closed-loop eigenvalues decide internal stability.
pub fn factor_system(f: &Factorization) -> Result<StateSpace> {
    if f.kind != FactorizationKind::Standard {
        return Err(Error::Invalid(
            "the robust-stability test needs a standard factorization G = M̃⁻¹Ñ ([model] factorization = \"standard\" or a [plant])".into(),
        ));
    }
    if let Some(ncf) = &f.realization {
        return Ok(ncf.plant_and_m_inverse());
    }
    let (p, m) = (f.outputs(), f.inputs());
    let mut rows = Vec::with_capacity(p);
    for i in 0..p {
        let mut row: Vec<TransferFunction> = (0..m).map(|j| f.n.entry(i, j).clone()).collect();
        row.extend((0..p).map(|j| TransferFunction::gain(if i == j { 1.0 } else { 0.0 })));
        rows.push(row);
    }
    let n_i = crate::system::TfMatrix::from_rows(rows).expect("rectangular");
    let s = StateSpace::from_tf_matrix(&n_i).minimal(1e-12);
    let mm = StateSpace::from_tf_matrix(&f.m).minimal(1e-12);
    Ok(mm.inverse("M̃")?.series(&s))
}

/// The Theorem 1 system `w ↦ [u; y]`, `T = [−K; I](I + GK)⁻¹M̃⁻¹`, for `u = −K·y`.
pub fn theorem1_system(f: &Factorization, k: &StateSpace) -> Result<StateSpace> {
    negative_feedback(&factor_system(f)?, k, f.inputs())
}

/// The system `[d₁; d₂] ↦ [u; y]` of `y = G(u + d₂) + d₁`, `u = −K·y`, i.e.
/// `[−K; I](I + GK)⁻¹[I  G]`, whose H∞ norm is `1/b(G, K)`.
pub fn gang_of_four(f: &Factorization, k: &StateSpace) -> Result<StateSpace> {
    let fs = factor_system(f)?;
    let m = f.inputs();
    let p = f.outputs();
    let g = StateSpace {
        a: fs.a.clone(),
        b: fs.b.columns(0, m).into_owned(),
        c: fs.c.clone(),
        d: fs.d.columns(0, m).into_owned(),
    };
    let n = g.states();
    let mut b = DMatrix::zeros(n, m + p + m);
    b.view_mut((0, 0), (n, m)).copy_from(&g.b);
    b.view_mut((0, m + p), (n, m)).copy_from(&g.b);
    let mut d = DMatrix::zeros(p, m + p + m);
    d.view_mut((0, 0), (p, m)).copy_from(&g.d);
    d.view_mut((0, m), (p, p))
        .copy_from(&DMatrix::identity(p, p));
    d.view_mut((0, m + p), (p, m)).copy_from(&g.d);
    let plant = StateSpace {
        a: g.a.clone(),
        b,
        c: g.c.clone(),
        d,
    };
    negative_feedback(&plant, k, m)
}

/// The margin of one bound `r`.
#[derive(Debug, Clone, Serialize)]
pub struct MarginRow {
    /// Which `r` (`configured`, `fitted`, …).
    pub label: String,
    /// The bound.
    #[serde(skip)]
    pub r: TransferFunction,
    /// `α* = 1/‖r·T‖∞` (exact, Hamiltonian iteration); `r` is proven robust iff `α* ≥ 1`.
    pub alpha: f64,
    /// Frequency where `|r|·σ_max(T)` peaks (rad/s; `inf` at high frequency).
    pub omega: f64,
    /// The same margin on the grid: `min_ω 1/(|r|·σ_max(T))`.
    pub alpha_grid: f64,
    /// Whether Theorem 1 proves robust stability (`α* ≥ 1`).
    pub robust: bool,
}

/// Grid curves for the figure.
#[derive(Debug, Clone, Serialize)]
pub struct GridCurve {
    /// Frequencies (rad/s).
    pub omega: Vec<f64>,
    /// `1/σ_max(T(jω))`, the largest `|r(jω)|` allowed pointwise.
    pub inv_t: Vec<f64>,
    /// `|r(jω)|` per margin row, in the same order.
    pub r: Vec<Vec<f64>>,
}

/// The whole Theorem 1 report.
#[derive(Debug, Clone, Serialize)]
pub struct RobustStability {
    /// Eigenvalues of the closed-loop state matrix.
    #[serde(serialize_with = "complex_list")]
    pub closed_loop_poles: Vec<Complex64>,
    /// Largest real part of the closed-loop poles.
    pub abscissa: f64,
    /// Condition 1: `K` internally stabilizes `G`.
    pub internally_stable: bool,
    /// `‖T‖∞` and its frequency (when internally stable).
    pub t_norm: Option<HinfNorm>,
    /// `b(G, K) = 1/‖[K; I](I + GK)⁻¹[I G]‖∞` (when internally stable).
    pub b_gk: Option<f64>,
    /// Whether the factors are normalized (then `1/‖T‖∞ = b(G, K)`).
    pub normalized: bool,
    /// One row per bound `r`.
    pub margins: Vec<MarginRow>,
}

fn complex_list<S: serde::Serializer>(
    v: &[Complex64],
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = s.serialize_seq(Some(v.len()))?;
    for z in v {
        seq.serialize_element(&[z.re, z.im])?;
    }
    seq.end()
}

/// `σ_max(T(jω))` from the factor values: `T = [−K; I](M̃ + ÑK)⁻¹` (since
/// `(I + GK)⁻¹M̃⁻¹ = (M̃ + ÑK)⁻¹`), an evaluation independent of the state-space path.
pub fn t_sigma_max(f: &Factorization, k: &FreqEvaluator, omega: f64) -> Option<f64> {
    let at = f.at(omega);
    let kw = k.freq(omega)?;
    let lhs = &at.m + &at.n * &kw;
    let x = lhs
        .lu()
        .solve(&DMatrix::<Complex64>::identity(at.m.nrows(), at.m.nrows()))?;
    let (m, p) = kw.shape();
    let mut t = DMatrix::zeros(m + p, p);
    t.view_mut((0, 0), (m, p)).copy_from(&(-(&kw * &x)));
    t.view_mut((m, 0), (p, p)).copy_from(&x);
    let s = crate::system::linalg::spectral_norm(&t);
    s.is_finite().then_some(s)
}

/// Runs the Theorem 1 test of `controller` on `f` for each labelled `r`, with grid curves
/// on `grid`.
pub fn analyze(
    f: &Factorization,
    controller: &Controller,
    rs: &[(String, TransferFunction)],
    grid: &[f64],
) -> Result<(RobustStability, GridCurve)> {
    let k = controller.negative_feedback_gain();
    if k.d.shape() != (f.inputs(), f.outputs()) {
        return Err(Error::Invalid(format!(
            "{}: the controller is {}×{} but must be {}×{} (plant inputs × plant outputs)",
            controller.path.display(),
            k.d.nrows(),
            k.d.ncols(),
            f.inputs(),
            f.outputs()
        )));
    }
    let t = theorem1_system(f, &k)?;
    let poles = eigenvalues(&t.a, "closed-loop poles")?;
    let abscissa = spectral_abscissa(&poles);
    let internally_stable = abscissa < 0.0;
    let normalized = f.realization.is_some();
    let kev = FreqEvaluator::new(&k);
    let inv_t: Vec<f64> = grid
        .iter()
        .map(|w| t_sigma_max(f, &kev, *w).map_or(0.0, |s| 1.0 / s))
        .collect();
    let r_curves: Vec<Vec<f64>> = rs
        .iter()
        .map(|(_, r)| grid.iter().map(|w| r.freq(*w).norm()).collect())
        .collect();
    let curve = GridCurve {
        omega: grid.to_vec(),
        inv_t: inv_t.clone(),
        r: r_curves.clone(),
    };
    if !internally_stable {
        return Ok((
            RobustStability {
                closed_loop_poles: poles,
                abscissa,
                internally_stable,
                t_norm: None,
                b_gk: None,
                normalized,
                margins: Vec::new(),
            },
            curve,
        ));
    }
    let t_norm = hinf_norm(&t)?;
    let b_gk = 1.0 / hinf_norm(&gang_of_four(f, &k)?)?.gamma;
    let mut margins = Vec::new();
    for ((label, r), rc) in rs.iter().zip(&r_curves) {
        if !r.is_proper() {
            return Err(Error::Invalid(format!("the {label} r is not proper")));
        }
        let rt = t.times_scalar(&StateSpace::from_tf(r));
        let h = hinf_norm(&rt).map_err(|e| Error::Invalid(format!("the {label} r: {e}")))?;
        let alpha = 1.0 / h.gamma;
        let alpha_grid = inv_t
            .iter()
            .zip(rc)
            .map(|(i, r)| i / r)
            .fold(f64::INFINITY, f64::min);
        margins.push(MarginRow {
            label: label.clone(),
            r: r.clone(),
            alpha,
            omega: h.omega,
            alpha_grid,
            robust: alpha >= 1.0,
        });
    }
    Ok((
        RobustStability {
            closed_loop_poles: poles,
            abscissa,
            internally_stable,
            t_norm: Some(t_norm),
            b_gk: Some(b_gk),
            normalized,
            margins,
        },
        curve,
    ))
}
