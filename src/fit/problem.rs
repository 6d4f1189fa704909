//! The linear programs, solved with Clarabel (pure-Rust interior point, `verbose = false`).
//!
//! * **Minimax step** ([`max_slack`]): for a fixed level `t`, with both `A` and `B` free,
//!   maximize the common slack `s` of every (row-normalized) constraint
//!   `A − L·B ≥ s`, `t·U·B − A ≥ s` (at the data only: the level is
//!   `max_i |r(jω_i)|²/r_min,i²`), `α·B − A ≥ s`, `B ≥ ε + s`, with `b₀ = 1`.  The level
//!   `t` is feasible iff `s* ≥ 0`.  `max_{data} |r|²/r_min²` is quasi-convex in `(A, B)`, so
//!   bisection on `t` gives the log-Chebyshev (minimax) fit with free poles and zeros, as
//!   `fitmagfrd` does; unlike it, the bounds hold on the dense grid, not only at the data.
//!   The LP is always feasible (s may be negative), so a status other than solved is a
//!   numerical event: it is recorded and the level is treated as not feasible.
//! * **Area step** ([`area_fixed_poles`]): with `B` fixed (the poles), minimize the
//!   log-frequency-weighted `Σ w_i |r(jω_i)|²/r_min,i²` over `A` subject to the same bounds.

use super::basis::{basis_row, GridPoint, PointKind};
use super::working_set::{active_set_solve, Escalate, Retry};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus as ClStatus, SupportedConeT,
};
use serde::Serialize;

/// Outcome of one Clarabel solve, in our own (serializable) terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverStatus {
    /// Solved to the requested accuracy.
    Solved,
    /// Solved to reduced accuracy.
    AlmostSolved,
    /// Primal infeasible.
    PrimalInfeasible,
    /// Primal infeasible (reduced accuracy).
    AlmostPrimalInfeasible,
    /// Dual infeasible (the objective is unbounded).
    DualInfeasible,
    /// Dual infeasible (reduced accuracy).
    AlmostDualInfeasible,
    /// Iteration limit.
    MaxIterations,
    /// Time limit.
    MaxTime,
    /// Numerical error.
    NumericalError,
    /// Lack of progress.
    InsufficientProgress,
    /// The solver could not be set up, or returned another status.
    SetupError,
    /// Not a solver status: every candidate of an order failed (see the action).
    NoCandidate,
}

impl SolverStatus {
    fn from_clarabel(s: ClStatus) -> Self {
        match s {
            ClStatus::Solved => Self::Solved,
            ClStatus::AlmostSolved => Self::AlmostSolved,
            ClStatus::PrimalInfeasible => Self::PrimalInfeasible,
            ClStatus::AlmostPrimalInfeasible => Self::AlmostPrimalInfeasible,
            ClStatus::DualInfeasible => Self::DualInfeasible,
            ClStatus::AlmostDualInfeasible => Self::AlmostDualInfeasible,
            ClStatus::MaxIterations => Self::MaxIterations,
            ClStatus::MaxTime => Self::MaxTime,
            ClStatus::NumericalError => Self::NumericalError,
            ClStatus::InsufficientProgress => Self::InsufficientProgress,
            _ => Self::SetupError,
        }
    }

    /// True when a primal solution is available (solved, possibly to reduced accuracy).
    pub fn has_solution(self) -> bool {
        matches!(self, Self::Solved | Self::AlmostSolved)
    }
}

/// A solver call that did not end in `Solved`: where, and what came back.
#[derive(Debug, Clone, Serialize)]
pub struct SolverEvent {
    /// Order being fitted.
    pub order: usize,
    /// Which LP (`minimax t=…`, `area …`).
    pub stage: String,
    /// The status.
    pub status: SolverStatus,
    /// What the event was, as a type.
    pub kind: super::provenance::EventKind,
    /// What was done about it.
    pub action: String,
}

/// A dense LP `min cᵀv` s.t. `G v ≥ h` (rows) and `E v = e`.
#[derive(Clone, PartialEq)]
pub(crate) struct Lp {
    pub n: usize,
    pub c: Vec<f64>,
    pub ge: Vec<(Vec<f64>, f64)>,
    pub eq: Vec<(Vec<f64>, f64)>,
}

/// Result of [`Lp::solve`].
#[derive(Clone)]
pub(crate) struct LpOut {
    pub status: SolverStatus,
    pub x: Vec<f64>,
}

