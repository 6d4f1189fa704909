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
//! ([`super::problem::active_set_solve`]).  The search starts by testing the level just
//! below the best candidate already found: when that is infeasible the other candidates
//! are optimal to the bisection tolerance and no more LPs are spent.

use super::basis::{GridPoint, PointKind};
use super::engine::{Prepared, Scored};
use super::problem::{active_set_solve, initial_points, SolverEvent, SolverStatus};
use super::spectral::Zpk;
use super::FitSettings;
use crate::system::Polynomial;
use num_complex::Complex64;

/// `[T_0(u), …, T_n(u)]`.
fn cheb(n: usize, u: f64) -> Vec<f64> {
    let mut t = vec![1.0, u];
    for k in 2..=n {
        let v = 2.0 * u * t[k - 1] - t[k - 2];
        t.push(v);
    }
    t.truncate(n + 1);
    t
}

/// The disk variable of `x = ω̂²` (`1` at infinity).
fn disk(x: f64) -> f64 {
    if x.is_infinite() {
        1.0
    } else {
        (x - 1.0) / (x + 1.0)
    }
}

/// Chebyshev coefficients → monomial coefficients in `u`, ascending.
fn cheb_to_mono(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    let mut out = vec![0.0; n];
    let (mut tkm1, mut tk) = (vec![1.0], vec![0.0, 1.0]);
    for (k, ck) in c.iter().enumerate() {
        let tcur: &Vec<f64> = if k == 0 { &tkm1 } else { &tk };
        for (j, v) in tcur.iter().enumerate() {
            out[j] += ck * v;
        }
        if k >= 1 {
            let mut next = vec![0.0; tk.len() + 1];
            for (j, v) in tk.iter().enumerate() {
                next[j + 1] += 2.0 * v;
            }
            for (j, v) in tkm1.iter().enumerate() {
                next[j] -= v;
            }
            tkm1 = std::mem::replace(&mut tk, next);
        }
    }
    out
}

/// `(1 + x)^n Σ c_k T_k(u)` as a polynomial in `x` (descending powers).
fn to_x_poly(c: &[f64]) -> Polynomial {
    let n = c.len() - 1;
    let mono = cheb_to_mono(c);
    let xm1 = Polynomial::new(vec![1.0, -1.0]);
    let xp1 = Polynomial::new(vec![1.0, 1.0]);
    let mut acc = Polynomial::constant(0.0);
    for (j, mj) in mono.iter().enumerate() {
        let mut term = Polynomial::constant(*mj);
        for _ in 0..j {
            term = term.mul(&xm1);
        }
        for _ in j..n {
            term = term.mul(&xp1);
        }
        acc = acc.add(&term);
    }
    acc
}

/// Stable spectral roots of `(1 + x)^n Σ c_k T_k(u)`, or why not.
fn spectral_roots(c: &[f64], set: &FitSettings) -> Result<Vec<Complex64>, String> {
    let p = to_x_poly(c);
    if p.degree() + 1 < c.len() {
        return Err("degree drop at infinity".into());
    }
    let roots = p.roots_capped(set.root_iter_cap);

    if !roots.converged {
        return Err("root iteration did not converge".into());
    }
    let mut out = Vec::with_capacity(roots.roots.len());
    for x in roots.roots {
        let s = -(-x).sqrt();
        let s = if x.im == 0.0 {
            Complex64::new(s.re, 0.0)
        } else {
            s
        };
        if !(s.re < -set.axis_tol * s.norm()) || s.norm() == 0.0 {
            return Err(format!(
                "root on the jω-axis at scaled ω = {:.4e}",
                s.im.abs()
            ));
        }
        out.push(s);
    }
    Ok(out)
}

/// Rows `row·v ≥ rhs` (variables `[a; b; s]`), their groups and grid points; the level rows
/// (`A ≤ t·upper·B`) are appended by [`level_rows`].
struct Rows {
    rows: Vec<(Vec<f64>, f64)>,
    group: Vec<u32>,
    point: Vec<usize>,
}

