//! One level of the global polynomial minimax of [`super::polyfit`] at one disk-map centre:
//! the feasibility LP (rows of [`super::polyrows`], solved on a working set), its rounds of
//! exact positivity and relative cuts, and the search over levels that uses it (bracket,
//! gallop, bisection).

use super::basis::PointKind;
use super::chebseries::cheb;
use super::engine::Prepared;
use super::experiment;
use super::polyrows::{
    cut_rows, disk, fixed_rows, level_rows, max_violation, reached_level, relative_cuts,
    relative_level_rows, Rows, B_CUT_GROUP,
};
use super::problem::{SolverEvent, SolverStatus};
use super::provenance::EventKind;
use super::working_set::{active_set_solve, initial_points, Escalate, Retry};
use super::FitSettings;

/// Interior-point iterations of the retry with every row after a working-set solve short
/// of a solution.  Measured on the reference sweep of `tests/fit_reference.rs` (all
/// fitters, cap 200): of 794 such retries every one that ended `Solved`, `AlmostSolved` or
/// `PrimalInfeasible` took at most 87 iterations but three (122, 139, 200); 227 ran to the
/// cap (about 0.4 s each with 1000 data at order 10) and ended as doubts all the same.  A
/// capped retry's point is still used when it meets every row (the check in `try_level`).
const RETRY_ITER: u32 = 100;

/// Rounds of positivity cuts per level.
const CUT_ROUNDS: usize = 8;

/// What one level's LP decided.
enum Level {
    /// Feasible, with this solution.
    Feasible(Vec<f64>),
    /// Proved infeasible (a full-accuracy certificate, no cut stricter than `B > 0`).
    Infeasible,
    /// Not decided (a solve short of `Solved`, cuts that did not converge); an event says
    /// which.
    Doubt,
    /// Infeasible only with a cut `B ≥ b_cut` in the LP (stricter than `B > 0`): not
    /// decided either, but a proof for the LP as it stands, which refinement cannot change;
    /// another cut floor or centre decides the level.
    CutBound,
}

/// The feasibility LP of one level at one disk-map centre, with the cuts found so far
/// (valid at every level: they are not level rows) and the working set carried between
/// levels.
pub(super) struct LevelLp<'a> {
    prep: &'a Prepared,
    n: usize,
    x0: f64,
    b_cut: f64,
    set: &'a FitSettings,
    /// The rows that do not depend on the level.
    base: Rows,
    /// The positivity floor on `|r̂|²` (at infinity).
    floor: f64,
    /// The data as (u, lower bound on `|r̂|²`), increasing in u, for the no-dip cuts.
    data: Vec<(f64, f64)>,
    init: Vec<bool>,
    mask: Vec<bool>,
    /// `(group, point)` of the rows `mask` belongs to (kept only with
    /// `Switches::keep_working_set`, to carry the working set across a change of rows).
    mask_keys: Vec<(u32, usize)>,
    cuts: Rows,
    /// LPs solved so far.
    pub(super) lp_solves: usize,
    /// Whether a cut `B ≥ b_cut` was ever added.
    pub(super) b_cut_used: bool,
}

impl<'a> LevelLp<'a> {
    pub(super) fn new(
        prep: &'a Prepared,
        n: usize,
        x0: f64,
        b_cut: f64,
        set: &'a FitSettings,
    ) -> Self {
        let floor = prep
            .grid
            .iter()
            .filter(|g| g.kind == PointKind::Infinity)
            .map(|g| g.lower)
            .fold(0.0, f64::max);
        let data = if set.no_dip {
            prep.grid
                .iter()
                .filter(|g| g.kind == PointKind::Datum)
                .map(|g| (disk(g.x, x0), g.lower))
                .collect()
        } else {
            Vec::new()
        };
        Self {
            prep,
            n,
            x0,
            b_cut,
            set,
            base: fixed_rows(n, &prep.grid, x0),
            floor,
            data,
            init: initial_points(&prep.grid, 40),
            mask: Vec::new(),
            mask_keys: Vec::new(),
            cuts: Rows::default(),
            lp_solves: 0,
            b_cut_used: false,
        }
    }

