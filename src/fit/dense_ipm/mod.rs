//! A dense interior-point solver for the fit's level LPs (issue 38, eighth step): few
//! columns (`n ≈ 14`), many rows (100–9000), no objective.  The answer is a *well-defined*
//! point of the level set — the analytic centre
//!
//! `v* = argmax Σ_i ln(g_iᵀv − h_i) + Σ_j ln(R² − v_j²)` s.t. `E v = e`
//!
//! of `{v : G v ≥ h, E v = e, ‖v‖∞ ≤ R}` (the box keeps the centre defined when the level
//! set is unbounded; `R = 10⁶` is far outside the fit's coefficients) — so the point is a
//! function of the LP alone: not of the row order, the start, or the solver's path.
//!
//! The equalities are eliminated (`v = v₀ + Z w`, `Z` an orthonormal null-space basis of
//! `E`), the rows scaled to unit norm, then [`phase1`] finds a strictly feasible `w` or a
//! Farkas certificate, and damped Newton ([`newton`]) goes to the centre.  Every claim is
//! checked: a certificate by [`farkas_holds`] on the unscaled rows, a centre by its Newton
//! decrement; what is neither proven is [`Outcome::Undecided`].

mod newton;
mod phase1;
#[cfg(test)]
mod tests;

use super::problem::Lp;
use nalgebra::DMatrix;
use newton::{centre, Centring, Rows};
use phase1::{find_interior, Phase1};

/// Box radius `R` on every coordinate of `v`.
pub(crate) const RADIUS: f64 = 1e6;

/// Newton steps, at most, per solve (phase 1 and the centring together).
const NEWTON_CAP: usize = 200;

/// `λ²/2` at which the centring stops (quadratic convergence: one step past `10⁻⁴`).
const CENTRE_TOL: f64 = 1e-14;

/// A Farkas certificate of `{G v ≥ h, E v = e}`: `y ≥ 0` on the `≥` rows, `μ` free on the
/// equalities, with `r = Gᵀy + Eᵀμ` small and `hᵀy + eᵀμ > R‖r‖₁` (then `yᵀ(Gv − h) +
/// μᵀ(Ev − e) = rᵀv − (hᵀy + eᵀμ) < 0` for every `‖v‖∞ ≤ R`: no feasible point there).
#[derive(Debug, Clone)]
pub(crate) struct Farkas {
    pub y: Vec<f64>,
    pub mu: Vec<f64>,
}

/// What a solve proved.
#[derive(Debug, Clone)]
pub(crate) enum Outcome {
    /// The analytic centre (`converged`: its Newton decrement met the tolerance; else a
    /// strictly feasible point short of it).
    Centre { v: Vec<f64>, converged: bool },
    /// No feasible point with `‖v‖∞ ≤ R`, with its checked certificate.
    Infeasible(Farkas),
    /// Neither proven; why (for the tests and a debugger: the fit needs only the status).
    Undecided(#[allow(dead_code)] &'static str),
}

/// Work done by one solve.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Stats {
    pub phase1_steps: usize,
    pub centre_steps: usize,
}

/// `E v = e` eliminated: `v = v0 + Z w`.
struct Elimination {
    v0: Vec<f64>,
    /// `n × d`, row-major.
    z: Vec<f64>,
    d: usize,
}

/// Orthonormal bases of the row space and null space of `E` from the eigenvectors of `EᵀE`;
/// `None` when the equalities are inconsistent (then `mu` is returned as the certificate).
fn eliminate(n: usize, eq: &[(Vec<f64>, f64)]) -> Result<Elimination, Vec<f64>> {
    if eq.is_empty() {
        let mut z = vec![0.0; n * n];
        (0..n).for_each(|j| z[j * n + j] = 1.0);
        return Ok(Elimination {
            v0: vec![0.0; n],
            z,
            d: n,
        });
    }
    let p = eq.len();
    let e = DMatrix::from_fn(p, n, |i, j| eq[i].0[j]);
    let rhs = nalgebra::DVector::from_iterator(p, eq.iter().map(|r| r.1));
    let ete = e.transpose() * &e;
    let eig = ete.symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let range: Vec<usize> = (0..n)
        .filter(|&j| eig.eigenvalues[j] > 1e-12 * top)
        .collect();
    let null: Vec<usize> = (0..n)
        .filter(|&j| eig.eigenvalues[j] <= 1e-12 * top)
        .collect();
    // v0 = Σ_range q (qᵀ Eᵀ e) / λ: the least-squares solution of E v = e.
    let ete_rhs = e.transpose() * &rhs;
    let mut v0 = vec![0.0; n];
    for &j in &range {
        let q = eig.eigenvectors.column(j);
        let coef = q.dot(&ete_rhs) / eig.eigenvalues[j];
        for (k, v) in v0.iter_mut().enumerate() {
            *v += coef * q[k];
        }
    }
    let resid: Vec<f64> = (0..p)
        .map(|i| rhs[i] - eq[i].0.iter().zip(&v0).map(|(a, b)| a * b).sum::<f64>())
        .collect();
    let scale = 1.0 + rhs.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if resid.iter().any(|r| r.abs() > 1e-9 * scale) {
        return Err(resid);
    }
    let d = null.len();
    let mut z = vec![0.0; n * d];
    for (c, &j) in null.iter().enumerate() {
        for k in 0..n {
            z[k * d + c] = eig.eigenvectors[(k, j)];
        }
    }
    Ok(Elimination { v0, z, d })
}

