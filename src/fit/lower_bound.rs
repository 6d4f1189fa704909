//! Proven lower bounds per order (issue 38, ninth step): a level `t` that no `r` of order
//! `n` meeting the fit's bounds on the grid can reach, proved by a checked Farkas
//! certificate — a proof does not move with the path of the search, unlike its LPs' points.
//!
//! **The relaxation.**  Write `|r̂|² = A/B` as in [`super::polyfit`], both Chebyshev series
//! of degree `n` in the disk variable `u = (x − 1)/(x + 1)`, `x = ω̂²`.  For any `r` of
//! order ≤ `n`, `A` and `B` are ≥ 0 on `[−1, 1]` (`x ∈ [0, ∞]`), so their Chebyshev
//! coefficients obey `a₀ ≥ 0`, `|a_k| ≤ 2a₀` (`a_k = (2/π)∫A·T_k/√(1−u²)`,
//! `a₀ = (1/π)∫A/√(1−u²)`, `|T_k| ≤ 1`), the same for `b`, and `a₀ + b₀ > 0` may be scaled
//! to 1.  With the bounds every candidate must meet on the grid (the ranking's
//! [`super::engine`] `feasible` test, relative tolerance `10⁻⁶`, loosened here by that much)
//! — `A ≥ (1 − 10⁻⁶)·lower·B`, `A ≤ (1 + 10⁻⁶)·α·B`, `B ≥ 0` at every grid point and the
//! level `A ≤ t·U·B` at the data — this is a convex LP in `(a, b)` (no positivity cuts
//! between grid points, no floor on `B`): every such `r` of level `t` gives a feasible point.
//! So its infeasibility at `t` proves that no such `r` of order `n` reaches `t`.
//!
//! **The proof.**  Clarabel's `PrimalInfeasible` returns `y ≥ 0` (inequalities) and `μ`
//! (the equality `a₀ + b₀ = 1`) with `Gᵀy + μ·e ≈ 0` and `μ > 0`.  It counts only after
//! [`check`] recomputes every row itself (Chebyshev values by `cos(k·acos u)`, not the
//! solver's recurrence), forms `r = Gᵀy + μ·e` and finds `μ > 2‖r‖₁` plus a bound on the
//! round-off: a feasible `v` has `‖v‖∞ ≤ 2` by the coefficient rows above, so
//! `μ ≤ Σ y_i g_iᵀv + μ·eᵀv = rᵀv ≤ 2‖r‖₁`, a contradiction.  Any other status, or a
//! certificate that fails the check, is no proof: a lower bound is raised only by proofs.

use super::basis::PointKind;
use super::chebseries::cheb;
use super::engine::Prepared;
use super::polyrows::disk;
use super::problem::{Lp, SolverStatus};

/// The relative tolerance the ranking allows a candidate on the grid bounds
/// (`engine::feasible`); the relaxation loosens the lower and A1 rows by it.
const FEASIBLE_TOL: f64 = 1e-6;

/// Clarabel iteration cap of one relaxation LP.
const MAX_ITER: u32 = 200;

/// What one row of the relaxation stands for (the check rebuilds the row from it).
#[derive(Debug, Clone, Copy, PartialEq)]
enum RowId {
    /// `a₀ ≥ 0` (`false`) or `b₀ ≥ 0` (`true`).
    Mean(bool),
    /// `2c₀ + sign·c_k ≥ 0` for `c = a` (`false`) or `b` (`true`).
    Coef(bool, usize, f64),
    /// `A ≥ (1 − tol)·lower·B` at grid point `i`.
    Lower(usize),
    /// `A ≤ (1 + tol)·α·B` at grid point `i`.
    A1(usize),
    /// `B ≥ 0` at grid point `i`.
    BPos(usize),
    /// `A ≤ t·U·B` at datum grid point `i`.
    Level(usize),
}

/// `T_0..T_n` at `u ∈ [−1, 1]` by the recurrence (the solver's rows).
fn by_recurrence(n: usize, u: f64) -> Vec<f64> {
    cheb(n, u)
}

