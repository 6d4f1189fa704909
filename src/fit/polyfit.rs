//! A second parametrization of the minimax step: the full numerator and denominator of
//! `|r̂|² = A(x)/B(x)`, `x = ω̂²`, as Chebyshev series in the disk variable
//! `u = (x − 1)/(x + 1)` (`A(x) = (1 + x)^N Σ a_k T_k(u)`, the factor cancels in the ratio).
//!
//! This is the classical log-Chebyshev formulation of magfit / `fitmagfrd`: for a fixed
//! level `t` every bound is linear in `(a, b)` —
//! `A ≥ lower·B`, `A ≤ t·upper·B` at the data, `A ≤ α·B` (A1), `B > 0` —, so
//! `min_t {feasible}` is quasi-convex and a bisection on `ln t` reaches its global optimum
//! over all `(A, B)` of degree `N` on the grid (GitHub issue 11, defect 3).  The mapped
//! variable keeps every basis value in `[−1, 1]` over any band, where the partial-fraction
//! basis of [`super::basis`] becomes ill-conditioned over 4–7 decades.
//!
//! Each level is a pure feasibility LP (feasible iff Clarabel reports `Solved`; an
//! interior-point solution of a zero objective lies near the analytic centre, away from
//! the bounds; a slack variable would not do: the disk form of a rising `|r|` is tiny far
//! above the band, so any uniform slack there is ~0 at every level), solved on a working set
//! ([`super::working_set::active_set_solve`]).  The search starts by testing the level just
//! below the best candidate already found: when that is infeasible the other candidates
//! are optimal to the bisection tolerance and no more LPs are spent.

use super::chebseries;
use super::engine::{Prepared, Scored};
use super::polylevel::LevelLp;
use super::polyrows::B_CUTS;
use super::problem::{SolverEvent, SolverStatus};
use super::provenance::{EventKind, Origin};
use super::spectral::Zpk;
use super::FitSettings;
use rayon::prelude::*;

/// Rows (summed over the retries with every row) that doubtful levels may cost one order
/// of the global candidate before the remaining disk centres are skipped: about 140
/// doubts at 1000 data (never reached on the reference sweep), 2 at 100,000.
const DOUBT_BUDGET_ROWS: usize = 600_000;

/// Disk-map centres tried, in scaled `x`: the band centre, then — only when the search at
/// the previous attempt had a doubt — the two quarter points (`x₀ = ω̂_hi` and `1/ω̂_hi`)
/// and the two ends of the band (`x₀ = ω̂_hi²` and `1/ω̂_hi²`; the reference sweep's rising
/// envelopes 27 at orders 3–5 reach the reference optimum only there, envelopes 5 and 20
/// at orders 4–6 only at the quarter points).  The Chebyshev series of `A` and `B` are
/// well scaled only near their centre: with all roots at one end of a wide band (a rising envelope: zeros at
/// its top, poles above it) the centred series are tiny there and the LP's tolerance hides
/// their sign, so the level it proves is not reachable by a unit; an off-centre map keeps
/// them of order one (measured on the reference sweep of `tests/fit_reference.rs`).
fn centres(prep: &Prepared) -> Vec<f64> {
    let w_hi = prep.band.1.max(1.0 / prep.band.0).max(1.0);
    if w_hi < 1.5 {
        vec![1.0]
    } else {
        let x_hi = w_hi * w_hi;
        vec![1.0, w_hi, 1.0 / w_hi, x_hi, 1.0 / x_hi]
    }
}

