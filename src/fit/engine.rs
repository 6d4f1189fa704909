//! One order of the fit: the minimax bisection with free poles and zeros, the area polish
//! with fixed poles, and the choice among candidates.
//!
//! Candidates for order `N`:
//! 1. the minimax fit (bisection on `t`, [`super::problem::max_slack`]);
//! 2. the area polish of each pole set: the minimax poles, the previous order's poles plus
//!    one real pole, and the reference poles;
//! 3. the previous order's `r` itself (an order-`N−1` unit is an order-`N` unit with a
//!    cancelling pole-zero pair), so every order has a candidate that keeps the objective's
//!    promise about the orders ([`admits`]).
//!
//! A candidate that fails (solver status, root on the axis) is recorded and skipped; the
//! run goes on with the others.

use super::basis::{reference_poles, GridPoint, PointKind};
use super::levelsearch::minimax_level;
use super::polyfit;
use super::problem::{area_fixed_poles, basis_rows, SolverEvent, SolverStatus};
use super::provenance::{EventKind, Origin, PoleSet};
use super::spectral::{stable_roots, RootKind, Zpk};
use super::working_set::initial_points;
use super::{FitSettings, Objective};
use num_complex::Complex64;

/// The scaled problem shared by all orders.
pub(crate) struct Prepared {
    /// Scaled data frequencies.
    pub w: Vec<f64>,
    /// Scaled `r_min` (0: no bound).
    pub rmin: Vec<f64>,
    /// Log-frequency weights of the data (sum 1 over data with a bound).
    pub weights: Vec<f64>,
    /// Constraint points.
    pub grid: Vec<GridPoint>,
    /// Lowest and highest scaled data frequency.
    pub band: (f64, f64),
}

/// A candidate, scaled, with its figures on the data.
#[derive(Debug, Clone)]
pub(crate) struct Scored {
    pub zpk: Zpk,
    /// Mean of `log10(|r|/r_min)` over the data with a bound.
    pub mean_log: f64,
    /// Max of the same.
    pub max_log: f64,
    /// Area objective `Σ w_i |r|²/r_min²`.
    pub area: f64,
    /// `max |r|²/U` over the data (the minimax level reached).
    pub t: f64,
    /// Where the candidate came from.
    pub origin: Origin,
    /// Smallest `|r|²/lower` over the grid (≥ 1 when feasible).
    pub coverage: f64,
    /// Smallest `α/|r|²` over the grid (≥ 1 when A1 holds).
    pub a1_ratio: f64,
    /// The polynomial candidate's attempt (disk-map centre, cut floor) that found it.
    pub attempt: Option<(f64, f64)>,
}

impl Prepared {
    pub fn score(&self, zpk: Zpk, origin: Origin) -> Scored {
        let (mut sum, mut cnt, mut max, mut area) = (0.0, 0.0, f64::NEG_INFINITY, 0.0);
        for i in 0..self.w.len() {
            if self.rmin[i] > 0.0 {
                let m = zpk.mag(self.w[i]);
                let l = (m / self.rmin[i]).log10();
                sum += l;
                cnt += 1.0;
                max = max.max(l);
                area += self.weights[i] * (m / self.rmin[i]).powi(2);
            }
        }
        let (mut t, mut coverage, mut a1_ratio) = (0.0f64, f64::INFINITY, f64::INFINITY);
        for p in &self.grid {
            let m2 = zpk.mag(p.w).powi(2);
            if let Some(u) = p.upper.filter(|_| p.kind == PointKind::Datum) {
                t = t.max(m2 / u);
            }
            if p.lower > 0.0 {
                coverage = coverage.min(m2 / p.lower);
            }
            if let Some(a) = p.a1 {
                a1_ratio = a1_ratio.min(a / m2);
            }
        }
        Scored {
            zpk,
            mean_log: if cnt > 0.0 { sum / cnt } else { 0.0 },
            max_log: max,
            area,
            t,
            origin,
            coverage,
            a1_ratio,
            attempt: None,
        }
    }
}

