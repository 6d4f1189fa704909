//! The working-set (cutting-plane) solve of the fit's LPs: an LP with thousands of rows and
//! few columns is solved with Clarabel on a subset of its rows, growing the subset by the
//! rows its solution violates until none is (split out of [`super::problem`]).

use super::basis::GridPoint;
use super::problem::{Lp, LpOut, SolverStatus};

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

/// The escalation of one polynomial level across its working-set solves (issue 38,
/// eleventh step; [`super::experiment::Switches`]): refinement for the rest of the level
/// once a refined solve stayed short of `Solved`, and a budget of Clarabel solves.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Escalate {
    /// Whether a refined solve short of `Solved` turns refinement on for the rest.
    pub sticky: bool,
    /// Refinement is on for the rest of the level (set here when `sticky`).
    pub refined: bool,
    /// Clarabel solves this call may make (`usize::MAX`: no budget).
    pub budget: usize,
    /// Set when the budget ran out before a verdict.
    pub spent: bool,
}

impl Escalate {
    /// No escalation, no budget: the working-set solve as before the eleventh step.
    pub(crate) fn off() -> Self {
        Self {
            sticky: false,
            refined: false,
            budget: usize::MAX,
            spent: false,
        }
    }
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
    esc: &mut Escalate,
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
        if solves >= esc.budget {
            // A budget (the level budget) spent before a verdict: a doubt, never a point.
            esc.spent = true;
            let out = LpOut {
                status: SolverStatus::MaxIterations,
                x: Vec::new(),
            };
            return (out, solves);
        }
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
        let refine = refine || esc.refined || (all && refine_all);
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
                esc.refined |= esc.sticky;
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