/// The global minimax candidate of order `n` on the grid, or `None` when it cannot improve
/// on `t_known` (the best level already reached) by more than the bisection tolerance.
/// `hint`: an attempt (disk-map centre, cut floor) to try first.
pub(crate) fn minimax(
    prep: &Prepared,
    n: usize,
    t_known: f64,
    hint: Option<(f64, f64)>,
    set: &FitSettings,
    events: &mut Vec<SolverEvent>,
    lp_solves: &mut usize,
) -> Option<Scored> {
    if n == 0 {
        return None;
    }
    let mut best: Option<Scored> = None;
    let mut t_best = t_known;
    let cs = centres(prep);
    // The centre 1 with both cut floors first, then the other centres.
    let attempts: Vec<(f64, f64)> = B_CUTS
        .iter()
        .map(|b| (cs[0], *b))
        .chain(cs[1..].iter().map(|x| (*x, B_CUTS[0])))
        .collect();
    // The doubts an order may spend on other centres, from a budget in rows: a doubt costs
    // a retry with every row (3 per grid point), cheap at 1000 data and about 2 s each at
    // 100,000 (where every centre's LP ends `InsufficientProgress` alike: order 6 took
    // 200 s with all five centres).
    let allowed = (DOUBT_BUDGET_ROWS / (3 * prep.grid.len()).max(1)).max(2);
    let first = events.len();
    // The attempts in order: the band centre with the first cut floor, the second cut floor
    // only when the first attempt cut on `B` (order 10 on 1000 data: 2.6 → 2.0 s, the
    // reference sweep unchanged), the other centres.
    let mut pending: std::collections::VecDeque<(f64, f64)> = attempts.iter().copied().collect();
    if let Some(pos) = hint.and_then(|h| pending.iter().position(|p| *p == h)) {
        let h = pending.remove(pos).expect("a pending attempt");
        pending.push_front(h);
    }
    let mut b_cut_used = None;
    // The band centre runs alone (most orders end there without a doubt); after a doubt the
    // next two attempts run at once on two cores (`rayon`; one after the other on a
    // one-thread pool) from the level known then.  The
    // loop takes their results in order, exactly as if they had run one after the other: an
    // attempt is run again when the one before it lowered the level it started from, and
    // dropped when the one before it was decisive.  So the fit is that of the sequential
    // search, and at most one attempt is run for nothing.
    let mut ready: std::collections::VecDeque<Attempt> = std::collections::VecDeque::new();
    loop {
        if events.len() - first >= allowed {
            events.push(SolverEvent {
                order: n,
                stage: "polynomial minimax".into(),
                status: SolverStatus::NoCandidate,
                kind: EventKind::DoubtBudgetSpent,
                action: format!(
                    "{} doubtful levels, the budget for {} grid points: other disk centres not tried (the other candidates stand)",
                    events.len() - first,
                    prep.grid.len()
                ),
            });
            break;
        }
        let mut a = match ready.pop_front() {
            Some(a) if a.t_start == t_best => a,
            Some(a) => attempt_at(prep, n, a.attempt, t_best, set),
            None => {
                let Some(next) = pending.pop_front() else {
                    break;
                };
                // One thread (`RAYON_NUM_THREADS=1`, or a one-thread pool): the plain
                // sequential search; a pair there would only run its second attempt for
                // nothing whenever the first is decisive or lowers the level.
                if b_cut_used.is_none() || rayon::current_num_threads() < 2 {
                    attempt_at(prep, n, next, t_best, set)
                } else {
                    let pair: Vec<(f64, f64)> =
                        std::iter::once(next).chain(pending.pop_front()).collect();
                    let mut done: Vec<Attempt> = pair
                        .par_iter()
                        .map(|p| attempt_at(prep, n, *p, t_best, set))
                        .collect();
                    ready.extend(done.drain(1..));
                    done.pop().expect("one attempt")
                }
            }
        };
        // The second cut floor follows from the band centre's first attempt (a hinted
        // attempt may run before it).
        if b_cut_used.is_none() && a.attempt == attempts[0] {
            b_cut_used = Some(a.b_cut_used);
            if !a.b_cut_used {
                pending.retain(|p| *p != attempts[1]);
            }
        }
        let decisive = a.events.is_empty();
        events.append(&mut a.events);
        *lp_solves += a.lp_solves;
        if let Some(c) = a.found {
            // A candidate at (or a hair above) the level already known is kept too: it
            // is exact between the data where the known one may need repair.
            if best.as_ref().is_none_or(|b: &Scored| c.t < b.t) {
                t_best = t_best.min(c.t);
                best = Some(c);
            }
        }
        // Every doubt (a solve short of `Solved`, cuts that did not converge, a failed
        // factorization) is an event; a search without one decided every level exactly
        // at this centre, and the other centres are not needed.
        if decisive {
            break;
        }
    }
    best
}

/// One attempt of [`minimax`] (a disk-map centre and cut floor) from the known level
/// `t_start`, with its own events and LP count.
struct Attempt {
    attempt: (f64, f64),
    t_start: f64,
    found: Option<Scored>,
    events: Vec<SolverEvent>,
    lp_solves: usize,
    b_cut_used: bool,
}

fn attempt_at(
    prep: &Prepared,
    n: usize,
    attempt: (f64, f64),
    t_start: f64,
    set: &FitSettings,
) -> Attempt {
    let (mut events, mut lp_solves, mut b_cut_used) = (Vec::new(), 0, false);
    let found = minimax_at(
        prep,
        n,
        attempt,
        t_start,
        set,
        &mut events,
        &mut lp_solves,
        &mut b_cut_used,
    );
    Attempt {
        attempt,
        t_start,
        found,
        events,
        lp_solves,
        b_cut_used,
    }
}