/// `T_0..T_n` at `u ∈ [−1, 1]` as `cos(k·acos u)` (the check's rows: another computation).
fn by_cosine(n: usize, u: f64) -> Vec<f64> {
    let th = u.clamp(-1.0, 1.0).acos();
    (0..=n).map(|k| (k as f64 * th).cos()).collect()
}

/// The row `g` of `id` (variables `[a; b]`, `g·v ≥ 0`), divided by its largest coefficient.
fn row(
    prep: &Prepared,
    n: usize,
    t: f64,
    id: RowId,
    basis: fn(usize, f64) -> Vec<f64>,
) -> Vec<f64> {
    let k = n + 1;
    let mut g = vec![0.0; 2 * k];
    let off = |is_b: bool| if is_b { k } else { 0 };
    let mut ab = |ca: f64, cb: f64, i: usize| {
        let tk = basis(n, disk(prep.grid[i].x, 1.0));
        for j in 0..k {
            g[j] = ca * tk[j];
            g[k + j] = cb * tk[j];
        }
    };
    match id {
        RowId::Mean(is_b) => g[off(is_b)] = 1.0,
        RowId::Coef(is_b, j, sign) => {
            g[off(is_b)] = 2.0;
            g[off(is_b) + j] = sign;
        }
        RowId::Lower(i) => ab(1.0, -(1.0 - FEASIBLE_TOL) * prep.grid[i].lower, i),
        RowId::A1(i) => ab(
            -1.0,
            (1.0 + FEASIBLE_TOL) * prep.grid[i].a1.unwrap_or(0.0),
            i,
        ),
        RowId::BPos(i) => ab(0.0, 1.0, i),
        RowId::Level(i) => ab(-1.0, t * prep.grid[i].upper.unwrap_or(0.0), i),
    }
    let m = g.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if m > 0.0 && m.is_finite() {
        g.iter_mut().for_each(|v| *v /= m);
    }
    g
}

/// The rows of the relaxation at order `n`.
fn row_ids(prep: &Prepared, n: usize) -> Vec<RowId> {
    let mut ids = vec![RowId::Mean(false), RowId::Mean(true)];
    for is_b in [false, true] {
        for j in 1..=n {
            ids.push(RowId::Coef(is_b, j, 1.0));
            ids.push(RowId::Coef(is_b, j, -1.0));
        }
    }
    for (i, g) in prep.grid.iter().enumerate() {
        if g.lower > 0.0 {
            ids.push(RowId::Lower(i));
        }
        if g.a1.is_some() {
            ids.push(RowId::A1(i));
        }
        ids.push(RowId::BPos(i));
        if g.kind == PointKind::Datum && g.upper.is_some() {
            ids.push(RowId::Level(i));
        }
    }
    ids
}

/// The equality `a₀ + b₀ = 1`.
fn normalization(n: usize) -> Vec<f64> {
    let mut e = vec![0.0; 2 * (n + 1)];
    e[0] = 1.0;
    e[n + 1] = 1.0;
    e
}

/// What one level of the relaxation gave.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Verdict {
    /// Infeasible, with a certificate that passed [`check`] (its relative margin).
    Proved(f64),
    /// Feasible (solved): no proof at this level.
    Feasible,
    /// No proof: another status, or a certificate that failed its check.
    Undecided(SolverStatus),
}