    fn doubt(&self, events: &mut Vec<SolverEvent>, t: f64, status: SolverStatus, action: String) {
        events.push(SolverEvent {
            order: self.n,
            stage: format!("polynomial minimax (x0 = {:.3e}) t={t:.4e}", self.x0),
            status,
            kind: EventKind::LevelNotFeasible,
            action,
        });
    }

    /// A solution `[a; b]` meeting every bound at level `t` with `A, B` positive on
    /// `[0, ∞]` (exactly, by the cuts), or `None` (infeasible, or a doubt recorded as an
    /// event).
    fn try_level(&mut self, t: f64, events: &mut Vec<SolverEvent>) -> Option<Vec<f64>> {
        match self.level(t, events) {
            Level::Feasible(x) => Some(x),
            Level::Infeasible | Level::Doubt | Level::CutBound => None,
        }
    }

    /// [`Self::try_level`], telling a proof of infeasibility from a doubt.
    ///
    /// The LPs are solved without Clarabel's iterative refinement first and, only when that
    /// leaves a doubt, again with it: the refinement decides the doubtful levels (envelope 13
    /// of the reference sweep at order 3: 0.011 decade above the reference without it) and
    /// costs 2–3× per solve, on every level when always on (2000 data, orders 0–8: 3.3 s CPU
    /// always on, 1.3 s on a doubt only).  A level infeasible only with the cuts on `B`
    /// ([`Level::CutBound`]) is not solved again: refinement does not remove a cut.
    fn level(&mut self, t: f64, events: &mut Vec<SolverEvent>) -> Level {
        let start = self.lp_solves;
        if self.set.thorough {
            return self.level_with(t, events, true, start);
        }
        let before = events.len();
        match self.level_with(t, events, false, start) {
            // A level whose budget is spent is not solved again.
            Level::Doubt if !self.budget_spent(start) => {
                events.truncate(before);
                self.level_with(t, events, true, start)
            }
            decided => decided,
        }
    }

    /// The LPs this level may still cost ([`Switches::level_budget`], counted from `start`).
    fn budget_left(&self, start: usize) -> usize {
        match experiment::switches().level_budget {
            0 => usize::MAX,
            k => k.saturating_sub(self.lp_solves - start),
        }
    }

    fn budget_spent(&self, start: usize) -> bool {
        self.budget_left(start) == 0
    }

    fn carry_mask(&mut self, r: &Rows) {
        self.mask = carry_mask(&self.mask_keys, &self.mask, &r.group, &r.point);
    }

