//! The covariance of every refit slot of a model, `cov = (2JᵀJ)⁻¹` (Fisher information of the
//! complex-Gaussian likelihood, `V = ‖r(θ)‖²` with `r = √2/ρ · (G_d − G)` over every datum
//! of radius `ρ`): the σ of [`crate::diagnose::changes`] and the identifiability rules of
//! [`crate::diagnose::admissible`].
//!
//! `J` is a forward-difference Jacobian, built column by column from the part of the model
//! the slot belongs to: `G` is the sum of its terms (and feedthrough) times the measured
//! quantity's `(jω)^k` and the path effects, so a mode's residue, frequency, damping or input
//! gain changes that mode's term only, and its column is `−(G_t(θ + h) − G_t(θ))·√2/(ρ h)`
//! with `G_t` the model holding that term alone.  A 1000-mode model on 200 data has 3000
//! slots: one single-term model per column instead of the whole model (1000 terms) per
//! column.  The slots of path effects (a delay, a corner) change every term and keep the
//! whole model's difference.
//!
//! The SVD is of the column-scaled `J`; a tall `J` (far more residual rows than slots, as
//! 29952 × 51 on a 1664-line, nine-channel record) is first reduced to its `R` factor
//! (`J = QR`, `Q` with orthonormal columns: `R` has `J`'s singular values and right singular
//! vectors), so the SVD is of a square matrix of the slots' size; a wide `J` (400 × 3000
//! for 1000 modes on 200 data) through the QR of `Jᵀ`, the SVD of a square matrix of the
//! rows' size ([`svd_right`]).

use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::slots::{get_lin, get_nl, set_lin, set_nl, Lin, Nl, Term};
use crate::model::physical::PhysicalModel;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use rayon::prelude::*;

/// A slot of the model: linear (an output gain, a feedthrough) or nonlinear.
#[derive(Clone, Copy)]
enum Slot {
    Lin(Lin),
    Nl(Nl),
}

/// The part of the model a slot changes.
enum Part {
    /// One term (a rigid body, an integrator or a mode): the model with it alone, and the
    /// slot re-indexed into that model.
    Term(Term),
    /// The feedthrough.
    Feed,
    /// Every term (a path effect's parameter).
    Whole,
}

fn part_of(s: Slot) -> Part {
    match s {
        Slot::Lin(Lin::Out(t, _)) => Part::Term(t),
        Slot::Lin(Lin::Feed(..)) => Part::Feed,
        Slot::Nl(Nl::ModeW(i) | Nl::ModeZ(i)) => Part::Term(Term::Mode(i)),
        Slot::Nl(Nl::RigidPole(i)) => Part::Term(Term::Rigid(i)),
        Slot::Nl(Nl::In(t, _)) => Part::Term(t),
        Slot::Nl(Nl::Delay(_) | Nl::LogEffect(_)) => Part::Whole,
    }
}

/// The first term of `t`'s kind (where `t` sits in a model holding it alone).
fn first(t: Term) -> Term {
    match t {
        Term::Rigid(_) => Term::Rigid(0),
        Term::Int(_) => Term::Int(0),
        Term::Mode(_) => Term::Mode(0),
    }
}

/// Slot `s` of a term re-indexed into the model holding that term alone.
fn reindexed(s: Slot) -> Slot {
    match s {
        Slot::Lin(Lin::Out(t, o)) => Slot::Lin(Lin::Out(first(t), o)),
        Slot::Nl(Nl::ModeW(_)) => Slot::Nl(Nl::ModeW(0)),
        Slot::Nl(Nl::ModeZ(_)) => Slot::Nl(Nl::ModeZ(0)),
        Slot::Nl(Nl::RigidPole(_)) => Slot::Nl(Nl::RigidPole(0)),
        Slot::Nl(Nl::In(t, i)) => Slot::Nl(Nl::In(first(t), i)),
        other => other,
    }
}

/// `m` without terms and feedthrough (its sizes, quantity and path effects kept).
fn skeleton(m: &PhysicalModel) -> PhysicalModel {
    PhysicalModel {
        inputs: Some(m.n_inputs()),
        outputs: Some(m.n_outputs()),
        quantity: m.quantity,
        factor_den: m.factor_den.clone(),
        factor_pole: m.factor_pole,
        pade_order: m.pade_order,
        rigid_body: vec![],
        integrator: vec![],
        mode: vec![],
        feedthrough: None,
        effect: m.effect.clone(),
    }
}

