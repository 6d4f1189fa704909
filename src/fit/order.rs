//! Order selection: fit orders `0..=n_max` in one chained sweep (each order starts from the
//! previous one, so conservatism never increases), tabulate order against conservatism
//! (mean and max of `log10(|r|/r_min)` over the data), and pick the smallest order whose
//! mean and max are both within `auto_tolerance` of the best in the table.

use super::context::prepare;
use super::engine::{fit_order, Scored};
use super::{A1Fn, EventKind, FitError, FitOptions, FitProgress, FitResult, FitSettings};
use crate::consistency::Envelope;
use serde::Serialize;

/// One row of the order table.
#[derive(Debug, Clone, Serialize)]
pub struct OrderRow {
    /// Order.
    pub order: usize,
    /// Mean `log10(|r|/r_min)` over the data (certified `r`); `NaN` when the order failed.
    pub mean_log10: f64,
    /// Max `log10(|r|/r_min)` over the data.
    pub max_log10: f64,
    /// `ok`, or why the order failed.
    pub status: String,
    /// Solver events of this order (solves short of `Solved`, discarded candidates).
    pub solver_events: usize,
    /// LPs solved for this order (every working-set round counts as one).
    pub lp_solves: usize,
}

/// An order that gains less than this (decades of max `log10 |r|/r_min`) on the order below
/// it is refit by the thorough route when its fast fit left a level undecided: about two
/// bisection tolerances.
const STALL_LOG10: f64 = 0.0017;

/// Whether an order whose fast fit reached `best` (max `log10 |r|/r_min`), over an order below
/// that reached `prev_max`, must be refit by the thorough route: only a stall (no gain of
/// [`STALL_LOG10`]) with a level left undecided qualifies, and never an order below already
/// within [`STALL_LOG10`] of its envelope (every certified `r` has max ≥ 0, so no route can
/// gain more there; the paper example reaches 0.00000 at order 3 and orders 4–8 were each
/// refit for nothing).
fn stall_needs_recheck(events: &[super::SolverEvent], best: f64, prev_max: f64) -> bool {
    let undecided = events.iter().any(|e| {
        matches!(
            e.kind,
            EventKind::LevelNotFeasible | EventKind::DoubtBudgetSpent | EventKind::NoFeasibleLevel
        )
    });
    undecided && best >= prev_max - STALL_LOG10 && prev_max > STALL_LOG10
}

/// One more order can never do worse than the order below it (its set of candidates
/// contains the lower order's), so an order that does not improve is suspect — but only
/// when its fast fit left a level undecided ([`EventKind::LevelNotFeasible`], a spent doubt
/// budget, no feasible level): every other verdict of the fast route is proved (a solve
/// short of `Solved` is solved again with refinement before its status counts, a level is
/// feasible only when its solution reaches it at the data, and the polynomial candidate's
/// factors must reach its level).  A stall without a doubt is the envelope's own floor (the
/// 2000-point jagged envelope stalls at 0.300 decade from order 3 on: neighbouring data differ
/// by up to a factor 2, and every order must cover both).  Such an order is refit with
/// [`FitSettings::thorough`] and the better of the two kept (the LPs of both are counted).
fn recheck_stall(
    prep: &super::engine::Prepared,
    n: usize,
    prev: Option<&Scored>,
    settings: &FitSettings,
    of: super::engine::OrderFit,
) -> super::engine::OrderFit {
    let best = |f: &super::engine::OrderFit| {
        f.ranked
            .iter()
            .map(|s| s.max_log)
            .fold(f64::INFINITY, f64::min)
    };
    let Some(p) = prev else { return of };
    if settings.thorough || !stall_needs_recheck(&of.events, best(&of), p.max_log) {
        return of;
    }
    let thorough = FitSettings {
        thorough: true,
        ..settings.clone()
    };
    let mut masks = (Vec::new(), Vec::new());
    let mut again = fit_order(prep, n, prev, &thorough, &mut masks);
    let lp_solves = of.lp_solves + again.lp_solves;
    let mut events = of.events.clone();
    events.append(&mut again.events);
    let ranked = if best(&again) < best(&of) {
        again.ranked
    } else {
        of.ranked
    };
    super::engine::OrderFit {
        ranked,
        events,
        lp_solves,
    }
}