/// The level rows in `w` (unit norm) followed by the `2n` box rows; `kept[i]` is the LP
/// row of reduced row `i`, `norm[i]` its scale.
struct Reduced {
    rows: Rows,
    mg: usize,
    kept: Vec<usize>,
    norm: Vec<f64>,
}

enum Reduction {
    Rows(Reduced),
    /// Row `i` is constant on `E v = e` and violated.
    Violated(usize),
    /// A row constant on `E v = e` and tight: no interior.
    Tight,
}

fn reduce(lp: &Lp, el: &Elimination) -> Reduction {
    let (n, d) = (lp.n, el.d);
    let mut a = Vec::with_capacity((lp.ge.len() + 2 * n) * d);
    let mut b = Vec::with_capacity(lp.ge.len() + 2 * n);
    let (mut kept, mut norm) = (Vec::new(), Vec::new());
    let mut row = vec![0.0; d];
    for (i, (g, h)) in lp.ge.iter().enumerate() {
        row.iter_mut().for_each(|v| *v = 0.0);
        let gmax = g.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
        for (k, gk) in g.iter().enumerate() {
            if *gk != 0.0 {
                let zk = &el.z[k * d..(k + 1) * d];
                row.iter_mut().zip(zk).for_each(|(r, z)| *r += gk * z);
            }
        }
        let gv0: f64 = g.iter().zip(&el.v0).map(|(u, v)| u * v).sum();
        let rhs = h - gv0;
        let nr = row.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(nr > 1e-13 * gmax) {
            let tol = 1e-12 * (h.abs() + gv0.abs() + gmax);
            if rhs > tol {
                return Reduction::Violated(i);
            }
            if rhs >= -tol {
                return Reduction::Tight;
            }
            continue;
        }
        a.extend(row.iter().map(|v| v / nr));
        b.push(rhs / nr);
        kept.push(i);
        norm.push(nr);
    }
    let mg = kept.len();
    for k in 0..n {
        let zk = &el.z[k * d..(k + 1) * d];
        let nz = zk.iter().map(|v| v * v).sum::<f64>().sqrt();
        if nz == 0.0 {
            continue;
        }
        // v_k ≥ −R and −v_k ≥ −R, with v_k = v0_k + z_kᵀw.
        a.extend(zk.iter().map(|v| v / nz));
        b.push((-RADIUS - el.v0[k]) / nz);
        a.extend(zk.iter().map(|v| -v / nz));
        b.push((-RADIUS + el.v0[k]) / nz);
    }
    Reduction::Rows(Reduced {
        rows: Rows { n: d, a, b },
        mg,
        kept,
        norm,
    })
}

/// `μ` minimizing `‖Gᵀy + Eᵀμ‖₂` (normal equations of the `p` equality rows).
fn best_mu(lp: &Lp, gty: &[f64]) -> Vec<f64> {
    let p = lp.eq.len();
    if p == 0 {
        return Vec::new();
    }
    let e = DMatrix::from_fn(p, lp.n, |i, j| lp.eq[i].0[j]);
    let g = nalgebra::DVector::from_column_slice(gty);
    let rhs = -(&e * g);
    let m = &e * e.transpose();
    match m.clone().cholesky() {
        Some(ch) => ch.solve(&rhs).iter().copied().collect(),
        None => m
            .pseudo_inverse(1e-14)
            .map(|pi| (pi * rhs).iter().copied().collect())
            .unwrap_or_else(|_| vec![0.0; p]),
    }
}