impl Lp {
    /// [`Self::solve`] through the memo of recent solves ([`super::memo`]): the same LP
    /// with the same settings (compared exactly) gives the same answer without a second
    /// solve.  Returns whether Clarabel ran.
    pub fn solve_memo(&self, max_iter: u32, refine: bool) -> (LpOut, bool) {
        super::memo::solve(self, max_iter, refine)
    }

    /// Solves with Clarabel.  Never panics: a setup failure is `SetupError`.
    pub fn solve(&self, max_iter: u32, refine: bool) -> LpOut {
        let (status, x, _) = self.solve_with_dual(max_iter, refine);
        LpOut { status, x }
    }

    /// [`Self::solve`] with Clarabel's dual vector `z` as well, in the order of the rows
    /// (equalities first, then `ge`): after `PrimalInfeasible` it is a Farkas certificate
    /// (`Aᵀz = 0`, `bᵀz < 0` in Clarabel's form `A v + s = b`; for the rows here
    /// `y = z_ge ≥ 0` and `μ = −z_eq` give `Gᵀy + Eᵀμ = 0`, `hᵀy + eᵀμ > 0`), which
    /// [`super::lower_bound`] checks itself before it counts.
    pub fn solve_with_dual(
        &self,
        max_iter: u32,
        refine: bool,
    ) -> (SolverStatus, Vec<f64>, Vec<f64>) {
        // The inequality rows in the order of the measurement switch (issue 38, eleventh
        // step: the noise floor).
        let order = super::experiment::row_permutation(self.ge.len());
        self.solve_in_order(max_iter, refine, order.as_deref())
    }

    /// [`Self::solve_with_dual`] with the inequality rows handed to Clarabel in `order`
    /// (`order[p]` is the row at position `p`; `None`: as built).  The dual vector is
    /// returned in the order of the rows as built.
    pub(crate) fn solve_in_order(
        &self,
        max_iter: u32,
        refine: bool,
        order: Option<&[usize]>,
    ) -> (SolverStatus, Vec<f64>, Vec<f64>) {
        let m = self.eq.len() + self.ge.len();
        let ge_at = |p: usize| order.as_ref().map_or(p, |o| o[p]);
        // Clarabel form: A v + s = b, s ∈ K.  Equalities: E v + s = e, s ∈ {0};
        // inequalities G v ≥ h  ⇔  −G v + s = −h, s ≥ 0.
        let mut colptr = Vec::with_capacity(self.n + 1);
        let mut rowval = Vec::new();
        let mut nzval = Vec::new();
        colptr.push(0);
        for j in 0..self.n {
            for (i, (row, _)) in self.eq.iter().enumerate() {
                if row[j] != 0.0 {
                    rowval.push(i);
                    nzval.push(row[j]);
                }
            }
            for p in 0..self.ge.len() {
                let row = &self.ge[ge_at(p)].0;
                if row[j] != 0.0 {
                    rowval.push(self.eq.len() + p);
                    nzval.push(-row[j]);
                }
            }
            colptr.push(rowval.len());
        }
        let a = CscMatrix::new(m, self.n, colptr, rowval, nzval);
        let b: Vec<f64> = self
            .eq
            .iter()
            .map(|(_, e)| *e)
            .chain((0..self.ge.len()).map(|p| -self.ge[ge_at(p)].1))
            .collect();
        let mut cones = Vec::new();
        if !self.eq.is_empty() {
            cones.push(SupportedConeT::ZeroConeT(self.eq.len()));
        }
        if !self.ge.is_empty() {
            cones.push(SupportedConeT::NonnegativeConeT(self.ge.len()));
        }
        let p = CscMatrix::<f64>::zeros((self.n, self.n));
        let fail = (SolverStatus::SetupError, Vec::new(), Vec::new());
        let Ok(settings) = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(max_iter)
            .presolve_enable(false)
            .tol_gap_abs(1e-6)
            .tol_gap_rel(1e-6)
            // Iterative refinement only where asked: on the partial-fraction and area LPs it
            // multiplied the cost per solve and turned solves into `AlmostSolved` (2000 data,
            // orders 0–8: 372 LPs, 9 retries with every row, 4.9 s CPU with it everywhere;
            // 209 LPs, no retry, 1.0 s with it nowhere), but the global polynomial candidate
            // needs it to reach the reference optimum (tests/fit_reference.rs, envelope 13 at
            // order 3: 0.011 decade above the reference without it, 0.012 below with it).
            .iterative_refinement_enable(refine)
            .build()
        else {
            return fail;
        };
        let Ok(mut solver) = DefaultSolver::new(&p, &self.c, &a, &b, &cones, settings) else {
            return fail;
        };
        solver.solve();
        let sol = &solver.solution;
        let mut z = sol.z.clone();
        if let (Some(o), true) = (order, z.len() == m) {
            // Back to the rows as built.
            for (p, &i) in o.iter().enumerate() {
                z[self.eq.len() + i] = sol.z[self.eq.len() + p];
            }
        }
        (SolverStatus::from_clarabel(sol.status), sol.x.clone(), z)
    }
}

