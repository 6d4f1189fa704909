//! Phase 1: a strictly feasible point of `{w : A w > b}` (inside the box), or multipliers
//! proving that none exists, by the barrier method on `min τ` s.t. `A w + τ ≥ b` (Boyd &
//! Vandenberghe §11.4.1): at the centre for parameter `t`, `y_i = 1/(t s_i)` is dual
//! feasible and `bᵀy` (box rows included) bounds `τ*` from below, so `τ < 0` proves
//! feasibility and a positive bound, once checked as a Farkas certificate, infeasibility.

use super::newton::{centre, newton_multipliers, Centring, Rows};

/// What phase 1 found.
pub(super) enum Phase1<C> {
    /// A point with every level row's slack positive.
    Interior(Vec<f64>),
    /// The caller's checked certificate.
    Infeasible(C),
    /// Neither proven within the caps.
    Undecided(&'static str),
}

/// Factor on `t` between centrings.
const MU: f64 = 20.0;

/// `λ²/2` at which a phase-1 centring stops: loose, because the multipliers of
/// [`newton_multipliers`] are dual feasible at any point (nonnegative where `λ < 1`), so
/// the bound they give does not need an exact centre.
const PHASE1_TOL: f64 = 0.05;

/// `|τ*|` (unit rows) below which a level set counts as on the boundary: neither a point
/// nor a certificate is sought further.
const BOUNDARY: f64 = 1e-9;

/// Largest barrier parameter: beyond it the Newton systems are at the round-off of `1/s²`.
const T_MAX: f64 = 1e14;

/// Centrings, at most.
const STAGES: usize = 40;

/// Phase 1 over `rows` whose first `mg` rows are the level rows (they get `τ`) and the rest
/// the box rows (strictly satisfied at `w0`, or the result is undecided).  `certify` turns
/// the level rows' multipliers into a checked certificate, or `None`.  Returns the result
/// and the Newton steps taken.
pub(super) fn find_interior<C>(
    rows: &Rows,
    mg: usize,
    w0: Vec<f64>,
    newton_cap: usize,
    certify: &mut dyn FnMut(&[f64]) -> Option<C>,
) -> (Phase1<C>, usize) {
    let d = rows.n;
    let s0 = rows.slacks(&w0);
    if s0[mg..].iter().any(|v| !(*v > 0.0)) {
        return (Phase1::Undecided("the start is outside the box"), 0);
    }
    let worst = s0[..mg].iter().fold(f64::NEG_INFINITY, |a, v| a.max(-v));
    if mg == 0 || worst < 0.0 {
        return (Phase1::Interior(w0), 0);
    }
    // The rows of (w, τ).
    let n1 = d + 1;
    let mut a = Vec::with_capacity(rows.m() * n1);
    for (i, r) in rows.a.chunks_exact(d).enumerate() {
        a.extend_from_slice(r);
        a.push(if i < mg { 1.0 } else { 0.0 });
    }
    let ext = Rows {
        n: n1,
        a,
        b: rows.b.clone(),
    };
    let tau0 = worst + 1.0;
    let mut x = w0;
    x.push(tau0);
    let mut c = vec![0.0; n1];
    c[d] = 1.0;
    let m = ext.m() as f64;
    // At this t the duality gap m/t equals τ0: the bound starts near zero.
    let mut t = m / tau0;
    let mut steps = 0;
    let feasible = |x: &[f64]| x[d] < 0.0;
    for _ in 0..STAGES {
        let left = newton_cap.saturating_sub(steps);
        if left == 0 {
            return (Phase1::Undecided("Newton step cap in phase 1"), steps);
        }
        let res = centre(&ext, t, Some(&c), x, PHASE1_TOL, left, &feasible);
        steps += res.iters;
        x = res.x;
        if x[d] < 0.0 {
            x.truncate(d);
            return (Phase1::Interior(x), steps);
        }
        match res.end {
            Centring::Stalled => {
                return (Phase1::Undecided("phase 1 stalled (Newton system)"), steps)
            }
            Centring::Capped => return (Phase1::Undecided("Newton step cap in phase 1"), steps),
            Centring::Converged => {}
        }
        // Dual estimate (Aᵀy = c): its objective bᵀy bounds τ* from below.
        let Some(y) = newton_multipliers(&ext, t, &c, &res.s) else {
            return (Phase1::Undecided("phase 1 stalled (Newton system)"), steps);
        };
        let lower: f64 = y.iter().zip(&ext.b).map(|(u, v)| u * v).sum();
        if lower > 0.0 {
            if let Some(cert) = certify(&y[..mg]) {
                return (Phase1::Infeasible(cert), steps);
            }
        }
        // Neither proven, and no more to learn: τ* is within `BOUNDARY` of zero (the level
        // set is empty or thinner than that: a tie at the rows' round-off), or known to
        // 1e-10 with a certificate that failed the check, or `t` is past the round-off.
        let boundary = x[d] <= BOUNDARY && lower >= -BOUNDARY;
        if boundary || x[d] - lower <= 1e-10 * (1.0 + x[d].abs()) || t > T_MAX {
            let why = if boundary {
                "no interior: the level set is within 1e-9 of empty"
            } else if lower > 0.0 {
                "phase 1 bound positive, certificate not verified"
            } else {
                "phase 1 reached the round-off of its barrier"
            };
            return (Phase1::Undecided(why), steps);
        }
        t *= MU;
    }
    (Phase1::Undecided("phase 1 stage cap"), steps)
}