/// The model holding only the part `p` of `m` (on `skel`), or `None` for the whole model.
fn alone(skel: &PhysicalModel, m: &PhysicalModel, p: &Part) -> Option<PhysicalModel> {
    let mut one = skel.clone();
    match p {
        Part::Term(Term::Rigid(i)) => one.rigid_body.push(m.rigid_body[*i].clone()),
        Part::Term(Term::Int(i)) => one.integrator.push(m.integrator[*i].clone()),
        Part::Term(Term::Mode(i)) => one.mode.push(m.mode[*i].clone()),
        Part::Feed => one.feedthrough = m.feedthrough.clone(),
        Part::Whole => return None,
    }
    Some(one)
}

/// `m` with slot `s` moved by a forward-difference step, and the step (the steps of the
/// slots' scales: `1e-6` of the value, of `1/ω_max` for a delay).
fn stepped(m: &PhysicalModel, s: Slot, w_max: f64) -> (PhysicalModel, f64) {
    let mut t = m.clone();
    let h = match s {
        Slot::Lin(l) => {
            let x = get_lin(m, l);
            let h = 1e-6 * x.abs().max(1e-300);
            set_lin(&mut t, l, x + h);
            h
        }
        Slot::Nl(s) => {
            let x = get_nl(m, s);
            let typ = match s {
                Nl::Delay(_) => 1.0 / w_max,
                Nl::In(..) => x.abs().max(1e-300),
                _ => 1.0,
            };
            let h = 1e-6 * x.abs().max(typ);
            set_nl(&mut t, s, x + h);
            h
        }
    };
    (t, h)
}

fn values(m: &PhysicalModel, data: &Channels) -> Vec<DMatrix<Complex64>> {
    data.omega.iter().map(|w| m.eval(*w)).collect()
}

/// Column of `∂r/∂s` (rows as the residual: datum by datum, each channel's real and
/// imaginary parts): `−(G(θ + h) − G(θ))·√2/(ρ h)` of the part of `m` that `s` changes.
fn column(
    m: &PhysicalModel,
    skel: &PhysicalModel,
    whole: &[DMatrix<Complex64>],
    s: Slot,
    data: &Channels,
) -> Vec<f64> {
    let w_max = data.omega.last().copied().unwrap_or(1.0);
    let part = part_of(s);
    let (g0, g1, h) = match alone(skel, m, &part) {
        Some(one) => {
            let (t, h) = stepped(&one, reindexed(s), w_max);
            (values(&one, data), values(&t, data), h)
        }
        None => {
            let (t, h) = stepped(m, s, w_max);
            (whole.to_vec(), values(&t, data), h)
        }
    };
    let mut col = Vec::with_capacity(2 * data.len() * data.n_ch());
    for k in 0..data.len() {
        for (ch, e) in data.entries.iter().enumerate() {
            let wt = std::f64::consts::SQRT_2 / data.radius[ch][k];
            let d = -(g1[k][*e] - g0[k][*e]) * (wt / h);
            col.push(d.re);
            col.push(d.im);
        }
    }
    col
}

/// The forward-difference Jacobian of the weighted residual over the slots `lin` then `nl`.
fn jacobian(m: &PhysicalModel, lin: &[Lin], nl: &[Nl], data: &Channels) -> DMatrix<f64> {
    let all: Vec<Slot> = lin
        .iter()
        .map(|l| Slot::Lin(*l))
        .chain(nl.iter().map(|s| Slot::Nl(*s)))
        .collect();
    let skel = skeleton(m);
    let whole = if all.iter().any(|s| matches!(part_of(*s), Part::Whole)) {
        values(m, data)
    } else {
        vec![]
    };
    // Independent columns: in parallel (the indexed collect keeps their order).
    let cols: Vec<Vec<f64>> = all
        .par_iter()
        .map(|s| column(m, &skel, &whole, *s, data))
        .collect();
    let rows = 2 * data.len() * data.n_ch();
    DMatrix::from_fn(rows, all.len(), |i, j| cols[j][i])
}

