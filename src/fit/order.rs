//! Order selection: fit orders `0..=n_max` in one chained sweep (each order starts from the
//! previous one, so the objective's promise holds: the max never rises, nor, with
//! [`Objective::Area`], the mean; see [`super::engine::admits`]), tabulate order against
//! conservatism (mean and max of `log10(|r|/r_min)` over the data), and pick the smallest
//! order whose max is within `auto_tolerance` of the best max and whose mean is within it of
//! the best mean among those orders (`choose`).

use super::context::prepare;
use super::engine::{admits, fit_order, max_tolerance, rank, Scored};
use super::provenance::Origin;
use super::{
    A1Fn, EventKind, FitError, FitOptions, FitProgress, FitResult, FitSettings, Objective,
};
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

/// The second chain of a minimax sweep: the `r` each order would have with the
/// mean-and-max promise ([`Objective::Area`]'s), and the working sets of its searches.
struct MeanChain {
    prev: Scored,
    masks: (Vec<bool>, Vec<bool>),
}

/// Sweeps orders `0..=n_max`, returns the chosen certified fit and the table;
/// `options.progress` hears of each order before it is fitted.
///
/// With [`Objective::Minimax`] (see its promise) an order may lower the max at a higher mean;
/// from the first order that does, a second chain is carried beside the first: the `r` the
/// mean-and-max promise would have chosen at each order (the sweep before issue 38's tenth
/// step), with its own search from its own previous `r`.  The candidates of both searches
/// compete for the row, so no order's max ends above that chain's by more than the
/// bisection tolerance (a lower max at order `n` changes where order `n + 1` starts, and a
/// search from another start may end elsewhere: envelope 15 of the sweep at order 8,
/// 0.0987 → 0.1020 without it).  The chains merge again where they choose the same `r`.
pub fn fit_auto(
    env: &Envelope,
    a1: Option<A1Fn<'_>>,
    settings: &FitSettings,
    n_max: usize,
    options: &FitOptions<'_>,
) -> Result<(FitResult, Vec<OrderRow>), FitError> {
    let progress = options.progress;
    // Every order's certificate asks for A1 on the same grid: evaluate each ω once.
    let memo = super::a1_memo::A1Memo::new(a1);
    let memoized = |w: f64| memo.eval(w);
    let ctx = prepare(env, memo.wrap(&memoized), settings)?;
    let mut prev: Option<Scored> = None;
    let mut second: Option<MeanChain> = None;
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
        // The working sets as the last certified order left them: a failed order's are
        // dropped below, so a failure never changes where the next order starts.
        let masks_before = masks.clone();
        let of = fit_order(&ctx.prep, n, prev.as_ref(), settings, &mut masks);
        let mut of = recheck_stall(&ctx.prep, n, prev.as_ref(), settings, of);
        let own = of.ranked.clone();
        // The second chain's search of this order; its candidates (but its carried-over r,
        // which is the first chain's business) compete for the row too.
        let ranked_second = second.as_mut().map(|c| {
            let o = fit_order(&ctx.prep, n, Some(&c.prev), settings, &mut c.masks);
            let mut o = recheck_stall(&ctx.prep, n, Some(&c.prev), settings, o);
            of.lp_solves += o.lp_solves;
            of.events.append(&mut o.events);
            let mut all = std::mem::take(&mut of.ranked);
            all.extend(
                o.ranked
                    .iter()
                    .filter(|c| !matches!(c.origin, Origin::CarriedOver { .. }))
                    .cloned(),
            );
            of.ranked = rank(all, prev.as_ref(), settings, n, settings.objective);
            rank(o.ranked, Some(&c.prev), settings, n, Objective::Area)
        });
        let (events_before, solves_before) = (events.len(), solves);
        events.extend(of.events);
        solves += of.lp_solves;
        let (first, cuts) = ctx.certify_ranked_cuts(
            n,
            &of.ranked,
            prev.as_ref(),
            settings.objective,
            events.clone(),
            solves,
            settings,
        );
        let outcome = match first {
            // No candidate certified, a bound broken between grid points: the order's
            // cutting-plane rounds (its row counts their LPs and events).
            Err(e) if settings.cut_rounds > 0 && !cuts.is_empty() => {
                super::cutting_plane::search_again(
                    &ctx,
                    n,
                    prev.as_ref(),
                    settings,
                    cuts,
                    e,
                    &mut events,
                    &mut solves,
                )
            }
            other => other,
        };
        let (ne, nl) = (events.len() - events_before, solves - solves_before);
        match outcome {
            Ok((res, sc)) => {
                rows.push(OrderRow {
                    order: n,
                    mean_log10: res.certificate.mean_log10_ratio,
                    max_log10: res.certificate.max_log10_ratio,
                    status: "ok".into(),
                    solver_events: ne,
                    lp_solves: nl,
                });
                second = next_second(
                    &ctx,
                    n,
                    settings,
                    prev.as_ref(),
                    &sc,
                    second,
                    ranked_second,
                    own,
                    &mut masks,
                );
                prev = Some(sc);
                fits.push(Some(res));
            }
            Err(e) => {
                masks = masks_before;
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
    let tol = settings.auto_tolerance;
    let chosen = choose(&rows, tol);
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

/// The second chain after order `n` ([`fit_auto`]): its certified `r` of this order under
/// the mean-and-max promise, or `None` where it is the first chain's `r` `chosen` (or could
/// not be certified).  It starts at the first order whose `chosen` that promise would not
/// admit after `prev`, from this order's own candidates `own` and working sets `masks`.
/// Where the chains merge, the first takes the second's working sets, so from there on the
/// sweep follows the mean-and-max sweep's path (the same `r` to `10⁻¹²` in its figures).
#[allow(clippy::too_many_arguments)]
fn next_second(
    ctx: &super::context::Context<'_>,
    n: usize,
    settings: &FitSettings,
    prev: Option<&Scored>,
    chosen: &Scored,
    second: Option<MeanChain>,
    ranked_second: Option<Vec<Scored>>,
    own: Vec<Scored>,
    masks: &mut (Vec<bool>, Vec<bool>),
) -> Option<MeanChain> {
    if settings.objective != Objective::Minimax {
        return None;
    }
    let (base, ranked, second_masks, started) = match (second, ranked_second) {
        (Some(c), Some(r)) => (c.prev, r, c.masks, false),
        _ => {
            let p = prev?;
            if admits(Objective::Area, max_tolerance(settings), p, chosen) {
                return None;
            }
            let r = rank(own, Some(p), settings, n, Objective::Area);
            (p.clone(), r, masks.clone(), true)
        }
    };
    let (_, sc) = ctx
        .certify_ranked(
            n,
            &ranked,
            Some(&base),
            Objective::Area,
            Vec::new(),
            0,
            settings,
        )
        .ok()?;
    let same = (sc.max_log - chosen.max_log).abs() <= 1e-12
        && (sc.mean_log - chosen.mean_log).abs() <= 1e-12;
    if same {
        if !started {
            *masks = second_masks;
        }
        return None;
    }
    Some(MeanChain {
        prev: sc,
        masks: second_masks,
    })
}

/// The order `--order auto` reports: the smallest order whose max is within `tol` of the best
/// max in the table and whose mean is within `tol` of the best mean among those orders.  The
/// best mean is taken among the orders near the best max because with
/// [`Objective::Minimax`] the mean may rise where the max falls ([`admits`]): the order with
/// the smallest mean may have a max far above the best, and no order is then near both
/// (a closed-loop envelope of the guide ended "no order fitted" that way).  Where both
/// columns fall with the order (always with [`Objective::Area`]) this is the smallest order
/// within `tol` of the best of both.
fn choose(rows: &[OrderRow], tol: f64) -> Option<usize> {
    let ok = || rows.iter().filter(|r| r.status == "ok");
    let best_max = ok().map(|r| r.max_log10).fold(f64::INFINITY, f64::min);
    let near = || ok().filter(|r| r.max_log10 <= best_max + tol);
    let best_mean = near().map(|r| r.mean_log10).fold(f64::INFINITY, f64::min);
    rows.iter().position(|r| {
        r.status == "ok" && r.max_log10 <= best_max + tol && r.mean_log10 <= best_mean + tol
    })
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
        "chosen: the smallest order whose max is within {tol} (log10) of the best max and whose mean is within {tol} of the best mean of those orders\n"
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

    fn row(order: usize, max: f64, mean: f64) -> OrderRow {
        OrderRow {
            order,
            mean_log10: mean,
            max_log10: max,
            status: "ok".into(),
            solver_events: 0,
            lp_solves: 0,
        }
    }

    /// The chosen order: near the best max, and near the best mean among the orders near the
    /// best max.  A minimax table whose mean rose where the max fell (order 2 below: max −0.28,
    /// mean +0.05) has no order within 0.01 of both column minima, and still a choice; a table
    /// falling in both columns gives the smallest order near both minima, as before.
    #[test]
    fn auto_chooses_near_the_best_max_then_the_best_mean() {
        let rising_mean = [
            row(0, 2.0, 1.0),
            row(1, 1.0, 0.50),
            row(2, 0.72, 0.55),
            row(3, 0.695, 0.545),
            row(4, 0.69, 0.56),
        ];
        assert_eq!(choose(&rising_mean, 0.01), Some(3));
        let falling = [
            row(0, 2.0, 1.0),
            row(1, 1.0, 0.5),
            row(2, 0.505, 0.3),
            row(3, 0.5, 0.295),
        ];
        assert_eq!(choose(&falling, 0.01), Some(2));
        let mut failed = falling.clone();
        failed[3].status = "failed".into();
        failed[3].max_log10 = f64::NAN;
        failed[3].mean_log10 = f64::NAN;
        assert_eq!(choose(&failed, 0.01), Some(2));
        assert_eq!(choose(&failed[..1], 0.01), Some(0));
        let none: Vec<OrderRow> = failed[3..].to_vec();
        assert_eq!(choose(&none, 0.01), None);
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
