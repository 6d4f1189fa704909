//! The linear programs, solved with Clarabel (pure-Rust interior point, `verbose = false`).
//!
//! * **Minimax step** ([`max_slack`]): for a fixed level `t`, with both `A` and `B` free,
//!   maximize the common slack `s` of every (row-normalized) constraint
//!   `A − L·B ≥ s`, `t·U·B − A ≥ s`, `α·B − A ≥ s`, `B ≥ ε + s`, with `b₀ = 1`.  The level
//!   `t` is feasible iff `s* ≥ 0`.  `max_{data} |r|²/r_min²` is quasi-convex in `(A, B)`, so
//!   bisection on `t` gives the log-Chebyshev (minimax) fit with free poles and zeros, as
//!   `fitmagfrd` does; unlike it, the bounds hold on the dense grid, not only at the data.
//!   The LP is always feasible (s may be negative), so a status other than solved is a
//!   numerical event: it is recorded and the level is treated as not feasible.
//! * **Area step** ([`area_fixed_poles`]): with `B` fixed (the poles), minimize the
//!   log-frequency-weighted `Σ w_i |r(jω_i)|²/r_min,i²` over `A` subject to the same bounds.

use super::basis::{basis_row, GridPoint};
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
    /// What was done about it.
    pub action: String,
}

/// A dense LP `min cᵀv` s.t. `G v ≥ h` (rows) and `E v = e`.
pub(crate) struct Lp {
    pub n: usize,
    pub c: Vec<f64>,
    pub ge: Vec<(Vec<f64>, f64)>,
    pub eq: Vec<(Vec<f64>, f64)>,
}

/// Result of [`Lp::solve`].
pub(crate) struct LpOut {
    pub status: SolverStatus,
    pub x: Vec<f64>,
    pub iterations: u32,
}

impl Lp {
    /// Solves with Clarabel.  Never panics: a setup failure is `SetupError`.
    pub fn solve(&self, max_iter: u32) -> LpOut {
        let m = self.eq.len() + self.ge.len();
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
            for (i, (row, _)) in self.ge.iter().enumerate() {
                if row[j] != 0.0 {
                    rowval.push(self.eq.len() + i);
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
            .chain(self.ge.iter().map(|(_, h)| -h))
            .collect();
        let mut cones = Vec::new();
        if !self.eq.is_empty() {
            cones.push(SupportedConeT::ZeroConeT(self.eq.len()));
        }
        if !self.ge.is_empty() {
            cones.push(SupportedConeT::NonnegativeConeT(self.ge.len()));
        }
        let p = CscMatrix::<f64>::zeros((self.n, self.n));
        let fail = LpOut {
            status: SolverStatus::SetupError,
            x: Vec::new(),
            iterations: 0,
        };
        let Ok(settings) = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(max_iter)
            .presolve_enable(false)
            .build()
        else {
            return fail;
        };
        let Ok(mut solver) = DefaultSolver::new(&p, &self.c, &a, &b, &cones, settings) else {
            return fail;
        };
        solver.solve();
        let sol = &solver.solution;
        LpOut {
            status: SolverStatus::from_clarabel(sol.status),
            x: sol.x.clone(),
            iterations: sol.iterations,
        }
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

/// The minimax step at level `t`: returns `(status, s*, a, b)`.  Variables `[a; b; s]`.
pub(crate) fn max_slack(
    q: &[f64],
    grid: &[GridPoint],
    t: f64,
    max_iter: u32,
) -> (SolverStatus, f64, Vec<f64>, Vec<f64>, u32) {
    let k = q.len() + 1;
    let n = 2 * k + 1;
    let mut ge = Vec::with_capacity(4 * grid.len() + 1);
    let row_ab = |phi: &[f64], ca: f64, cb: f64| -> Vec<f64> {
        let mut r = vec![0.0; n];
        for j in 0..k {
            r[j] = ca * phi[j];
            r[k + j] = cb * phi[j];
        }
        r
    };
    for p in grid {
        let phi = basis_row(q, p.x);
        let mut push = |row: Vec<f64>, rhs: f64| {
            let (mut r, h) = normalized(row, rhs);
            r[n - 1] = -1.0;
            ge.push((r, h));
        };
        // |r|² ≥ lower:  A − L·B ≥ 0.
        push(row_ab(&phi, 1.0, -p.lower), 0.0);
        if let Some(u) = p.upper {
            push(row_ab(&phi, -1.0, t * u), 0.0);
        }
        if let Some(a1) = p.a1 {
            push(row_ab(&phi, -1.0, a1), 0.0);
        }
        push(row_ab(&phi, 0.0, 1.0), B_FLOOR);
    }
    // s ≤ 1.
    let mut cap = vec![0.0; n];
    cap[n - 1] = -1.0;
    ge.push((cap, -1.0));
    let mut norm = vec![0.0; n];
    norm[k] = 1.0;
    let mut c = vec![0.0; n];
    c[n - 1] = -1.0;
    let lp = Lp {
        n,
        c,
        ge,
        eq: vec![(norm, 1.0)],
    };
    let out = lp.solve(max_iter);
    if !out.status.has_solution() {
        return (out.status, f64::NEG_INFINITY, vec![], vec![], out.iterations);
    }
    let a = out.x[..k].to_vec();
    let b = out.x[k..2 * k].to_vec();
    (out.status, out.x[n - 1], a, b, out.iterations)
}

/// The area step with fixed poles.  `kappa(x) = D(x)/B(x)` turns the basis value into
/// `|r̂|²`; `weights[i]` is the objective weight of grid point `i` divided by its bound
/// (zero for points outside the objective).  `t_cap` scales the upper envelope.
pub(crate) fn area_fixed_poles(
    q: &[f64],
    grid: &[GridPoint],
    kappa: &[f64],
    weights: &[f64],
    t_cap: f64,
    max_iter: u32,
) -> (SolverStatus, Vec<f64>, f64, u32) {
    let k = q.len() + 1;
    let mut c = vec![0.0; k];
    let mut ge = Vec::with_capacity(3 * grid.len());
    for ((p, kp), w) in grid.iter().zip(kappa).zip(weights) {
        let phi = basis_row(q, p.x);
        if *w != 0.0 {
            for j in 0..k {
                c[j] += w * kp * phi[j];
            }
        }
        // κ·φ·a ≥ L; κ·φ·a ≤ t·U; κ·φ·a ≤ α  (rows divided by κ, then normalized).
        ge.push(normalized(phi.clone(), p.lower / kp));
        if let Some(u) = p.upper {
            ge.push(normalized(
                phi.iter().map(|v| -v).collect(),
                -t_cap * u / kp,
            ));
        }
        if let Some(a1) = p.a1 {
            ge.push(normalized(phi.iter().map(|v| -v).collect(), -a1 / kp));
        }
    }
    let lp = Lp {
        n: k,
        c,
        ge,
        eq: vec![],
    };
    let out = lp.solve(max_iter);
    if !out.status.has_solution() {
        return (out.status, vec![], f64::INFINITY, out.iterations);
    }
    let obj: f64 = lp.c.iter().zip(&out.x).map(|(a, b)| a * b).sum();
    (out.status, out.x, obj, out.iterations)
}