fn normalized(mut row: Vec<f64>, rhs: f64) -> (Vec<f64>, f64) {
    let m = row.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if m > 0.0 && m.is_finite() {
        row.iter_mut().for_each(|v| *v /= m);
        (row, rhs / m)
    } else {
        (row, rhs)
    }
}

/// Floor on `B/D` (the scaled denominator over the reference polynomial, `b₀ = 1`).
pub const B_FLOOR: f64 = 1e-12;

/// Basis rows of every grid point (computed once per order).
pub(crate) fn basis_rows(q: &[f64], grid: &[GridPoint]) -> Vec<Vec<f64>> {
    grid.iter().map(|p| basis_row(q, p.x)).collect()
}

/// The minimax step at level `t`: returns `(status, s*, a, b, working-set rounds)`.
/// Variables `[a; b; s]`; `refine` as in [`active_set_solve`].
pub(crate) fn max_slack(
    phi: &[Vec<f64>],
    grid: &[GridPoint],
    t: f64,
    init: &[bool],
    mask: &mut Vec<bool>,
    max_iter: u32,
    refine: bool,
) -> (SolverStatus, f64, Vec<f64>, Vec<f64>, usize) {
    let k = phi.first().map_or(1, |p| p.len());
    let n = 2 * k + 1;
    let mut rows = Vec::with_capacity(4 * grid.len() + 1);
    let mut group = Vec::with_capacity(rows.capacity());
    let mut point = Vec::with_capacity(rows.capacity());
    let row_ab = |phi: &[f64], ca: f64, cb: f64| -> Vec<f64> {
        let mut r = vec![0.0; n];
        for j in 0..k {
            r[j] = ca * phi[j];
            r[k + j] = cb * phi[j];
        }
        r
    };
    // Group rows by kind (and data vs grid), each group in frequency order.
    for kind in 0..4u32 {
        for (i, p) in grid.iter().enumerate() {
            let row = match kind {
                0 => Some((row_ab(&phi[i], 1.0, -p.lower), 0.0)),
                // The level: at the data only (the log-Chebyshev objective of the issue).
                1 => p
                    .upper
                    .filter(|_| p.kind == PointKind::Datum)
                    .map(|u| (row_ab(&phi[i], -1.0, t * u), 0.0)),
                2 => p.a1.map(|a1| (row_ab(&phi[i], -1.0, a1), 0.0)),
                _ => Some((row_ab(&phi[i], 0.0, 1.0), B_FLOOR)),
            };
            if let Some((row, rhs)) = row {
                let (mut r, h) = normalized(row, rhs);
                r[n - 1] = -1.0;
                rows.push((r, h));
                group.push(2 * kind + u32::from(p.datum.is_some()));
                point.push(i);
            }
        }
    }
    // s ≤ 1.
    let mut cap = vec![0.0; n];
    cap[n - 1] = -1.0;
    rows.push((cap, -1.0));
    group.push(99);
    point.push(usize::MAX);
    let mut norm = vec![0.0; n];
    norm[k] = 1.0;
    let mut c = vec![0.0; n];
    c[n - 1] = -1.0;
    let (out, rounds) = active_set_solve(
        n,
        &c,
        &rows,
        &group,
        &point,
        &[(norm, 1.0)],
        init,
        mask,
        max_iter,
        max_iter,
        refine,
        Retry::Decides,
        &mut Escalate::off(),
    );
    if !out.status.has_solution() {
        return (out.status, f64::NEG_INFINITY, vec![], vec![], rounds);
    }
    let a = out.x[..k].to_vec();
    let b = out.x[k..2 * k].to_vec();
    (out.status, out.x[n - 1], a, b, rounds)
}