/// `D(x)/B(x)` at every grid point for fixed poles `p` (scaled) and reference poles `q`.
fn kappa(grid: &[GridPoint], q: &[f64], poles: &[Complex64]) -> Vec<f64> {
    grid.iter()
        .map(|g| {
            if g.x.is_infinite() {
                return 1.0;
            }
            let s = Complex64::new(0.0, g.w);
            let mut k = 1.0;
            for j in 0..q.len().max(poles.len()) {
                if let Some(qj) = q.get(j) {
                    k *= g.x + qj * qj;
                }
                if let Some(pj) = poles.get(j) {
                    k /= (s - pj).norm_sqr();
                }
            }
            k
        })
        .collect()
}

/// The bisection tolerance as decades of `max |r|/r_min`: `log10(1 + bisection_tol)`
/// (0.00087 by default).  Two maxima closer than this are the same level to the search.
pub(crate) fn max_tolerance(set: &FitSettings) -> f64 {
    (1.0 + set.bisection_tol).log10()
}

/// Whether candidate `c` may follow the previous order's `p` — the promise of the objective
/// ([`Objective`]) about order `n` against order `n − 1`:
/// - minimax: the max never rises (`c.max ≤ p.max`), and the mean rises only where the max
///   falls by more than the bisection tolerance `max_tol` (then the max is the better fit
///   and the mean, the tie-break, gives way);
/// - area: neither the max nor the mean rises.
///
/// Both within `10⁻¹²` (rounding of the figures).  The previous order's `r` itself (carried
/// over) is always admitted, so every order has an admitted candidate.
pub(crate) fn admits(objective: Objective, max_tol: f64, p: &Scored, c: &Scored) -> bool {
    let max_ok = c.max_log <= p.max_log + 1e-12;
    let mean_ok = c.mean_log <= p.mean_log + 1e-12;
    match objective {
        Objective::Minimax => max_ok && (mean_ok || c.max_log < p.max_log - max_tol),
        Objective::Area => max_ok && mean_ok,
    }
}

/// Result of one order: the candidates (best first) and the solver events.
pub(crate) struct OrderFit {
    pub ranked: Vec<Scored>,
    pub events: Vec<SolverEvent>,
    pub lp_solves: usize,
}

/// Fits order `n` given the previous order's chosen candidate: the steps of the module
/// doc, in order.  `masks` are the working sets of the level search and of the area polish,
/// carried from order to order (the row layout depends only on the grid, and the rows that
/// bind at order N mostly bind at order N+1).
pub(crate) fn fit_order(
    prep: &Prepared,
    n: usize,
    prev: Option<&Scored>,
    set: &FitSettings,
    masks: &mut (Vec<bool>, Vec<bool>),
) -> OrderFit {
    let mut o = OrderSearch::new(prep, n, prev, set);
    let pole_sets = o.partial_fraction_minimax(&mut masks.0);
    o.area_polish(pole_sets, &mut masks.1);
    o.fallbacks();
    o.global_minimax();
    OrderFit {
        ranked: rank(o.cands, prev, set, n, set.objective),
        events: o.events,
        lp_solves: o.lp_solves,
    }
}

/// The state of one order's search: its inputs, the candidates so far, the events.
struct OrderSearch<'a> {
    prep: &'a Prepared,
    n: usize,
    prev: Option<&'a Scored>,
    set: &'a FitSettings,
    /// Reference poles of the partial-fraction basis.
    q: Vec<f64>,
    /// Basis rows at the grid.
    phi: Vec<Vec<f64>>,
    /// Initial working-set points.
    init: Vec<bool>,
    cands: Vec<Scored>,
    events: Vec<SolverEvent>,
    lp_solves: usize,
}

/// Feasible to the LP accuracy on the grid.
fn feasible(c: &Scored) -> bool {
    c.coverage >= 1.0 - 1e-6 && c.a1_ratio >= 1.0 - 1e-6
}

impl<'a> OrderSearch<'a> {
    fn new(prep: &'a Prepared, n: usize, prev: Option<&'a Scored>, set: &'a FitSettings) -> Self {
        let q = reference_poles(n, prep.band.0, prep.band.1);
        let phi = basis_rows(&q, &prep.grid);
        Self {
            prep,
            n,
            prev,
            set,
            q,
            phi,
            init: initial_points(&prep.grid, 40),
            cands: Vec::new(),
            events: Vec::new(),
            lp_solves: 0,
        }
    }

    fn event(&mut self, stage: String, status: SolverStatus, kind: EventKind, action: &str) {
        self.events.push(SolverEvent {
            order: self.n,
            stage,
            status,
            kind,
            action: action.into(),
        });
    }

