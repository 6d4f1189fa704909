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
        };
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
        LpOut {
            status: SolverStatus::from_clarabel(sol.status),
            x: sol.x.clone(),
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

/// Initial working set: every point at a stride chosen so that about `target` points are
/// kept, plus the point at infinity.
pub(crate) fn initial_points(grid: &[GridPoint], target: usize) -> Vec<bool> {
    let stride = grid.len().div_ceil(target.max(1)).max(1);
    grid.iter()
        .enumerate()
        .map(|(i, p)| i % stride == 0 || p.x.is_infinite())
        .collect()
}

/// Violated rows added to the working set per round, at most (the largest local maxima of
/// the violation along each group; then the 10 worst rows).
const MAX_ADD: usize = 200;

/// Working-set rounds before the retry with every row.
const MAX_ROUNDS: usize = 40;

/// No retry with every row above this many rows: one retry at 100,000 data (300,000 rows)
/// took 25 s (wall, loaded machine) and ended `AlmostSolved` all the same.
const MAX_RETRY_ROWS: usize = 60_000;

/// Cutting-plane solve of `min cᵀv` s.t. `rows·v ≥ rhs`, `eq`: the LP is solved on a
/// working set of rows; rows violated by its solution are added (the local maxima of the
/// violation along each group, and the worst ones) until none is violated, so the solution
/// is optimal for the full LP.  With 1000 data the working set stays a few hundred rows.
/// `retry_iter` caps the interior-point iterations of the retry with every row (see
/// below), `max_iter` those of the working-set solves; `refine` turns on Clarabel's
/// iterative refinement in every solve (otherwise only in the second try of a solve that
/// ended short of `Solved` or a proof of infeasibility).  `Retry::Decides` (the level
/// searches, where the status says whether a level is feasible) retries an `AlmostSolved`
/// solve too; `Retry::Fails` (the area polish, where an `AlmostSolved` point is a usable
/// candidate, certified like any other) only a solve without a solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Retry {
    /// The status decides a level: retry every solve short of `Solved` or infeasible.
    Decides,
    /// Only the point is used: retry only solves without one.
    Fails,
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn active_set_solve(
    n: usize,
    c: &[f64],
    rows: &[(Vec<f64>, f64)],
    group: &[u32],
    point: &[usize],
    eq: &[(Vec<f64>, f64)],
    init: &[bool],
    mask: &mut Vec<bool>,
    max_iter: u32,
    retry_iter: u32,
    refine: bool,
    retry: Retry,
) -> (LpOut, usize) {
    // Whether the retry with every row is solved with refinement straight away: once a
    // working-set solve stayed short of `Solved` with refinement (`Retry::Decides`), its
    // retry with every row without refinement ended short of `Solved` as well and was
    // solved again with it, at the price of the largest solve of the level (issue 38:
    // envelopes 0, 3 and 15 of the sweep 3136 → 3068 LPs, 11.4 → 10.5 s CPU, every order's
    // max the same).
    let mut refine_all = refine;
    if mask.len() != rows.len() {
        // Rows of the initial points; the floor rows of B only at every fourth of them.
        *mask = (0..rows.len())
            .map(|i| {
                point[i] == usize::MAX
                    || (init[point[i]] && (group[i] < 6 || point[i].is_multiple_of(4)))
            })
            .collect();
    }
    let mut rounds = 0;
    // Clarabel solves (a repeat answered by the memo is not one).
    let mut solves = 0;
    let mut all = false;
    let on = |mask: &[bool], i: usize| mask[i];
    loop {
        rounds += 1;
        let ge: Vec<(Vec<f64>, f64)> = (0..rows.len())
            .filter(|i| all || on(mask, *i))
            .map(|i| rows[i].clone())
            .collect();
        let lp = Lp {
            n,
            c: c.to_vec(),
            ge,
            eq: eq.to_vec(),
        };
        let iter = if all { retry_iter } else { max_iter };
        let refine = refine || (all && refine_all);
        let (mut out, ran) = lp.solve_memo(iter, refine);
        solves += usize::from(ran);
        let settled = match retry {
            Retry::Decides => matches!(
                out.status,
                SolverStatus::Solved | SolverStatus::PrimalInfeasible
            ),
            Retry::Fails => matches!(
                out.status,
                SolverStatus::Solved | SolverStatus::AlmostSolved | SolverStatus::PrimalInfeasible
            ),
        };
        if !refine && !settled {
            // Solved again with iterative refinement before the status counts: without it a
            // level of the partial-fraction search at order 8 of the ISS example ended short
            // of `Solved` and was taken as not feasible, and the order lost 0.14 decade
            // (max log10 |r|/r_min 1.930 instead of 1.790); with this retry the example's
            // `--order auto` fit solves fewer LPs (379 instead of 519), the retry being
            // cheaper than the bisection steps a wrong verdict costs.
            rounds += 1;
            let (o, ran) = lp.solve_memo(iter, true);
            out = o;
            solves += usize::from(ran);
            if retry == Retry::Decides
                && !matches!(
                    out.status,
                    SolverStatus::Solved | SolverStatus::PrimalInfeasible
                )
            {
                refine_all = true;
            }
        }
        if !out.status.has_solution() || rounds > MAX_ROUNDS {
            // A working set can leave the objective unbounded or the LP ill-posed: retry
            // once with every row before reporting the status.  An infeasible working set
            // proves the full LP infeasible: no retry.  Nor is there one beyond
            // `MAX_RETRY_ROWS` (it would cost more than the rest of the fit).
            if all
                || rows.len() > MAX_RETRY_ROWS
                || matches!(
                    out.status,
                    SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible
                )
            {
                return (out, solves);
            }
            all = true;
            continue;
        }
        if all {
            return (out, solves);
        }
        let scale = 1.0 + out.x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let viol: Vec<f64> = rows
            .iter()
            .map(|(r, h)| h - r.iter().zip(&out.x).map(|(a, b)| a * b).sum::<f64>())
            .collect();
        let tol = 1e-9 * scale;
        let mut add: Vec<usize> = Vec::new();
        let mut worst: Vec<usize> = Vec::new();
        for i in 0..rows.len() {
            if on(mask, i) || viol[i] <= tol {
                continue;
            }
            let same = |j: usize| group[j] == group[i];
            let left = i == 0 || !same(i - 1) || viol[i - 1] <= viol[i];
            let right = i + 1 == rows.len() || !same(i + 1) || viol[i + 1] < viol[i];
            if left && right {
                add.push(i);
            } else {
                worst.push(i);
            }
        }
        // The largest local maxima only: on jagged data nearly every other row is one (7000
        // rows added in one round at 100,000 data, a working set of 21,000 rows).
        add.sort_by(|a, b| viol[*b].total_cmp(&viol[*a]));
        add.truncate(MAX_ADD);
        worst.sort_by(|a, b| viol[*b].total_cmp(&viol[*a]));
        add.extend(worst.into_iter().take(10));
        if add.is_empty() {
            return (out, solves);
        }
        for i in add {
            mask[i] = true;
        }
    }
}

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
    );
    if !out.status.has_solution() {
        return (out.status, vec![], f64::INFINITY, rounds);
    }
    let obj: f64 = c.iter().zip(&out.x).map(|(a, b)| a * b).sum();
    (out.status, out.x, obj, rounds)
}