/// Checks a Farkas certificate `(y, μ)` of the relaxation at level `t` (rows `ids`) on rows
/// it computes itself; returns the margin `(μ − 2‖r‖₁ − round-off)/(Σy + μ)` when positive.
/// Negative or non-finite weights fail.
///
/// Round-off, bounded rather than estimated: each coefficient of a row (at most 1 in
/// magnitude after the division by the largest) is within `(πn + 4)·ε` of the row at the
/// computed `u` (`cos(k·acos u)`: the angle to `πε`, times `k`); each `r_j = Σ y_i g_ij`
/// is summed with Neumaier's compensation (error `≤ 2ε|r_j| + O(mε²)·Σ|y_i g_ij|`) of products
/// each within `ε` relative.  (The computed `u` differs from the grid point's by `~ε`, which
/// moves a bound by far less than the `10⁻⁶` the lower and A1 rows are loosened by, and a
/// level by `~ε` relative.)
fn check(prep: &Prepared, n: usize, t: f64, ids: &[RowId], y: &[f64], mu: f64) -> Option<f64> {
    let nv = 2 * (n + 1);
    if y.len() != ids.len() || !mu.is_finite() || y.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
        return None;
    }
    // Neumaier's compensated sums of `μ·e + Σ y_i g_i`, and `Σ |y_i g_ij|`.
    let (mut sum, mut comp, mut abs) = (normalization(n), vec![0.0; nv], vec![0.0; nv]);
    sum.iter_mut().for_each(|v| *v *= mu);
    abs.iter_mut().zip(&sum).for_each(|(a, v)| *a = v.abs());
    let mut total = mu.abs();
    for (id, yi) in ids.iter().zip(y) {
        if *yi == 0.0 {
            continue;
        }
        total += yi;
        for (j, gj) in row(prep, n, t, *id, by_cosine).into_iter().enumerate() {
            let p = yi * gj;
            let s = sum[j] + p;
            comp[j] += if sum[j].abs() >= p.abs() {
                (sum[j] - s) + p
            } else {
                (p - s) + sum[j]
            };
            sum[j] = s;
            abs[j] += p.abs();
        }
    }
    let e = f64::EPSILON;
    let coef = (std::f64::consts::PI * n as f64 + 4.0) * e;
    let (mut norm1, mut round) = (0.0, 0.0);
    for j in 0..nv {
        let r = sum[j] + comp[j];
        norm1 += r.abs();
        round +=
            coef * total + e * abs[j] + 2.0 * e * r.abs() + (ids.len() as f64) * e * e * abs[j];
    }
    // Every feasible `v` has `‖v‖∞ ≤ 2`.
    let margin = mu - 2.0 * norm1 - 2.0 * 1.01 * round;
    (margin > 0.0 && total.is_finite()).then_some(margin / total)
}

/// Solves the relaxation of order `n` at level `t` and checks a certificate of
/// infeasibility; one LP.
pub(crate) fn prove_below(prep: &Prepared, n: usize, t: f64) -> Verdict {
    match certificate(prep, n, t) {
        Ok((ids, y, mu)) => match check(prep, n, t, &ids, &y, mu) {
            Some(m) => Verdict::Proved(m),
            None => Verdict::Undecided(SolverStatus::PrimalInfeasible),
        },
        Err(v) => v,
    }
}

/// The rows of the relaxation and Clarabel's certificate `(y, μ)` of its infeasibility at
/// `t`, unchecked; or the verdict without one.
#[allow(clippy::type_complexity)]
fn certificate(prep: &Prepared, n: usize, t: f64) -> Result<(Vec<RowId>, Vec<f64>, f64), Verdict> {
    if !(t.is_finite() && t > 0.0) {
        return Err(Verdict::Undecided(SolverStatus::SetupError));
    }
    let ids = row_ids(prep, n);
    let lp = Lp {
        n: 2 * (n + 1),
        c: vec![0.0; 2 * (n + 1)],
        ge: ids
            .iter()
            .map(|id| (row(prep, n, t, *id, by_recurrence), 0.0))
            .collect(),
        eq: vec![(normalization(n), 1.0)],
    };
    let (status, _, z) = lp.solve_with_dual(MAX_ITER, true);
    match status {
        SolverStatus::Solved => Err(Verdict::Feasible),
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible
            if z.len() == ids.len() + 1 =>
        {
            // Clarabel's form `A v + s = b`: the equality's dual is `−μ`; tiny negative
            // weights of inequalities are round-off, and dropping them only changes `r`,
            // which the check computes itself.
            let y: Vec<f64> = z[1..].iter().map(|v| v.max(0.0)).collect();
            Ok((ids, y, -z[0]))
        }
        s => Err(Verdict::Undecided(s)),
    }
}

/// A proven lower bound of one order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Bound {
    /// The largest level `t` with a checked certificate (`None`: none proved).
    pub t: Option<f64>,
    /// LPs solved.
    pub lp_solves: usize,
    /// Levels tested without a proof nor a feasible solve.
    pub undecided: usize,
}

