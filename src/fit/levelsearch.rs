//! The minimax level search of one order in the partial-fraction basis of
//! [`super::basis`]: bracket the level `t` (from the previous order's when known), then a
//! safeguarded ITP search on the max-slack `s(ln t)` of [`super::problem::max_slack`].  The
//! max-slack solutions are centred: they keep away from the floor, so the poles and zeros
//! keep away from the axis (a Dinkelbach iteration, tried, converged to boundary solutions
//! with poles on the axis).  When no level is feasible, [`blocking_families`] names the
//! constraint family that blocks it (GitHub issue 11, defect 5).

use super::basis::{GridPoint, PointKind};
use super::problem::{max_slack, SolverEvent, SolverStatus};
use super::provenance::EventKind;
use super::FitSettings;

/// The lowest feasible level found, with its numerator and denominator coefficients
/// `(t, a, b)`, or `None` when no level up to `t = 1e24` is feasible (an event then says
/// which constraint family blocks it).  `phi` are the basis rows at the grid, `init` the
/// initial working-set points, `mask` the working set carried between calls.
#[allow(clippy::too_many_arguments)]
pub(crate) fn minimax_level(
    phi: &[Vec<f64>],
    grid: &[GridPoint],
    init: &[bool],
    mask: &mut Vec<bool>,
    prev_t: Option<f64>,
    n: usize,
    set: &FitSettings,
    events: &mut Vec<SolverEvent>,
    lp_solves: &mut usize,
) -> Option<(f64, Vec<f64>, Vec<f64>)> {
    let event = |stage: String, status: SolverStatus, kind: EventKind, action: &str| SolverEvent {
        order: n,
        stage,
        status,
        kind,
        action: action.into(),
    };
    let solve = |t: f64,
                 stage: &str,
                 events: &mut Vec<SolverEvent>,
                 lp: &mut usize,
                 mask: &mut Vec<bool>| {
        let (st, s, a, b, rounds) =
            max_slack(phi, grid, t, init, mask, set.max_solver_iter, set.thorough);
        *lp += rounds;
        if st != SolverStatus::Solved {
            let (kind, action) = if st.has_solution() {
                (
                    EventKind::ReducedAccuracyUsed,
                    "used the reduced-accuracy solution; verified below",
                )
            } else {
                (
                    EventKind::LevelNotFeasible,
                    "treated the level as not feasible",
                )
            };
            events.push(event(format!("{stage} t={t:.4e}"), st, kind, action));
        }
        let s = if st.has_solution() {
            s
        } else {
            f64::NEG_INFINITY
        };
        (s, a, b)
    };
    let tol = 2.0 * (1.0 + set.bisection_tol).ln();
    let mut lo = 0.0f64; // ln t ≥ 0: upper = lower at the data
    let mut s_lo = None::<f64>;
    let mut s_hi = 0.0;
    let mut best: Option<(f64, Vec<f64>, Vec<f64>)> = None;
    let mut t_hi = prev_t.map_or(10.0, |t| t.max(1.0) * (1.0 + 1e-9));
    for _ in 0..12 {
        let (s, a, b) = solve(t_hi, "minimax bracket", events, lp_solves, mask);
        if s >= 0.0 {
            best = Some((t_hi, a, b));
            s_hi = s;
            break;
        }
        lo = t_hi.ln();
        s_lo = s.is_finite().then_some(s);
        t_hi *= 100.0;
    }
    if let Some((t0, a0, b0)) = &best {
        // ITP search (interpolate, truncate, project; Oliveira & Takahashi 2020) on the
        // max-slack s(ln t), never more than one step beyond bisection.  The interpolation
        // is Illinois false position, used only while the slack at the feasible end is
        // well below its cap s ≤ 1: at higher orders s(ln t) is close to a step (a feasible
        // level's slack is limited only by the cap) and false position crawled from the
        // infeasible end, so those steps are bisections.  A feasible (A, B) at level t
        // also meets every bound at its own level max A/(U·B) ≤ t: that level is feasible
        // too and tightens the bracket.
        let mut hi = t0.ln().min(achieved_level(phi, grid, a0, b0).ln());
        let eps = 0.5 * tol;
        let w0 = hi - lo;
        let n_max = (w0 / tol).log2().ceil().max(0.0) + 1.0;
        let k1 = 0.2 / w0.max(tol);
        let mut j = 0.0;
        let mut side = 0i8; // Illinois: halve the value kept at a repeated end
        let mut hi_raw = s_hi;
        while hi - lo > tol {
            let w = hi - lo;
            let half = 0.5 * (lo + hi);
            let r = (eps * (n_max - j).exp2() - 0.5 * w).max(0.0);
            j += 1.0;
            let mid = match s_lo {
                Some(sl) if s_hi > sl && hi_raw < 0.9 => {
                    // Aim a little above the estimate so that a good one closes the bracket.
                    let xf = (lo - sl * w / (s_hi - sl) + 0.3 * tol).min(hi);
                    let sigma = (half - xf).signum();
                    let delta = k1 * w * w;
                    let xt = if delta <= (half - xf).abs() {
                        xf + sigma * delta
                    } else {
                        half
                    };
                    let x = if (xt - half).abs() <= r {
                        xt
                    } else {
                        half - sigma * r
                    };
                    x.clamp(lo + 1e-3 * w, hi - 1e-3 * w)
                }
                _ => half,
            };
            let t = mid.exp();
            let (s, a, b) = solve(t, "minimax", events, lp_solves, mask);
            if s >= 0.0 {
                hi = mid.min(achieved_level(phi, grid, &a, &b).ln());
                s_hi = s;
                hi_raw = s;
                best = Some((t, a, b));
                if side == 1 {
                    s_lo = s_lo.map(|v| 0.5 * v);
                }
                side = 1;
            } else {
                lo = mid;
                s_lo = s.is_finite().then_some(s);
                if side == -1 {
                    s_hi *= 0.5;
                }
                side = -1;
            }
        }
    } else {
        let blocking = blocking_families(phi, grid, init, set.max_solver_iter);
        *lp_solves += 4;
        events.push(event(
            "minimax".into(),
            SolverStatus::PrimalInfeasible,
            EventKind::NoFeasibleLevel,
            &format!(
                "no feasible level up to t = 1e24; {blocking}; other candidates tried (the constant r among them)"
            ),
        ));
    }

    best
}

