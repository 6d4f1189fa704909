//! The cutting-plane (exchange) round of one order: the standard remedy of semi-infinite
//! programming (Hettich & Kortanek, SIAM Review 35(3), 1993, Sec. 7: exchange methods).
//!
//! The fit imposes its bounds (`|r| ≥` the envelope at the data and, no-dip, between them;
//! `|r| < σ_min(M̃)` for A1) on a finite grid; the certificate then proves them between grid
//! points. A candidate whose own lightly damped pole pair peaks between two grid points can
//! cross A1 there, and when every candidate of the order does, the order fails although an
//! `r` of that order exists (the DaISy arm with ζ = 0.01 at orders 3 and 4). The certificate
//! names the frequency where each failed candidate is worst ([`cut_frequencies`]); the round
//! adds those frequencies to the order's grid and searches the order again, at most
//! [`super::FitSettings::cut_rounds`] times. The grid only grows, so each round's LPs are
//! those of the previous round with more rows (the rounds' A1 rows held a little further off,
//! by [`ROUND_BACKOFF`]), and the certificate stays the judge: a round changes where the fit
//! looks, never what passes.
//!
//! Only orders with no certified candidate enter a round, and the rounds work on a copy of
//! the grid: an order that certifies in the first round, and every order of a fit without a
//! failure, are untouched (same LPs, same `r`).

use super::certificate::Certificate;
use super::context::Context;
use super::engine::{admits, fit_order, max_tolerance, Prepared, Scored};
use super::provenance::EventKind;
use super::{FitError, FitResult, FitSettings, SolverEvent, SolverStatus};

/// Two cut frequencies closer than this (relative) are one.
const SAME: f64 = 1e-9;

/// Whether a candidate met every bound of the fit's grid (to the LP's accuracy, as the
/// search judges feasibility): only then is a failure of its certificate one between grid
/// points, which a cut can fix.
pub(crate) fn met_grid(c: &Scored) -> bool {
    c.coverage >= 1.0 - 1e-6 && c.a1_ratio >= 1.0 - 1e-6
}

/// Where a failed certificate found a bound broken (rad/s): the worst A1 frequency when A1
/// failed or was not proved (`σ_min/|r| ≤ 1` there, found by the `L∞` proof or the refined
/// grid), and the worst frequency between data when the certificate had to raise the gain
/// (a dip below the no-dip bound, repaired `ucover`-style; the repaired `r` then failed).
/// `ω = ∞` and non-finite frequencies are left out (the grid holds `ω = ∞`).
pub(crate) fn cut_frequencies(cert: &Certificate) -> Vec<f64> {
    let mut v = Vec::new();
    let a1_broken = cert.worst_a1_margin.is_some_and(|m| !(m > 1.0))
        || cert.a1_lower_bound.is_some_and(|l| !(l > 1.0));
    if let (true, Some(w)) = (a1_broken, cert.worst_a1_omega) {
        v.push(w);
    }
    if cert.repair_factor > 1.0 + 1e-12 {
        v.push(cert.worst_between_omega);
    }
    v.retain(|w| w.is_finite() && *w > 0.0);
    v
}

/// The new cuts among `found`: sorted, without repeats, none already in `have` (sorted).
fn fresh(mut found: Vec<f64>, have: &[f64]) -> Vec<f64> {
    found.sort_by(f64::total_cmp);
    found.dedup_by(|a, b| (*a / *b - 1.0).abs() < SAME);
    found.retain(|w| !have.iter().any(|h| (w / h - 1.0).abs() < SAME));
    found
}

/// The A1 back-off of a round's grid (`|r| ≤ (1 − b)·σ_min(M̃)` at its points), at least
/// this, ten times the fit's default 1e-6. A round runs only where a candidate touched A1
/// between grid points, i.e. next to a notch of `σ_min(M̃)`; there the cluster's points lie
/// up to `h/2⁹ = 9e-5` apart at `1e-4` from a cut, over which a notch of damping ζ = 0.02
/// (the arm's 0.3613 rad/s mode) curves `σ_min` by `(δ/ζ)²/2 ≈ 2.6e-6` (δ half the gap):
/// more than 1e-6. Measured on the ζ = 0.01 arm's order 3 (issue 38, thirteenth step): with
/// 1e-6 the candidate of a round overshoots A1 between points by up to 1.6e-6 (σ_min/|r| =
/// 0.9999994, uncertified after 3 rounds) depending only on which feasible point the level
/// LPs return (working set kept or not, row order), and certifies with margins of 1e-5 down
/// to 7e-7 when it does; with 1e-5, every one of 25 such variants certifies orders 3 and 4,
/// `max |r|/σ_min ≤ 0.9999915`. The cost is `|r|` lower by 1e-5 (4e-6 decade) where A1 binds.
const ROUND_BACKOFF: f64 = 1e-5;