fn push(r: &mut Rows, mut row: Vec<f64>, rhs: f64, g: u32, p: usize) {
    let m = row.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if m > 0.0 && m.is_finite() {
        row.iter_mut().for_each(|v| *v /= m);
    }
    r.rows.push((row, rhs / m.max(f64::MIN_POSITIVE)));
    r.group.push(g);
    r.point.push(p);
}

/// Floor on `Σ b_k T_k(u)` (normalized to 1 at `ω̂ = 1`).
const B_MIN: f64 = 1e-14;

fn fixed_rows(n: usize, grid: &[GridPoint]) -> Rows {
    let k = n + 1;
    let mut r = Rows {
        rows: Vec::new(),
        group: Vec::new(),
        point: Vec::new(),
    };
    for (i, g) in grid.iter().enumerate() {
        let t = cheb(n, disk(g.x));
        let mk = |ca: f64, cb: f64| {
            let mut v = vec![0.0; 2 * k];
            for j in 0..k {
                v[j] = ca * t[j];
                v[k + j] = cb * t[j];
            }
            v
        };
        if g.lower > 0.0 {
            push(&mut r, mk(1.0, -g.lower), 0.0, 0, i);
        }
        if let Some(a) = g.a1 {
            push(&mut r, mk(-1.0, a), 0.0, 2, i);
        }
        push(&mut r, mk(0.0, 1.0), B_MIN, 3, i);
    }
    r
}

fn level_rows(n: usize, grid: &[GridPoint], t: f64, base: &Rows) -> Rows {
    let k = n + 1;
    let mut r = Rows {
        rows: base.rows.clone(),
        group: base.group.clone(),
        point: base.point.clone(),
    };
    for (i, g) in grid.iter().enumerate() {
        if let Some(u) = g.upper.filter(|_| g.kind == PointKind::Datum) {
            let tt = cheb(n, disk(g.x));
            let mut v = vec![0.0; 2 * k];
            for j in 0..k {
                v[j] = -tt[j];
                v[k + j] = t * u * tt[j];
            }
            push(&mut r, v, 0.0, 1, i);
        }
    }
    // Sort by (group, point) so that neighbours along a group are adjacent for the
    // working-set rule.
    let mut idx: Vec<usize> = (0..r.rows.len()).collect();
    idx.sort_by_key(|&i| (r.group[i], r.point[i]));
    Rows {
        rows: idx.iter().map(|&i| r.rows[i].clone()).collect(),
        group: idx.iter().map(|&i| r.group[i]).collect(),
        point: idx.iter().map(|&i| r.point[i]).collect(),
    }
}