/// The singular values of `j` and its right singular vectors (the rows of `vt`, one
/// column per slot), from the SVD of a square triangular factor: a tall `j = QR` through
/// `R` (the same singular values and right singular vectors); a wide `j` (more slots than
/// rows: 3000 × 400 for 1000 modes on 200 data) through the QR of its transpose,
/// `jᵀ = QR`, so `j = RᵀQᵀ` and, with `R = UΣWᵀ`, `j = WΣ(QU)ᵀ`: the right singular vectors
/// are `QU`.  Signs may differ from a direct SVD; no use of them sees signs.
fn svd_right(j: DMatrix<f64>) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let (rows, n) = j.shape();
    if rows > n {
        let svd = j.qr().r().svd(false, true);
        Some((svd.singular_values, svd.v_t?))
    } else if rows < n {
        let qr = j.transpose().qr();
        let (q, r) = (qr.q(), qr.r());
        let svd = r.svd(true, false);
        let u = svd.u?;
        Some((svd.singular_values, (q * u).transpose()))
    } else {
        let svd = j.svd(false, true);
        Some((svd.singular_values, svd.v_t?))
    }
}

/// Standard deviations of every slot coordinate of `m` (`lin` then `nl`) from
/// `cov = (2JᵀJ)⁻¹`, by an SVD of the column-scaled Jacobian; a coordinate with a
/// noticeable share in a direction the data do not determine gets `∞`.
pub(crate) fn slot_sigmas(m: &PhysicalModel, lin: &[Lin], nl: &[Nl], data: &Channels) -> Vec<f64> {
    slot_covariance(m, lin, nl, data).0
}

/// Standard deviations of every slot coordinate (as [`slot_sigmas`]) and, when the Jacobian
/// has full rank, the correlation matrix of the slots (`lin` then `nl`) from the same
/// covariance `(2JᵀJ)⁻¹`.
pub(crate) fn slot_covariance(
    m: &PhysicalModel,
    lin: &[Lin],
    nl: &[Nl],
    data: &Channels,
) -> (Vec<f64>, Option<DMatrix<f64>>) {
    let n = lin.len() + nl.len();
    let rows = 2 * data.len() * data.n_ch();
    if n == 0 || rows == 0 {
        return (vec![f64::INFINITY; n], None);
    }
    let mut jac = jacobian(m, lin, nl, data);
    let scale: Vec<f64> = (0..n).map(|j| jac.column(j).norm()).collect();
    if scale.iter().any(|s| !s.is_finite()) {
        return (vec![f64::INFINITY; n], None);
    }
    for (j, s) in scale.iter().enumerate() {
        if *s > 0.0 {
            jac.column_mut(j).scale_mut(1.0 / s);
        }
    }
    let Some((singular_values, vt)) = svd_right(jac) else {
        return (vec![f64::INFINITY; n], None);
    };
    let smax = singular_values.max();
    let mut var = vec![0.0; n];
    let mut undetermined = vec![false; n];
    for (k, sk) in singular_values.iter().enumerate() {
        if *sk <= 1e-10 * smax {
            for (j, u) in undetermined.iter_mut().enumerate() {
                *u |= vt[(k, j)].abs() > 1e-3;
            }
            continue;
        }
        for (j, v) in var.iter_mut().enumerate() {
            *v += (vt[(k, j)] / sk).powi(2);
        }
    }
    // Fewer residual rows than slots (a wide `J`: 1000 modes on 200 data): the SVD returns
    // only `rows` right singular vectors, and the other `n − rows` span directions the data
    // do not see at all; a coordinate's share in them is what its unit vector lacks in
    // the ones returned.
    if singular_values.len() < n {
        for (j, u) in undetermined.iter_mut().enumerate() {
            let seen: f64 = vt.column(j).norm_squared();
            *u |= 1.0 - seen > 1e-6;
        }
    }
    let sigma = (0..n)
        .map(|j| {
            if undetermined[j] || scale[j] == 0.0 {
                f64::INFINITY
            } else {
                (var[j] / 2.0).sqrt() / scale[j]
            }
        })
        .collect();
    // Correlations in the scaled coordinates (the scale cancels): V Σ⁻² Vᵀ normalized.
    let full_rank =
        singular_values.len() == n && singular_values.iter().all(|sk| *sk > 1e-10 * smax);
    let corr = full_rank.then(|| {
        let k = singular_values.len();
        let mut w = vt.transpose();
        for c in 0..k {
            let sk = singular_values[c];
            w.column_mut(c).scale_mut(1.0 / sk);
        }
        let cov = &w * w.transpose();
        let d: Vec<f64> = (0..n).map(|j| cov[(j, j)].max(1e-300).sqrt()).collect();
        DMatrix::from_fn(n, n, |a, b| cov[(a, b)] / (d[a] * d[b]))
    });
    (sigma, corr)
}

#[cfg(test)]
mod tests;