/// Points a cut adds on each side of its frequency: at `ω·(1 ± h·2⁻ʲ)`, `j = 0..CLUSTER`,
/// `h` the grid's step (4.7 % at 50 points per decade), down to `h/2¹³` (6e-6).
const CLUSTER: i32 = 14;

/// A cut at `w` and the points around it, geometrically closer towards it, and the lightly
/// damped zeros of `M̃` (`dips`) within one grid step of it. The failed candidate's peak was
/// at `w`; the next search's peak moves a little away from any one new point (a pole pair
/// of damping ζ is about 2ζ wide: 1.5 % at the arm's ζ = 0.0076), so a single point per
/// round chased it round after round. The cluster holds the bound at every scale from one
/// grid step down to `6e-6·ω` around `w` in the one round: where an LP solution touches A1
/// at a notch of `σ_min(M̃)` (ζ = 0.03: `σ_min` curves by `(δ/ζ)²/2`, 2e-8 over `δ = 6e-6`),
/// the fit's back-off of 1e-6 covers what lies between the points.
fn cluster(w: f64, per_decade: usize, dips: &[f64]) -> Vec<f64> {
    let h = 10f64.powf(1.0 / per_decade as f64) - 1.0;
    let mut v = vec![w];
    for j in 0..CLUSTER {
        let d = h * 0.5f64.powi(j);
        v.push(w * (1.0 + d));
        v.push(w / (1.0 + d));
    }
    v.extend(
        dips.iter()
            .filter(|d| **d > w / (1.0 + h) && **d < w * (1.0 + h)),
    );
    v
}

/// Whether the certified fit `a` of a round beats `b` of an earlier one, as
/// [`Context::certify_ranked`] ranks its certified candidates: admitted after the previous
/// order's `r` first ([`admits`]), then the objective's value, then the mean.
fn better(
    (a, sa): &(FitResult, Scored),
    (b, sb): &(FitResult, Scored),
    prev: Option<&Scored>,
    set: &FitSettings,
) -> bool {
    let admitted =
        |s: &Scored| prev.is_none_or(|p| admits(set.objective, max_tolerance(set), p, s));
    let (ka, kb) = (admitted(sa), admitted(sb));
    let (x, y) = (a.objective_value, b.objective_value);
    (ka && !kb)
        || (ka == kb
            && (x < y - 1e-12
                || (x <= y + 1e-12
                    && a.certificate.mean_log10_ratio < b.certificate.mean_log10_ratio)))
}