    /// [`Self::level`] with iterative refinement on or off.
    fn level_with(
        &mut self,
        t: f64,
        events: &mut Vec<SolverEvent>,
        refine: bool,
        start: usize,
    ) -> Level {
        let (n, set) = (self.n, self.set);
        let sw = experiment::switches();
        let mut esc = Escalate {
            sticky: sw.refine_rest_of_level,
            ..Escalate::off()
        };
        let nv = 2 * (n + 1);
        let mut eq = vec![0.0; nv];
        eq[n + 1..].copy_from_slice(&cheb(n, 0.0));
        let eqs = vec![(eq, 1.0)];
        let cost = vec![0.0; nv];
        // Relative level rows of this level (they hold at `t` only).
        let mut level_cuts = Rows::default();
        // A level is proved when the solution reaches it within the search's resolution.
        let reach_tol = set.level_resolution();
        for _ in 0..CUT_ROUNDS {
            let r = level_rows(
                n,
                &self.prep.grid,
                self.x0,
                t,
                &self.base,
                &self.cuts,
                &level_cuts,
            );
            if self.mask.len() != r.rows.len() {
                if sw.keep_working_set
                    && !self.mask.is_empty()
                    && self.mask.len() == self.mask_keys.len()
                {
                    self.carry_mask(&r);
                } else {
                    self.mask.clear();
                }
            }
            esc.budget = self.budget_left(start);
            let (out, rounds) = active_set_solve(
                nv,
                &cost,
                &r.rows,
                &r.group,
                &r.point,
                &eqs,
                &self.init,
                &mut self.mask,
                set.max_solver_iter,
                set.max_solver_iter.min(RETRY_ITER),
                refine,
                Retry::Decides,
                &mut esc,
            );
            self.lp_solves += rounds;
            if sw.keep_working_set {
                self.mask_keys = r
                    .group
                    .iter()
                    .copied()
                    .zip(r.point.iter().copied())
                    .collect();
            }
            if esc.spent {
                self.doubt(
                    events,
                    t,
                    out.status,
                    format!(
                        "level budget of {} LPs spent; level treated as not feasible (the other candidates stand)",
                        sw.level_budget
                    ),
                );
                return Level::Doubt;
            }
            // Only a full-accuracy certificate of infeasibility decides the level; a
            // reduced-accuracy one is a doubt like any other status below.
            if out.status == SolverStatus::PrimalInfeasible {
                // The cuts `B ≥ b_cut` are stricter than `B > 0`: with one of them in the
                // LP, infeasible proves nothing about the level, and another attempt
                // (another centre or cut floor) must decide it.
                if self.cuts.group.contains(&B_CUT_GROUP) {
                    self.doubt(events, t, out.status, "infeasible with the positivity cuts on B; level treated as not feasible (the other candidates stand)".into());
                    return Level::CutBound;
                }
                return Level::Infeasible;
            }
            // A reduced-accuracy or capped solve still proves the level when its point
            // meets every row to the working tolerance: the positivity cuts below and the
            // coverage check of the candidate are exact, whatever the LP's accuracy.
            let usable = out.status == SolverStatus::Solved
                || (out.x.len() == nv
                    && out.x.iter().all(|v| v.is_finite())
                    && max_violation(&r.rows, &out.x) <= 1e-8);
            if !usable {
                self.doubt(
                    events,
                    t,
                    out.status,
                    "level treated as not feasible (the other candidates stand)".into(),
                );
                return Level::Doubt;
            }
            let cut = cut_rows(
                n,
                &out.x,
                self.b_cut,
                self.floor,
                &self.data,
                set.root_iter_cap,
                &mut self.cuts,
            );
            self.b_cut_used |= self.cuts.group.contains(&B_CUT_GROUP);
            if cut || relative_cuts(n, &out.x, &self.prep.grid, self.x0, &mut self.cuts) {
                continue;
            }
            // The level rows are met only to the LP's absolute tolerance: the solution must
            // reach the level as `A/B`, else the level is solved again with the missed rows
            // scaled by the solution's magnitude (a level the solution does not reach proves
            // nothing, and its candidate silently lost the order: ISS orders 6–7).
            if reached_level(n, &out.x, &self.prep.grid, self.x0) <= t * reach_tol {
                return Level::Feasible(out.x);
            }
            if !relative_level_rows(n, &out.x, &self.prep.grid, self.x0, t, &mut level_cuts) {
                self.doubt(
                    events,
                    t,
                    out.status,
                    "the solution misses the level at the data even with its rows scaled relatively; level treated as not feasible".into(),
                );
                return Level::Doubt;
            }
        }
        self.doubt(
            events,
            t,
            SolverStatus::Solved,
            format!("A or B still not positive on [0, inf] after {CUT_ROUNDS} rounds of cuts; level treated as not feasible"),
        );
        Level::Doubt
    }

