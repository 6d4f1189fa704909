//! One order of the fit: the minimax bisection with free poles and zeros, the area polish
//! with fixed poles, and the choice among candidates.
//!
//! Candidates for order `N`:
//! 1. the minimax fit (bisection on `t`, [`super::problem::max_slack`]);
//! 2. the area polish of each pole set: the minimax poles, the previous order's poles plus
//!    one real pole, and the reference poles;
//! 3. the previous order's `r` itself (an order-`N−1` unit is an order-`N` unit with a
//!    cancelling pole-zero pair), so conservatism can never increase with the order.
//!
//! A candidate that fails (solver status, root on the axis) is recorded and skipped; the
//! run goes on with the others.

use super::basis::{reference_poles, GridPoint, PointKind};
use super::levelsearch::minimax_level;
use super::polyfit;
use super::problem::{area_fixed_poles, basis_rows, initial_points, SolverEvent, SolverStatus};
use super::spectral::{stable_roots, RootKind, Zpk};
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
    pub origin: String,
    /// Smallest `|r|²/lower` over the grid (≥ 1 when feasible).
    pub coverage: f64,
    /// Smallest `α/|r|²` over the grid (≥ 1 when A1 holds).
    pub a1_ratio: f64,
}

impl Prepared {
    pub fn score(&self, zpk: Zpk, origin: &str) -> Scored {
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
            origin: origin.into(),
            coverage,
            a1_ratio,
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

/// Result of one order: the candidates (best first) and the solver events.
pub(crate) struct OrderFit {
    pub ranked: Vec<Scored>,
    pub events: Vec<SolverEvent>,
    pub lp_solves: usize,
}

/// Fits order `n` given the previous order's chosen candidate.
pub(crate) fn fit_order(
    prep: &Prepared,
    n: usize,
    prev: Option<&Scored>,
    set: &FitSettings,
    masks: &mut (Vec<bool>, Vec<bool>),
) -> OrderFit {
    let q = reference_poles(n, prep.band.0, prep.band.1);
    let mut events = Vec::new();
    let mut lp_solves = 0;
    let mut cands: Vec<Scored> = Vec::new();
    let event = |stage: String, status: SolverStatus, action: &str| SolverEvent {
        order: n,
        stage,
        status,
        action: action.into(),
    };

    // 1. Minimax in the partial-fraction basis ([`super::levelsearch`]).
    let phi = basis_rows(&q, &prep.grid);
    let init = initial_points(&prep.grid, 40);
    // Working sets (per row) carried from order to order: the row layout depends only on
    // the grid, and the rows that bind at order N mostly bind at order N+1.
    let (mut mask, mut area_mask) = std::mem::take(masks);
    let best = minimax_level(
        &phi,
        &prep.grid,
        &init,
        &mut mask,
        prev.map(|p| p.t),
        n,
        set,
        &mut events,
        &mut lp_solves,
    );

    let mut pole_sets: Vec<(String, Vec<Complex64>)> = Vec::new();
    if let Some((t, a, b)) = &best {
        let poles = stable_roots(&q, b, RootKind::Pole, set.axis_tol, set.root_iter_cap);
        let zeros = stable_roots(&q, a, RootKind::Zero, set.axis_tol, set.root_iter_cap);
        match (poles, zeros) {
            (Ok(p), Ok(z)) => {
                let gain = (a[0] / b[0]).sqrt();
                cands.push(prep.score(
                    Zpk {
                        gain,
                        zeros: z,
                        poles: p.clone(),
                    },
                    &format!("minimax (t = {t:.4e})"),
                ));
                pole_sets.push(("minimax poles".into(), p));
            }
            (Err(e), _) | (_, Err(e)) => {
                events.push(event(
                    "minimax spectral factorization".into(),
                    SolverStatus::Solved,
                    &format!("{e}; candidate discarded, others tried"),
                ));
                if let Ok(p) = stable_roots(&q, b, RootKind::Pole, set.axis_tol, set.root_iter_cap)
                {
                    pole_sets.push(("minimax poles".into(), p));
                }
            }
        }
    }
    if let Some(p) = prev {
        let mut poles = p.zpk.poles.clone();
        if n > poles.len() {
            poles.push(Complex64::new(-1.0, 0.0));
        }
        if poles.len() == n {
            pole_sets.push(("previous poles + one".into(), poles));
        }
    }
    pole_sets.push((
        "reference poles".into(),
        q.iter().map(|v| Complex64::new(-v, 0.0)).collect(),
    ));

    // 2. Area polish with fixed poles.
    let t_best = cands
        .iter()
        .map(|c| c.t)
        .chain(prev.map(|p| p.t))
        .fold(f64::INFINITY, f64::min);
    let t_cap = if t_best.is_finite() {
        match set.objective {
            Objective::Minimax => t_best * (1.0 + set.bisection_tol).powi(2),
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
        let kp = kappa(&prep.grid, &q, &poles);
        let (st, a, _, rounds) = area_fixed_poles(
            &phi,
            &prep.grid,
            &kp,
            &weights,
            t_cap,
            &init,
            &mut area_mask,
            set.max_solver_iter,
        );
        lp_solves += rounds;
        if st != SolverStatus::Solved {
            events.push(event(
                format!("area with {name}"),
                st,
                match st {
                    s if s.has_solution() => "used the reduced-accuracy solution; verified below",
                    SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                        "these poles cannot meet the bounds at this level; candidate skipped, others tried"
                    }
                    _ => "candidate discarded, others tried",
                },
            ));
        }
        if !st.has_solution() {
            continue;
        }
        match stable_roots(&q, &a, RootKind::Zero, set.axis_tol, set.root_iter_cap) {
            Ok(z) => cands.push(prep.score(
                Zpk {
                    gain: a[0].sqrt(),
                    zeros: z,
                    poles,
                },
                &format!("area polish, {name}"),
            )),
            Err(e) => events.push(event(
                format!("area with {name}: spectral factorization"),
                st,
                &format!("{e}; candidate discarded, others tried"),
            )),
        }
    }
    if let Some(p) = prev {
        let mut c = p.clone();
        c.origin = format!("order {} carried over", p.zpk.order());
        cands.push(c);
    }
    // The constant r at the largest lower bound meets every lower bound: a candidate at
    // every order, so a level search that fails numerically never turns a feasible order
    // into "infeasible" (GitHub issue 11, defect 5).
    let c2 = prep.grid.iter().map(|g| g.lower).fold(0.0f64, f64::max);
    if c2 > 0.0 && c2.is_finite() {
        cands.push(prep.score(
            Zpk {
                gain: c2.sqrt(),
                zeros: Vec::new(),
                poles: Vec::new(),
            },
            "constant at the largest lower bound",
        ));
    }

    // 3. The global minimax over the full numerator and denominator (quasi-convex, see
    //    [`super::polyfit`]), searched only below the best level reached so far.
    let ok = |c: &Scored| c.coverage >= 1.0 - 1e-6 && c.a1_ratio >= 1.0 - 1e-6;
    let t_known = cands
        .iter()
        .filter(|c| ok(c))
        .map(|c| c.t)
        .fold(f64::INFINITY, f64::min);
    if let Some(c) = polyfit::minimax(prep, n, t_known, set, &mut events, &mut lp_solves) {
        cands.push(c);
    }

    // 4. Rank: feasible (to the LP accuracy) first; never worse than the previous order.
    let guard = |c: &Scored| match prev {
        Some(p) => c.mean_log <= p.mean_log + 1e-12 && c.max_log <= p.max_log + 1e-12,
        None => true,
    };
    let max_tol = (1.0 + set.bisection_tol).log10();
    let best_max = cands
        .iter()
        .filter(|c| ok(c) && guard(c))
        .map(|c| c.max_log)
        .fold(f64::INFINITY, f64::min);
    let key = |c: &Scored| -> (u8, f64) {
        let class = if ok(c) && guard(c) {
            0
        } else if ok(c) {
            1
        } else {
            2
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
    // Keep only orders that are actually n (the carried-over one has fewer poles): pad it.
    for c in cands.iter_mut() {
        while c.zpk.poles.len() < n {
            c.zpk.poles.push(Complex64::new(-1.0, 0.0));
            c.zpk.zeros.push(Complex64::new(-1.0, 0.0));
        }
    }
    *masks = (mask, area_mask);
    OrderFit {
        ranked: cands,
        events,
        lp_solves,
    }
}