    /// Step 1: the minimax level search in the partial-fraction basis
    /// ([`super::levelsearch`]); its fit is a candidate.  Returns the pole sets for the
    /// area polish: the minimax poles, the previous order's plus one, the reference poles.
    fn partial_fraction_minimax(&mut self, mask: &mut Vec<bool>) -> Vec<(PoleSet, Vec<Complex64>)> {
        let (set, q) = (self.set, &self.q);
        let best = minimax_level(
            &self.phi,
            &self.prep.grid,
            &self.init,
            mask,
            self.prev.map(|p| p.t),
            self.n,
            set,
            &mut self.events,
            &mut self.lp_solves,
        );
        let mut pole_sets: Vec<(PoleSet, Vec<Complex64>)> = Vec::new();
        if let Some((t, a, b)) = &best {
            let poles = stable_roots(q, b, RootKind::Pole, set.axis_tol, set.root_iter_cap);
            let zeros = stable_roots(q, a, RootKind::Zero, set.axis_tol, set.root_iter_cap);
            match (poles, zeros) {
                (Ok(p), Ok(z)) => {
                    let gain = (a[0] / b[0]).sqrt();
                    let zpk = Zpk {
                        gain,
                        zeros: z,
                        poles: p.clone(),
                    };
                    self.cands
                        .push(self.prep.score(zpk, Origin::Minimax { t: *t }));
                    pole_sets.push((PoleSet::Minimax, p));
                }
                (poles, zeros) => {
                    let e = match (&poles, &zeros) {
                        (Err(e), _) | (_, Err(e)) => e.to_string(),
                        _ => String::new(),
                    };
                    self.event(
                        "minimax spectral factorization".into(),
                        SolverStatus::Solved,
                        EventKind::CandidateDiscarded,
                        &format!("{e}; candidate discarded, others tried"),
                    );
                    // The zeros failed, the poles did not: the area polish can still use them.
                    if let Ok(p) = poles {
                        pole_sets.push((PoleSet::Minimax, p));
                    }
                }
            }
        }
        if let Some(p) = self.prev {
            let mut poles = p.zpk.poles.clone();
            if self.n > poles.len() {
                poles.push(Complex64::new(-1.0, 0.0));
            }
            if poles.len() == self.n {
                pole_sets.push((PoleSet::PreviousPlusOne, poles));
            }
        }
        pole_sets.push((
            PoleSet::Reference,
            self.q.iter().map(|v| Complex64::new(-v, 0.0)).collect(),
        ));
        pole_sets
    }

    /// Step 2: the area objective with each pole set fixed, the level capped at the best
    /// reached so far (minimax) or `area_slack` above it (area).
    fn area_polish(&mut self, pole_sets: Vec<(PoleSet, Vec<Complex64>)>, mask: &mut Vec<bool>) {
        let (prep, set) = (self.prep, self.set);
        let t_best = self
            .cands
            .iter()
            .map(|c| c.t)
            .chain(self.prev.map(|p| p.t))
            .fold(f64::INFINITY, f64::min);
        let t_cap = if t_best.is_finite() {
            match set.objective {
                Objective::Minimax => t_best * set.level_resolution(),
                Objective::Area => t_best * set.area_slack * set.area_slack,
            }
        } else {
            1e24
        };
        let weights: Vec<f64> = prep
            .grid
            .iter()
            .map(|g| match (g.kind, g.datum) {
                (PointKind::Datum, Some(i)) if prep.rmin[i] > 0.0 => {
                    prep.weights[i] / (prep.rmin[i] * prep.rmin[i])
                }
                _ => 0.0,
            })
            .collect();
        for (name, poles) in pole_sets {
            let kp = kappa(&prep.grid, &self.q, &poles);
            let (st, a, _, rounds) = area_fixed_poles(
                &self.phi,
                &prep.grid,
                &kp,
                &weights,
                t_cap,
                &self.init,
                mask,
                set.max_solver_iter,
                set.thorough,
            );
            self.lp_solves += rounds;
            if st != SolverStatus::Solved {
                let (kind, action) = match st {
                    s if s.has_solution() => (
                        EventKind::ReducedAccuracyUsed,
                        "used the reduced-accuracy solution; verified below",
                    ),
                    SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => (
                        EventKind::CandidateDiscarded,
                        "these poles cannot meet the bounds at this level; candidate skipped, others tried",
                    ),
                    _ => (
                        EventKind::CandidateDiscarded,
                        "candidate discarded, others tried",
                    ),
                };
                self.event(format!("area with {name}"), st, kind, action);
            }
            if !st.has_solution() {
                continue;
            }
            match stable_roots(&self.q, &a, RootKind::Zero, set.axis_tol, set.root_iter_cap) {
                Ok(z) => {
                    let zpk = Zpk {
                        gain: a[0].sqrt(),
                        zeros: z,
                        poles,
                    };
                    let c = prep.score(zpk, Origin::AreaPolish { poles: name });
                    self.cands.push(c);
                }
                Err(e) => self.event(
                    format!("area with {name}: spectral factorization"),
                    st,
                    EventKind::CandidateDiscarded,
                    &format!("{e}; candidate discarded, others tried"),
                ),
            }
        }
    }