/// Whether `cert` proves that no `v` with `‖v‖∞ ≤ radius` meets the LP's rows: `y ≥ 0`,
/// and `hᵀy + eᵀμ − radius·‖Gᵀy + Eᵀμ‖₁` positive beyond the round-off of its terms.
/// Computed from the unscaled rows, independently of how the certificate was found.
pub(crate) fn farkas_holds(lp: &Lp, cert: &Farkas, radius: f64) -> bool {
    if cert.y.len() != lp.ge.len() || cert.mu.len() != lp.eq.len() {
        return false;
    }
    if cert.y.iter().chain(&cert.mu).any(|v| !v.is_finite()) || cert.y.iter().any(|v| *v < 0.0) {
        return false;
    }
    let mut r = vec![0.0; lp.n];
    let mut gap = 0.0;
    let mut size = 0.0;
    for ((g, h), y) in lp.ge.iter().zip(&cert.y).chain(lp.eq.iter().zip(&cert.mu)) {
        if *y == 0.0 {
            continue;
        }
        r.iter_mut().zip(g).for_each(|(ri, gi)| *ri += y * gi);
        gap += h * y;
        size += (h * y).abs() + radius * g.iter().map(|v| (v * y).abs()).sum::<f64>();
    }
    let r1: f64 = r.iter().map(|v| v.abs()).sum();
    // Round-off of the sums: a few units of 1e-16 per term's size (rows of 9000 terms).
    gap > 0.0 && gap - radius * r1 > 1e-14 * size
}

/// The analytic centre of the LP's feasible set (its objective is ignored), from `start`
/// when given (any point: only the work depends on it).
pub(crate) fn analytic_centre(lp: &Lp, start: Option<&[f64]>) -> (Outcome, Stats) {
    let mut stats = Stats::default();
    let bad = |v: &(Vec<f64>, f64)| {
        v.0.len() != lp.n || !v.1.is_finite() || v.0.iter().any(|x| !x.is_finite())
    };
    if lp.n == 0 || lp.ge.iter().chain(&lp.eq).any(bad) {
        return (
            Outcome::Undecided(
                "malformed LP (no columns, a wrong length or a non-finite coefficient)",
            ),
            stats,
        );
    }
    let el = match eliminate(lp.n, &lp.eq) {
        Ok(el) => el,
        Err(resid) => {
            let cert = Farkas {
                y: vec![0.0; lp.ge.len()],
                mu: resid,
            };
            return if farkas_holds(lp, &cert, RADIUS) {
                (Outcome::Infeasible(cert), stats)
            } else {
                (
                    Outcome::Undecided("inconsistent equalities without a checked certificate"),
                    stats,
                )
            };
        }
    };
    let red = match reduce(lp, &el) {
        Reduction::Rows(r) => r,
        Reduction::Violated(i) => {
            let mut y = vec![0.0; lp.ge.len()];
            y[i] = 1.0;
            let mu = best_mu(lp, &lp.ge[i].0);
            let cert = Farkas { y, mu };
            return if farkas_holds(lp, &cert, RADIUS) {
                (Outcome::Infeasible(cert), stats)
            } else {
                (
                    Outcome::Undecided("a row constant on the equalities is violated, unproven"),
                    stats,
                )
            };
        }
        Reduction::Tight => {
            return (
                Outcome::Undecided("a row is an implied equality: no interior"),
                stats,
            )
        }
    };
    let d = el.d;
    // The start in w: the projection of `start − v0` on the null space.
    let w0: Vec<f64> = match start {
        Some(s) if s.len() == lp.n && s.iter().all(|v| v.is_finite()) => (0..d)
            .map(|c| (0..lp.n).map(|k| el.z[k * d + c] * (s[k] - el.v0[k])).sum())
            .collect(),
        _ => vec![0.0; d],
    };
    let mut certify = |yr: &[f64]| -> Option<Farkas> {
        let mut y = vec![0.0; lp.ge.len()];
        for ((i, nr), v) in red.kept.iter().zip(&red.norm).zip(yr) {
            y[*i] = v / nr;
        }
        let mut gty = vec![0.0; lp.n];
        for ((g, _), yi) in lp.ge.iter().zip(&y) {
            if *yi != 0.0 {
                gty.iter_mut().zip(g).for_each(|(r, gi)| *r += yi * gi);
            }
        }
        let mu = best_mu(lp, &gty);
        let cert = Farkas { y, mu };
        farkas_holds(lp, &cert, RADIUS).then_some(cert)
    };
    let (p1, steps) = find_interior(&red.rows, red.mg, w0, NEWTON_CAP, &mut certify);
    stats.phase1_steps = steps;
    let w = match p1 {
        Phase1::Interior(w) => w,
        Phase1::Infeasible(cert) => return (Outcome::Infeasible(cert), stats),
        Phase1::Undecided(why) => return (Outcome::Undecided(why), stats),
    };
    let res = centre(
        &red.rows,
        0.0,
        None,
        w,
        CENTRE_TOL,
        NEWTON_CAP.saturating_sub(steps).max(1),
        &|_| false,
    );
    stats.centre_steps = res.iters;
    let v: Vec<f64> = (0..lp.n)
        .map(|k| el.v0[k] + (0..d).map(|c| el.z[k * d + c] * res.x[c]).sum::<f64>())
        .collect();
    if res.s.iter().any(|s| !(*s > 0.0)) {
        return (Outcome::Undecided("the centring left the interior"), stats);
    }
    (
        Outcome::Centre {
            v,
            converged: res.end == Centring::Converged,
        },
        stats,
    )
}