/// Sweeps orders `0..=n_max`, returns the chosen certified fit and the table;
/// `options.progress` hears of each order before it is fitted.
pub fn fit_auto(
    env: &Envelope,
    a1: Option<A1Fn<'_>>,
    settings: &FitSettings,
    n_max: usize,
    options: &FitOptions<'_>,
) -> Result<(FitResult, Vec<OrderRow>), FitError> {
    let progress = options.progress;
    let ctx = prepare(env, a1, settings)?;
    let mut prev: Option<Scored> = None;
    let mut masks = (Vec::new(), Vec::new());
    let mut rows = Vec::new();
    let mut fits: Vec<Option<FitResult>> = Vec::new();
    let mut events = Vec::new();
    let mut solves = 0;
    let mut last_err = None;
    for n in 0..=n_max {
        if let Some(p) = progress {
            p(FitProgress {
                order: n,
                last_order: n_max,
                lp_solves: solves,
            });
        }
        let of = fit_order(&ctx.prep, n, prev.as_ref(), settings, &mut masks);
        let of = recheck_stall(&ctx.prep, n, prev.as_ref(), settings, of);
        let (ne, nl) = (of.events.len(), of.lp_solves);
        events.extend(of.events);
        solves += of.lp_solves;
        match ctx.certify_ranked(n, &of.ranked, events.clone(), solves, settings) {
            Ok((res, sc)) => {
                rows.push(OrderRow {
                    order: n,
                    mean_log10: res.certificate.mean_log10_ratio,
                    max_log10: res.certificate.max_log10_ratio,
                    status: "ok".into(),
                    solver_events: ne,
                    lp_solves: nl,
                });
                prev = Some(sc);
                fits.push(Some(res));
            }
            Err(e) => {
                rows.push(OrderRow {
                    order: n,
                    mean_log10: f64::NAN,
                    max_log10: f64::NAN,
                    status: e.to_string(),
                    solver_events: ne,
                    lp_solves: nl,
                });
                fits.push(None);
                last_err = Some(e);
            }
        }
    }
    let ok = rows.iter().filter(|r| r.status == "ok");
    let best_mean = ok
        .clone()
        .map(|r| r.mean_log10)
        .fold(f64::INFINITY, f64::min);
    let best_max = ok.map(|r| r.max_log10).fold(f64::INFINITY, f64::min);
    let tol = settings.auto_tolerance;
    let chosen = rows.iter().position(|r| {
        r.status == "ok" && r.mean_log10 <= best_mean + tol && r.max_log10 <= best_max + tol
    });
    match chosen {
        Some(i) => {
            let mut res = fits[i].take().expect("row ok has a fit");
            res.solver_events = events;
            res.lp_solves = solves;
            Ok((res, rows))
        }
        None => Err(last_err.unwrap_or_else(|| FitError::Invalid("no order fitted".into()))),
    }
}

/// The order table as aligned text, with the chosen order marked.
pub fn format_table(rows: &[OrderRow], chosen: usize, tol: f64) -> String {
    let mut s = format!(
        "{:>5}  {:>18}  {:>14}  {:>5}  {}\n",
        "order", "mean log10 r/r_min", "max log10", "LPs", "status"
    );
    for r in rows {
        s.push_str(&format!(
            "{:>5}  {:>18.5}  {:>14.5}  {:>5}  {}{}\n",
            r.order,
            r.mean_log10,
            r.max_log10,
            r.lp_solves,
            r.status,
            if r.order == chosen { "  <- chosen" } else { "" }
        ));
    }
    s.push_str(&format!(
        "chosen: the smallest order whose mean and max are within {tol} (log10) of the best\n"
    ));
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::{SolverEvent, SolverStatus};

    fn event(kind: EventKind) -> SolverEvent {
        SolverEvent {
            order: 5,
            stage: "minimax".into(),
            status: SolverStatus::PrimalInfeasible,
            kind,
            action: String::new(),
        }
    }

    /// The thorough refit runs exactly for a stall with a level left undecided, above the
    /// envelope's floor: a gain, a stall without a doubt, a reduced-accuracy solution (proved
    /// afterwards) or an order below already at its envelope never triggers it.
    #[test]
    fn recheck_only_a_stall_with_an_undecided_level() {
        let doubt = [
            EventKind::LevelNotFeasible,
            EventKind::DoubtBudgetSpent,
            EventKind::NoFeasibleLevel,
        ];
        for kind in doubt {
            let ev = [event(EventKind::ReducedAccuracyUsed), event(kind)];
            assert!(stall_needs_recheck(&ev, 0.3, 0.3), "{kind:?} stall");
            assert!(stall_needs_recheck(&ev, 0.31, 0.3), "{kind:?} worse");
            assert!(stall_needs_recheck(&ev, 0.3 - 0.9 * STALL_LOG10, 0.3));
            assert!(!stall_needs_recheck(&ev, 0.3 - 1.1 * STALL_LOG10, 0.3));
            assert!(!stall_needs_recheck(&ev, 0.0, 0.5 * STALL_LOG10));
        }
        let proved = [
            event(EventKind::ReducedAccuracyUsed),
            event(EventKind::CandidateDiscarded),
            event(EventKind::RefittedChained),
        ];
        assert!(!stall_needs_recheck(&proved, 0.3, 0.3));
        assert!(!stall_needs_recheck(&[], 0.3, 0.3));
    }
}