/// [`minimax`] with the disk map centred at `x₀`: bracket the level, bisect it, and
/// factor the lowest feasible solutions.
#[allow(clippy::too_many_arguments)]
fn minimax_at(
    prep: &Prepared,
    n: usize,
    (x0, b_cut): (f64, f64),
    t_known: f64,
    set: &FitSettings,
    events: &mut Vec<SolverEvent>,
    lp_solves: &mut usize,
    b_cut_used: &mut bool,
) -> Option<Scored> {
    let mut lp = LevelLp::new(prep, n, x0, b_cut, set);
    let tol = 2.0 * (1.0 + set.bisection_tol).ln();
    let found = lp
        .bracket(t_known, tol, events)
        .map(|(lo, hi, feasible)| lp.bisect(lo, hi, tol, feasible, events));
    *lp_solves += lp.lp_solves;
    *b_cut_used |= lp.b_cut_used;
    factor_lowest(prep, n, x0, found?, set, events).map(|mut c| {
        c.attempt = Some((x0, b_cut));
        c
    })
}

/// The candidate of the lowest feasible level whose spectral factors exist and meet the
/// bounds on the grid; a solution that still fails (the certificate's exact test is
/// stricter than the grid) gives way to the next higher feasible level.
fn factor_lowest(
    prep: &Prepared,
    n: usize,
    x0: f64,
    mut found: Vec<(f64, Vec<f64>)>,
    set: &FitSettings,
    events: &mut Vec<SolverEvent>,
) -> Option<Scored> {
    let k = n + 1;
    found.sort_by(|p, q| p.0.total_cmp(&q.0));
    let mut last_err = None;
    for (lev, x) in found.into_iter().take(6) {
        let (a, b) = (&x[..k], &x[k..2 * k]);
        match (
            chebseries::spectral_roots(a, x0, set.axis_tol, set.root_iter_cap),
            chebseries::spectral_roots(b, x0, set.axis_tol, set.root_iter_cap),
        ) {
            (Ok(zeros), Ok(poles)) => {
                let mut z = Zpk {
                    gain: 1.0,
                    zeros,
                    poles,
                };
                let target = (chebseries::eval(a, 0.0) / chebseries::eval(b, 0.0)).sqrt();
                z.gain = target / z.mag(x0.sqrt());
                if z.gain > 0.0 && z.gain.is_finite() {
                    let c = prep.score(z, Origin::PolynomialMinimax { t: lev.exp() });
                    // The level is proved as `A/B` reaches it (`LevelLp::level`); the factors
                    // must reach it too, or the candidate is not the level's.
                    let reach = set.level_resolution() * (1.0 + 1e-6);
                    if c.coverage >= 1.0 - 1e-6 && c.a1_ratio >= 1.0 - 1e-6 {
                        if c.t <= lev.exp() * reach {
                            return Some(c);
                        }
                        last_err = Some(format!(
                            "level {:.4e}: the spectral factors reach only {:.4e}",
                            lev.exp(),
                            c.t
                        ));
                        continue;
                    }
                    last_err = Some(format!(
                        "level {:.4e}: bounds missed on the grid (coverage {:.3e})",
                        lev.exp(),
                        c.coverage
                    ));
                }
            }
            (Err(e), _) | (_, Err(e)) => last_err = Some(format!("level {:.4e}: {e}", lev.exp())),
        }
    }
    if let Some(e) = last_err {
        events.push(SolverEvent {
            order: n,
            stage: format!("polynomial minimax (x0 = {x0:.3e}) spectral factorization"),
            status: SolverStatus::Solved,
            kind: EventKind::CandidateDiscarded,
            action: format!("{e}; candidate discarded, others tried"),
        });
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectral_roots_of_a_known_unit_through_the_disk_map() {
        // |r|² for r = (s + 3)(s + 200)/((s + 0.5)(s + 1000)) in x, centre x₀ = 50:
        // A(x) = (x + 9)(x + 4e4); as a series in u, A(x)/(x + x₀)² = Σ a_k T_k(u) with
        // x = x₀(1+u)/(1−u): fit the three coefficients by interpolation at u = −½, 0, ½.
        let x0 = 50.0;
        let set = FitSettings::default();
        for (roots, want) in [([9.0, 4e4], [-3.0, -200.0]), ([0.25, 1e6], [-0.5, -1000.0])] {
            let f = |u: f64| {
                let x = x0 * (1.0 + u) / (1.0 - u);
                (x + roots[0]) * (x + roots[1]) / ((x + x0) * (x + x0))
            };
            // T0 = 1, T1 = u, T2 = 2u² − 1 at u = −½, 0, ½.
            let m = nalgebra::Matrix3::new(1.0, -0.5, -0.5, 1.0, 0.0, -1.0, 1.0, 0.5, -0.5);
            let rhs = nalgebra::Vector3::new(f(-0.5), f(0.0), f(0.5));
            let c = m.lu().solve(&rhs).unwrap();
            let mut s =
                chebseries::spectral_roots(c.as_slice(), x0, set.axis_tol, set.root_iter_cap)
                    .unwrap();
            s.sort_by(|p, q| q.re.total_cmp(&p.re));
            for (got, w) in s.iter().zip(want) {
                assert!(
                    (got.re - w).abs() < 1e-9 * w.abs() && got.im == 0.0,
                    "{s:?}"
                );
            }
        }
    }
}