/// The area step with fixed poles.  `kappa(x) = D(x)/B(x)` turns the basis value into
/// `|r̂|²`; `weights[i]` is the objective weight of grid point `i` divided by its bound
/// (zero for points outside the objective).  `t_cap` scales the upper envelope; `refine` as
/// in [`active_set_solve`].  Returns `(status, a, objective, working-set rounds)`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn area_fixed_poles(
    phi: &[Vec<f64>],
    grid: &[GridPoint],
    kappa: &[f64],
    weights: &[f64],
    t_cap: f64,
    init: &[bool],
    mask: &mut Vec<bool>,
    max_iter: u32,
    refine: bool,
) -> (SolverStatus, Vec<f64>, f64, usize) {
    let k = phi.first().map_or(1, |p| p.len());
    let mut c = vec![0.0; k];
    for ((ph, kp), w) in phi.iter().zip(kappa).zip(weights) {
        if *w != 0.0 {
            for j in 0..k {
                c[j] += w * kp * ph[j];
            }
        }
    }
    let mut rows = Vec::with_capacity(3 * grid.len());
    let mut group = Vec::with_capacity(rows.capacity());
    let mut point = Vec::with_capacity(rows.capacity());
    // κ·φ·a ≥ L; κ·φ·a ≤ t·U; κ·φ·a ≤ α  (rows divided by κ, then normalized).
    for kind in 0..3u32 {
        for (i, p) in grid.iter().enumerate() {
            let neg = || phi[i].iter().map(|v| -v).collect::<Vec<f64>>();
            let row = match kind {
                0 => Some((phi[i].clone(), p.lower / kappa[i])),
                1 => p.upper.map(|u| (neg(), -t_cap * u / kappa[i])),
                _ => p.a1.map(|a1| (neg(), -a1 / kappa[i])),
            };
            if let Some((row, rhs)) = row {
                rows.push(normalized(row, rhs));
                group.push(2 * kind + u32::from(p.datum.is_some()));
                point.push(i);
            }
        }
    }
    let (out, rounds) = active_set_solve(
        k,
        &c,
        &rows,
        &group,
        &point,
        &[],
        init,
        mask,
        max_iter,
        max_iter,
        refine,
        Retry::Fails,
        &mut Escalate::off(),
    );
    if !out.status.has_solution() {
        return (out.status, vec![], f64::INFINITY, rounds);
    }
    let obj: f64 = c.iter().zip(&out.x).map(|(a, b)| a * b).sum();
    (out.status, out.x, obj, rounds)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows' order changes the iterates, not the LP: the same optimum in every order,
    /// and an infeasible LP's Farkas certificate comes back in the order of the rows as
    /// built (checked here by hand: `y ≥ 0`, `Gᵀy = 0`, `hᵀy > 0`).
    #[test]
    fn row_order_keeps_the_optimum_and_the_certificate() {
        // min 2x + y  s.t.  x ≥ 1, y ≥ 2, x + y ≥ 4: the unique optimum (1, 3).
        let lp = Lp {
            n: 2,
            c: vec![2.0, 1.0],
            ge: vec![
                (vec![1.0, 0.0], 1.0),
                (vec![0.0, 1.0], 2.0),
                (vec![1.0, 1.0], 4.0),
            ],
            eq: vec![],
        };
        // x ≥ 1, y ≥ 1, 2x + y ≤ 2: infeasible; every certificate is a multiple of
        // y = (2, 1, 1), so a multiplier returned at the wrong row fails `Gᵀy = 0`.
        let bad = Lp {
            n: 2,
            c: vec![0.0, 0.0],
            ge: vec![
                (vec![1.0, 0.0], 1.0),
                (vec![0.0, 1.0], 1.0),
                (vec![-2.0, -1.0], -2.0),
            ],
            eq: vec![],
        };
        for order in [None, Some(vec![2, 1, 0]), Some(vec![1, 2, 0])] {
            let (st, x, _) = lp.solve_in_order(100, false, order.as_deref());
            assert_eq!(st, SolverStatus::Solved, "{order:?}");
            assert!(
                (x[0] - 1.0).abs() < 1e-6 && (x[1] - 3.0).abs() < 1e-6,
                "{x:?}"
            );
            let (st, _, z) = bad.solve_in_order(100, false, order.as_deref());
            assert_eq!(st, SolverStatus::PrimalInfeasible, "{order:?}");
            assert!(z.iter().all(|v| *v >= -1e-9), "{z:?}");
            for j in 0..2 {
                let g: f64 = bad.ge.iter().zip(&z).map(|((r, _), y)| r[j] * y).sum();
                assert!(g.abs() < 1e-6 * z.iter().sum::<f64>(), "{order:?}: {z:?}");
            }
            let h: f64 = bad.ge.iter().zip(&z).map(|((_, h), y)| h * y).sum();
            assert!(h > 0.0, "{order:?}: {z:?}");
        }
    }
}