/// The level `max A/(U·B)` over the data with a bound reached by `(A, B)`
/// (`+∞` when `B ≤ 0` somewhere, which a feasible max-slack solution never has).
fn achieved_level(phi: &[Vec<f64>], grid: &[GridPoint], a: &[f64], b: &[f64]) -> f64 {
    let dot = |r: &[f64], c: &[f64]| r.iter().zip(c).map(|(x, y)| x * y).sum::<f64>();
    let mut t = 0.0f64;
    for (ph, g) in phi.iter().zip(grid) {
        if let Some(u) = g.upper.filter(|_| g.kind == PointKind::Datum) {
            let bv = dot(ph, b);
            if !(bv > 0.0) {
                return f64::INFINITY;
            }
            t = t.max(dot(ph, a) / (u * bv));
        }
    }
    if t.is_nan() {
        f64::INFINITY
    } else {
        t
    }
}

/// Drops one constraint family from a grid point.
type Relax = fn(&mut GridPoint);

/// When no level is feasible: which constraint family blocks it.  Each family is dropped in
/// turn and the level `t = 1e24` tried again; the families whose removal makes it feasible
/// are named (the data lower bounds, the no-dip bounds between data, the floor, A1).
fn blocking_families(phi: &[Vec<f64>], grid: &[GridPoint], init: &[bool], max_iter: u32) -> String {
    let families: [(&str, Relax); 4] = [
        ("the lower bounds at the data", |g| {
            if g.kind == PointKind::Datum {
                g.lower = 0.0;
            }
        }),
        ("the no-dip bounds between data", |g| {
            if g.kind == PointKind::Band {
                g.lower = 0.0;
            }
        }),
        ("the floor outside the band and at 0 and infinity", |g| {
            if matches!(g.kind, PointKind::Outside | PointKind::Infinity) {
                g.lower = 0.0;
            }
        }),
        ("A1 (|r| < sigma_min(M))", |g| g.a1 = None),
    ];
    let mut found = Vec::new();
    for (name, drop) in families {
        let relaxed: Vec<GridPoint> = grid
            .iter()
            .map(|g| {
                let mut g = *g;
                drop(&mut g);
                g
            })
            .collect();
        let mut mask = Vec::new();
        let (st, s, _, _, _) = max_slack(phi, &relaxed, 1e24, init, &mut mask, max_iter, false);
        if st.has_solution() && s >= 0.0 {
            found.push(name);
        }
    }
    if found.is_empty() {
        "no single constraint family blocks it alone (dropping any one of data bounds, no-dip, floor, A1 does not help): the LP failed numerically or several families conflict".into()
    } else {
        format!("blocked by {} (feasible without it)", found.join(" / "))
    }
}