/// `LB_n`: bisection on `ln t` over `(0, ln t_hi)` (`t_hi` a level some `r` of order `n`
/// reaches) until the bracket is `tol_ln` wide or `cap` LPs are spent; a level is raised to
/// only by a checked certificate, and both a feasible solve and a doubt lower the top.
pub(crate) fn lower_bound(prep: &Prepared, n: usize, t_hi: f64, tol_ln: f64, cap: usize) -> Bound {
    let mut b = Bound {
        t: None,
        lp_solves: 0,
        undecided: 0,
    };
    if !(t_hi.is_finite() && t_hi > 1.0) {
        return b;
    }
    let (mut lo, mut hi) = (0.0f64, t_hi.ln());
    // `t ≥ 1 − 10⁻⁶` for every `r` (the datum's lower bound and level share `U`): test the
    // bottom first, so that a bound at the floor is not bisected for.
    let mut at = (1.0 - 2.0 * FEASIBLE_TOL).ln();
    while b.lp_solves < cap {
        b.lp_solves += 1;
        match prove_below(prep, n, at.exp()) {
            Verdict::Proved(_) => {
                b.t = Some(at.exp());
                lo = lo.max(at);
            }
            Verdict::Feasible => hi = at,
            Verdict::Undecided(_) => {
                b.undecided += 1;
                hi = at;
            }
        }
        if b.t.is_none() && at < 0.0 {
            // Not even the floor is proved: nothing will be.
            break;
        }
        if hi - lo <= tol_ln {
            break;
        }
        at = 0.5 * (lo + hi);
    }
    b
}

/// `min` over the data of `½·log10(U_i/r_min,i²)`: `max log10 |r|/r_min ≥ ½·log10 t + this`
/// for an `r` of level `t` (the data's `U` is `((1 + margin)·r_min)²`, so it is
/// `log10(1 + margin)` and a little, see `context::prepare`).
pub(crate) fn log10_offset(prep: &Prepared) -> f64 {
    prep.grid
        .iter()
        .filter(|g| g.kind == PointKind::Datum)
        .filter_map(|g| {
            let (u, i) = (g.upper?, g.datum?);
            (prep.rmin[i] > 0.0).then(|| 0.5 * (u / (prep.rmin[i] * prep.rmin[i])).log10())
        })
        .fold(f64::INFINITY, f64::min)
}

/// A proven lower bound of one order, in the units of the order table.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ProvenBound {
    /// The order.
    pub order: usize,
    /// No `r` of this order meeting the fit's bounds on its grid has a max
    /// `log10 |r|/r_min` below this (`None`: nothing proved).
    pub max_log10: Option<f64>,
    /// The same as a level `t` of `|r̂|²/U` at the data, the fit's scaled units (the
    /// `t=` of its solver events).
    pub level: Option<f64>,
    /// LPs solved for it.
    pub lp_solves: usize,
    /// Levels left without a proof nor a feasible solve.
    pub undecided: usize,
}

/// `LB_n` for each order `n` of `maxes` (the max `log10 |r|/r_min` some `r` of order `n`
/// reaches, e.g. the order table of [`super::fit_auto`]), bisected to `tol_log10` decade
/// (at most 40 LPs per order).  The same grid as the fit of `env` with `settings`.
pub fn proven_lower_bounds(
    env: &crate::consistency::Envelope,
    a1: Option<super::A1Fn<'_>>,
    settings: &super::FitSettings,
    maxes: &[f64],
    tol_log10: f64,
) -> Result<Vec<ProvenBound>, super::FitError> {
    let ctx = super::context::prepare(env, a1, settings)?;
    let off = log10_offset(&ctx.prep);
    let tol_ln = 2.0 * tol_log10 * std::f64::consts::LN_10;
    Ok(maxes
        .iter()
        .enumerate()
        .map(|(n, m)| {
            let t_hi = 10f64.powf(2.0 * (m - off));
            let b = lower_bound(&ctx.prep, n, t_hi, tol_ln, 40);
            ProvenBound {
                order: n,
                max_log10: b.t.map(|t| 0.5 * t.log10() + off),
                level: b.t,
                lp_solves: b.lp_solves,
                undecided: b.undecided,
            }
        })
        .collect())
}

#[cfg(test)]
#[path = "lower_bound_tests.rs"]
mod tests;