    /// The initial bracket `(lo, hi)` of `ln t` and the feasible solutions found on the
    /// way, or `None` when no level is feasible.  With a level `t_known` already reached by
    /// another candidate, the level just below it is tested first (infeasible: the other
    /// candidates are optimal to the tolerance).
    #[allow(clippy::type_complexity)]
    pub(super) fn bracket(
        &mut self,
        t_known: f64,
        tol: f64,
        events: &mut Vec<SolverEvent>,
    ) -> Option<(f64, f64, Vec<(f64, Vec<f64>)>)> {
        if !(t_known.is_finite() && t_known >= 1.0) {
            // No level known: up from t = 10 by factors of 100.
            let mut t = 10.0f64;
            let mut lo = 0.0;
            while t < 1e25 {
                if let Some(x) = self.try_level(t, events) {
                    return Some((lo, t.ln(), vec![(t.ln(), x)]));
                }
                lo = t.ln();
                t *= 100.0;
            }
            return None;
        }
        let probe = (t_known.ln() - tol).max(0.0);
        if let Some(x) = self.try_level(probe.exp(), events) {
            // Better levels exist.  The other candidates are usually close to the optimum,
            // so the search gallops down from the probe (steps of 2, 8, 32, … tolerances)
            // before bisecting, rather than bisecting all the way from `t = 1`.
            let mut hi = probe;
            let mut feasible = vec![(hi, x)];
            if self.set.thorough {
                // The reference route bisects from `t = 1`.
                return Some((0.0, hi, feasible));
            }
            let mut step = 2.0 * tol;
            while hi > tol {
                let at = (hi - step).max(0.0);
                match self.try_level(at.exp(), events) {
                    Some(x) => {
                        hi = at;
                        feasible.push((hi, x));
                        step *= 4.0;
                    }
                    None => return Some((at, hi, feasible)),
                }
            }
            return Some((0.0, hi, feasible));
        }
        // No better level exists on the grid, but the candidate that reached `t_known` may
        // dip between grid points and lose up to 0.03 decade to the certificate's repair;
        // this fitter's solution at that level has its no-dip cuts checked exactly, so it is
        // offered too.  When that candidate does dip, the exact optimum lies above
        // `t_known`: steps of 0.25, 2, 8, 32 tolerances (up to 0.06 decade), then bisection.
        // A doubt on the way up ends the climb: the levels above it are as hard for this
        // centre's LP (measured at orders 7–8 on 2000 data: every step after a doubt was
        // one too, each costing a retry with every row), and the other centres stand.
        let mut lo = t_known.ln();
        for step in [0.25, 2.0, 8.0, 32.0] {
            let at = t_known.ln() + step * tol;
            match self.level(at.exp(), events) {
                Level::Feasible(x) => return Some((lo, at, vec![(at, x)])),
                Level::Infeasible => lo = at,
                Level::Doubt | Level::CutBound => return None,
            }
        }
        None
    }

    /// Bisection on `ln t` from the bracket down to the tolerance; returns every feasible
    /// solution found (the bracket's included).
    pub(super) fn bisect(
        &mut self,
        mut lo: f64,
        mut hi: f64,
        tol: f64,
        mut feasible: Vec<(f64, Vec<f64>)>,
        events: &mut Vec<SolverEvent>,
    ) -> Vec<(f64, Vec<f64>)> {
        for _ in 0..40 {
            if hi - lo <= tol {
                break;
            }
            let mid = 0.5 * (lo + hi);
            match self.try_level(mid.exp(), events) {
                Some(x) => {
                    hi = mid;
                    feasible.push((mid, x));
                }
                None => lo = mid,
            }
        }
        feasible
    }
}

/// The working set `mask` of the rows keyed `keys` (group, grid point) carried onto rows
/// keyed by `group`, `point`: a row keeps its state when the old rows had one of the same
/// key (the `k`-th of a key to the `k`-th: both are sorted by key, stably, and cuts are
/// only appended); a row without a counterpart (a new cut) is in.
fn carry_mask(keys: &[(u32, usize)], mask: &[bool], group: &[u32], point: &[usize]) -> Vec<bool> {
    use std::collections::HashMap;
    let mut old: HashMap<(u32, usize), Vec<bool>> = HashMap::new();
    for (key, on) in keys.iter().zip(mask) {
        old.entry(*key).or_default().push(*on);
    }
    let mut seen: HashMap<(u32, usize), usize> = HashMap::new();
    group
        .iter()
        .zip(point)
        .map(|(g, p)| {
            let k = seen.entry((*g, *p)).or_default();
            let on = old.get(&(*g, *p)).and_then(|v| v.get(*k)).copied();
            *k += 1;
            on.unwrap_or(true)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::carry_mask;

    /// Rows keep their state by key and occurrence; new cut rows are in; rows that vanished
    /// (a level's relative rows) leave nothing behind.
    #[test]
    fn working_set_is_carried_by_key() {
        let m = usize::MAX;
        // Old rows: lower at points 0, 1; level at 0, 1; two B cuts; one relative level row.
        let keys = [(0, 0), (0, 1), (1, 0), (1, 1), (4, m), (4, m), (9, 1)];
        let mask = [true, false, false, true, false, true, true];
        // New rows: the same fixed rows, a third B cut appended, a new A-floor cut, no
        // relative row.
        let group = [0, 0, 1, 1, 4, 4, 4, 5];
        let point = [0, 1, 0, 1, m, m, m, m];
        let got = carry_mask(&keys, &mask, &group, &point);
        assert_eq!(
            got,
            vec![true, false, false, true, false, true, true, true],
            "{got:?}"
        );
    }
}