/// The global minimax candidate of order `n` on the grid, or `None` when it cannot improve
/// on `t_known` (the best level already reached) by more than the bisection tolerance.
pub(crate) fn minimax(
    prep: &Prepared,
    n: usize,
    t_known: f64,
    set: &FitSettings,
    events: &mut Vec<SolverEvent>,
    lp_solves: &mut usize,
) -> Option<Scored> {
    if n == 0 {
        return None;
    }
    let k = n + 1;
    let nv = 2 * k;
    let base = fixed_rows(n, &prep.grid);
    let init = initial_points(&prep.grid, 40);
    let mut eq = vec![0.0; nv];
    eq[k..2 * k].copy_from_slice(&cheb(n, 0.0));
    let eqs = vec![(eq, 1.0)];
    let cost = vec![0.0; nv];
    let mut mask = Vec::new();
    let mut try_level = |t: f64, events: &mut Vec<SolverEvent>| -> Option<Vec<f64>> {
        let r = level_rows(n, &prep.grid, t, &base);
        if mask.len() != r.rows.len() {
            mask.clear();
        }
        let (out, rounds) = active_set_solve(
            nv,
            &cost,
            &r.rows,
            &r.group,
            &r.point,
            &eqs,
            &init,
            &mut mask,
            set.max_solver_iter,
        );
        *lp_solves += rounds;
        if matches!(
            out.status,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible
        ) {
            return None;
        }
        if out.status != SolverStatus::Solved {
            events.push(SolverEvent {
                order: n,
                stage: format!("polynomial minimax t={t:.4e}"),
                status: out.status,
                action: "level treated as not feasible (the partial-fraction candidates stand)"
                    .into(),
            });
            return None;
        }
        Some(out.x)
    };
    let tol = 2.0 * (1.0 + set.bisection_tol).ln();
    let mut feasible: Vec<(f64, Vec<f64>)> = Vec::new();
    let (mut lo, mut hi);
    if t_known.is_finite() && t_known >= 1.0 {
        let probe = (t_known.ln() - tol).max(0.0);
        feasible.push((probe, try_level(probe.exp(), events)?));
        hi = probe;
        lo = 0.0;
    } else {
        let mut t = 10.0f64;
        lo = 0.0;
        hi = 0.0;
        while t < 1e25 {
            if let Some(x) = try_level(t, events) {
                feasible.push((t.ln(), x));
                hi = t.ln();
                break;
            }
            lo = t.ln();
            t *= 100.0;
        }
        if feasible.is_empty() {
            return None;
        }
    }
    for _ in 0..40 {
        if hi - lo <= tol {
            break;
        }
        let mid = 0.5 * (lo + hi);
        match try_level(mid.exp(), events) {
            Some(x) => {
                hi = mid;
                feasible.push((mid, x));
            }
            None => lo = mid,
        }
    }
    // The lowest feasible level first; a solution whose spectral factors fail (B or A
    // negative between grid points far above the band, where the disk form is small and
    // the LP tolerance hides the sign) gives way to the next higher feasible level.
    let mut found: Vec<(f64, Vec<f64>)> = feasible;
    found.sort_by(|p, q| p.0.total_cmp(&q.0));
    let mut last_err = None;
    for (lev, x) in found.into_iter().take(6) {
        let (a, b) = (&x[..k], &x[k..2 * k]);
        match (spectral_roots(a, set), spectral_roots(b, set)) {
            (Ok(zeros), Ok(poles)) => {
                let mut z = Zpk {
                    gain: 1.0,
                    zeros,
                    poles,
                };
                let ev = |c: &[f64]| cheb(n, 0.0).iter().zip(c).map(|(p, q)| p * q).sum::<f64>();
                let target = (ev(a) / ev(b)).sqrt();
                z.gain = target / z.mag(1.0);
                if z.gain > 0.0 && z.gain.is_finite() {
                    let c = prep.score(z, &format!("polynomial minimax (t = {:.4e})", lev.exp()));
                    if c.coverage >= 1.0 - 1e-6 && c.a1_ratio >= 1.0 - 1e-6 {
                        return Some(c);
                    }
                    last_err = Some(format!(
                        "level {:.4e}: bounds missed on the grid",
                        lev.exp()
                    ));
                }
            }
            (Err(e), _) | (_, Err(e)) => last_err = Some(format!("level {:.4e}: {e}", lev.exp())),
        }
    }
    if let Some(e) = last_err {
        events.push(SolverEvent {
            order: n,
            stage: "polynomial minimax spectral factorization".into(),
            status: SolverStatus::Solved,
            action: format!("{e}; candidate discarded, others tried"),
        });
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn x_polynomial_matches_the_chebyshev_form() {
        let c = [0.7, -0.2, 0.05, 0.01];
        let p = to_x_poly(&c);
        for x in [1e-3, 0.5, 1.0, 7.0, 1e3] {
            let u = disk(x);
            let direct =
                (1.0 + x).powi(3) * cheb(3, u).iter().zip(&c).map(|(a, b)| a * b).sum::<f64>();
            let via = p.eval(Complex64::new(x, 0.0)).re;
            assert!((direct - via).abs() <= 1e-12 * direct.abs().max(1.0), "{x}");
        }
    }
}