    /// Step 3: the candidates that need no LP: the previous order's `r` (an order-`N−1`
    /// unit is an order-`N` unit with a cancelling pole-zero pair) and the constant `r` at
    /// the largest lower bound, which meets every lower bound, so a level search that fails
    /// numerically never turns a feasible order into "infeasible" (GitHub issue 11, defect 5).
    fn fallbacks(&mut self) {
        if let Some(p) = self.prev {
            let mut c = p.clone();
            c.origin = Origin::CarriedOver {
                from_order: p.zpk.order(),
            };
            self.cands.push(c);
        }
        let c2 = self
            .prep
            .grid
            .iter()
            .map(|g| g.lower)
            .fold(0.0f64, f64::max);
        if c2 > 0.0 && c2.is_finite() {
            let zpk = Zpk {
                gain: c2.sqrt(),
                zeros: Vec::new(),
                poles: Vec::new(),
            };
            self.cands.push(self.prep.score(zpk, Origin::Constant));
        }
    }

    /// Step 4: the global minimax over the full numerator and denominator (quasi-convex,
    /// see [`super::polyfit`]), searched only below the best level reached so far.
    fn global_minimax(&mut self) {
        let t_known = self
            .cands
            .iter()
            .filter(|c| feasible(c))
            .map(|c| c.t)
            .fold(f64::INFINITY, f64::min);
        let (prep, n, set) = (self.prep, self.n, self.set);
        // The attempt that found the previous order's `r` first (a measurement switch).
        let hint = self
            .prev
            .and_then(|p| p.attempt)
            .filter(|_| super::experiment::switches().previous_centre_first);
        let (events, lps) = (&mut self.events, &mut self.lp_solves);
        if let Some(c) = polyfit::minimax(prep, n, t_known, hint, set, events, lps) {
            self.cands.push(c);
        }
    }
}

/// Step 5: ranks candidates, feasible first and admitted after the previous order `prev`
/// under the promise of `guard` ([`admits`]); among those within the bisection tolerance of
/// the best maximum, the smallest mean (minimax) or area (`set.objective`).  Every candidate
/// is padded to order `n` with cancelling pole-zero pairs.
pub(crate) fn rank(
    mut cands: Vec<Scored>,
    prev: Option<&Scored>,
    set: &FitSettings,
    n: usize,
    guard: Objective,
) -> Vec<Scored> {
    let max_tol = max_tolerance(set);
    let guard = |c: &Scored| prev.is_none_or(|p| admits(guard, max_tol, p, c));
    let best_max = cands
        .iter()
        .filter(|c| feasible(c) && guard(c))
        .map(|c| c.max_log)
        .fold(f64::INFINITY, f64::min);
    let key = |c: &Scored| -> (u8, f64) {
        let class = match (feasible(c), guard(c)) {
            (true, true) => 0,
            (true, false) => 1,
            _ => 2,
        };
        let v = match set.objective {
            Objective::Minimax if c.max_log <= best_max + max_tol => c.mean_log,
            Objective::Minimax => 1e6 + c.max_log,
            Objective::Area => c.area,
        };
        (class, v)
    };
    cands.sort_by(|a, b| {
        let (ka, kb) = (key(a), key(b));
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
    for c in cands.iter_mut() {
        while c.zpk.poles.len() < n {
            c.zpk.poles.push(Complex64::new(-1.0, 0.0));
            c.zpk.zeros.push(Complex64::new(-1.0, 0.0));
        }
    }
    cands
}