fn fmt_list(v: &[f64]) -> String {
    v.iter()
        .map(|w| format!("{w:.6e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The rounds of order `n` after its first search failed with `err`, its certificates
/// naming `cuts` (rad/s). `prev` is the previous order's certified `r` (a chained sweep);
/// `events` and `lp_solves` are the fit's so far and grow by the rounds'. Returns the first
/// certified fit of a round, or, after the last round (the cap, or no new frequency), the
/// last failure with the rounds said in its reasons.
#[allow(clippy::too_many_arguments)]
pub(crate) fn search_again(
    ctx: &Context<'_>,
    n: usize,
    prev: Option<&Scored>,
    set: &FitSettings,
    cuts: Vec<f64>,
    err: FitError,
    events: &mut Vec<SolverEvent>,
    lp_solves: &mut usize,
) -> Result<(FitResult, Scored), FitError> {
    let mut err = err;
    let mut all: Vec<f64> = Vec::new();
    let mut next = fresh(cuts, &all);
    let mut rounds = 0;
    // The best certified fit of a round; later rounds run while a better-ranked candidate
    // failed between grid points (and the cap allows), and the best of all wins.
    let mut best: Option<(FitResult, Scored)> = None;
    // The rounds' grid keeps A1 off by `ROUND_BACKOFF` (the first search's by the fit's own).
    let round_set = FitSettings {
        a1_backoff: set.a1_backoff.max(ROUND_BACKOFF),
        ..set.clone()
    };
    while rounds < set.cut_rounds && !next.is_empty() {
        rounds += 1;
        all.extend(&next);
        all.sort_by(f64::total_cmp);
        let points: Vec<f64> = all
            .iter()
            .flat_map(|w| cluster(*w, set.grid_per_decade, &set.a1_dips))
            .collect();
        let sub = Context {
            env: ctx.env,
            a1: ctx.a1,
            scaling: ctx.scaling,
            floor: ctx.floor,
            lower: ctx.lower.clone(),
            prep: Prepared {
                w: ctx.prep.w.clone(),
                rmin: ctx.prep.rmin.clone(),
                weights: ctx.prep.weights.clone(),
                grid: ctx.grid_with_cuts(&round_set, &points),
                band: ctx.prep.band,
            },
        };
        // The previous order's r judged on this grid (it is certified: it meets the cuts).
        let prev = prev.map(|p| sub.prep.score(p.zpk.clone(), p.origin));
        // The working sets of the first search index the old grid's rows: start afresh.
        let mut masks = (Vec::new(), Vec::new());
        let of = fit_order(&sub.prep, n, prev.as_ref(), set, &mut masks);
        *lp_solves += of.lp_solves;
        let what = if best.is_none() {
            format!("no candidate of order {n} certified")
        } else {
            format!("a better-ranked candidate of order {n} failed its certificate")
        };
        events.push(SolverEvent {
            order: n,
            stage: format!("cutting-plane round {rounds} of at most {}", set.cut_rounds),
            status: SolverStatus::NoCandidate,
            kind: EventKind::CutsAdded,
            action: format!(
                "{what}: a bound fails between the fit's constraint points at omega = {} rad/s; added as constraint points with {} more around each (within one grid step), order {n} searched again ({} LPs)",
                fmt_list(&next),
                2 * CLUSTER,
                of.lp_solves
            ),
        });
        events.extend(of.events);
        let (res, found) = sub.certify_ranked_cuts(
            n,
            &of.ranked,
            prev.as_ref(),
            set.objective,
            events.clone(),
            *lp_solves,
            set,
        );
        match res {
            Ok(ok) => {
                if best
                    .as_ref()
                    .is_none_or(|b| better(&ok, b, prev.as_ref(), set))
                {
                    best = Some(ok);
                }
            }
            Err(e) => err = e,
        }
        next = fresh(found, &all);
    }
    if let Some((mut res, sc)) = best {
        // The fit's work includes every round's.
        res.solver_events = events.clone();
        res.lp_solves = *lp_solves;
        return Ok((res, sc));
    }
    if rounds == 0 {
        return Err(err);
    }
    let why = if next.is_empty() {
        "no new frequency to add"
    } else {
        "the cap"
    };
    let note = format!(
        "{rounds} cutting-plane round(s) ({why}; constraint points added at omega = {} rad/s, {} more around each)",
        fmt_list(&all),
        2 * CLUSTER
    );
    Err(match err {
        FitError::Uncertified {
            result,
            mut reasons,
        } => {
            reasons.push(note);
            FitError::Uncertified { result, reasons }
        }
        FitError::NoFeasibleFit {
            order,
            mut reasons,
            events,
        } => {
            reasons.push(note);
            FitError::NoFeasibleFit {
                order,
                reasons,
                events,
            }
        }
        other => other,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cluster: the cut, `2·CLUSTER` points within one grid step, closer and closer
    /// (the innermost `6e-6` relative), and the dips within one step only.
    #[test]
    fn cluster_spans_one_grid_step_down_to_6e_6() {
        let h = 10f64.powf(1.0 / 50.0) - 1.0;
        let v = cluster(2.0, 50, &[2.05, 3.0]);
        assert_eq!(v.len(), 2 * CLUSTER as usize + 2);
        assert!(v.contains(&2.05) && !v.contains(&3.0));
        let rel: Vec<f64> = v[1..v.len() - 1]
            .iter()
            .map(|w| (w / 2.0).ln().abs())
            .collect();
        let max = rel.iter().copied().fold(0.0, f64::max);
        let min = rel.iter().copied().fold(f64::INFINITY, f64::min);
        assert!((max - (1.0 + h).ln()).abs() < 1e-12, "{max}");
        assert!(min > 5e-6 && min < 7e-6, "{min}");
    }

    /// New cuts are sorted, once each, and never one already added.
    #[test]
    fn fresh_drops_repeats_and_known_cuts() {
        let v = fresh(vec![3.0, 1.0, 1.0 + 1e-12, 2.0], &[2.0 * (1.0 + 1e-12)]);
        assert_eq!(v, vec![1.0, 3.0]);
    }
}
