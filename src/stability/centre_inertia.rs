//! The level test at an interval's centre (see [`certified_norm`](super::certified_norm)):
//! `‖T₀‖ < γ` iff `P = γ²MᴴM − I − VᴴV ≻ 0`, decided from the diagonal-plus-low-rank form
//! `P = Λ + W·Z·Wᴴ` by Haynsworth's inertia additivity on a small block, each eigenvalue
//! counted only when it clears its rounding bound.

use super::certified_norm::{At, MAX_SMALL, SMALL_LAMBDA, U};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// The centre's data for [`positive_definite`]: `n` states, `m` inputs, the enclosures, `V₀`
/// and the relative rounding bound of `V₀`'s entries.
pub(super) struct PdContext<'a> {
    pub(super) n: usize,
    pub(super) m: usize,
    pub(super) at: &'a At,
    pub(super) v0: &'a DMatrix<Complex64>,
    pub(super) rho_v: f64,
}

/// Whether `P(γ) = γ²MᴴM − I − VᴴV ≻ 0` at the centre (the module docs of
/// [`certified_norm`](super::certified_norm)): `Some(true)` proven
/// positive definite (`‖T₀‖ < γ`), `Some(false)` proven to have a negative eigenvalue
/// (`‖T₀‖ > γ`), `None` undecided at rounding.
pub(super) fn positive_definite(ctx: &PdContext, gamma: f64) -> Option<bool> {
    let (n, m, at) = (ctx.n, ctx.m, ctx.at);
    let g = gamma * gamma;
    let w_cols = 2 * m;
    // Rows of W = [Vᴴ  DᴴU], their norms and rounding bounds.
    let mut small: Vec<usize> = Vec::new();
    let mut neg_r = 0usize;
    let mut sum_r = DMatrix::<Complex64>::zeros(w_cols, w_cols);
    let mut err = 0.0;
    let mut row = vec![Complex64::new(0.0, 0.0); w_cols];
    let mut rows_s: Vec<(f64, Vec<Complex64>)> = Vec::new();
    // The entry-wise error bounds of the same terms, for `weighted_inertia`: of the small
    // rows (diagonal, row) and of the `2m` block.
    let mut f_s: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut f_w = DMatrix::<f64>::zeros(w_cols, w_cols);
    let mut eps = vec![0.0; w_cols];
    let mut wa = vec![0.0; w_cols];
    for i in 0..n {
        let di = at.d[i];
        for (k, x) in row.iter_mut().take(m).enumerate() {
            *x = ctx.v0[(k, i)].conj();
        }
        let mut eu2 = 0.0;
        let mut u2 = 0.0;
        for l in 0..m {
            let ui = at.u[i * m + l];
            row[m + l] = di.c.conj() * ui.c;
            eu2 += ui.e * ui.e;
            u2 += ui.c.norm_sqr();
        }
        let v2: f64 = (0..m).map(|k| row[k].norm_sqr()).sum();
        let w2: f64 = row.iter().map(|z| z.norm_sqr()).sum();
        let wn = w2.sqrt();
        let dn2 = di.c.norm_sqr();
        let lam = g * dn2 - 1.0;
        let ew = ctx.rho_v * v2.sqrt() + u2.sqrt() * di.e + di.c.norm() * eu2.sqrt() + 4.0 * U * wn;
        let el = 2.0 * g * di.c.norm() * di.e + 4.0 * U * (g * dn2 + 1.0);
        // The row's error split by blocks: `Vᴴ`'s part and `DᴴU`'s (each entry at most its
        // block's norm; the two together are `ew`).
        let e_vb = ctx.rho_v * v2.sqrt() + 4.0 * U * wn;
        let e_ub = u2.sqrt() * di.e + di.c.norm() * eu2.sqrt() + 4.0 * U * wn;
        for (a, (e, w)) in eps.iter_mut().zip(wa.iter_mut()).enumerate() {
            *e = if a < m { e_vb } else { e_ub };
            *w = row[a].norm();
        }
        if lam.abs() < SMALL_LAMBDA * (g * dn2 + 1.0) {
            if small.len() == MAX_SMALL {
                return None;
            }
            small.push(i);
            rows_s.push((lam, row.clone()));
            f_s.push((el, eps.clone()));
            err += el + 2.0 * std::f64::consts::SQRT_2 * ew;
            continue;
        }
        if lam.abs() <= 2.0 * el {
            return None;
        }
        if lam < 0.0 {
            neg_r += 1;
        }
        for a in 0..w_cols {
            let ca = row[a].conj() / lam;
            for b in 0..w_cols {
                sum_r[(a, b)] += ca * row[b];
            }
        }
        let al = lam.abs();
        // Entry (a, b) of (w + e)ᴴ(w + e)/(λ + δ) − wᴴw/λ, |δ| ≤ el, and of the summation.
        let (c1, c2) = (
            1.0 / (al - el),
            el / (al * (al - el)) + (n as f64 + w_cols as f64 + 4.0) * U / al,
        );
        for a_ in 0..w_cols {
            for b in 0..w_cols {
                f_w[(a_, b)] += (wa[a_] * eps[b] + eps[a_] * wa[b] + eps[a_] * eps[b]) * c1
                    + wa[a_] * wa[b] * c2;
            }
        }
        err += (2.0 * wn * ew + ew * ew) / al
            + w2 * el / (al * (al - el))
            + (n as f64 + w_cols as f64 + 4.0) * U * w2 / al;
    }
    if neg_r > m {
        return Some(false);
    }
    // −Z⁻¹ = [0  −I/γ²; −I/γ²  A/γ⁴], A = γ²·UᴴU − I.
    let mut a = DMatrix::<Complex64>::zeros(m, m);
    let mut eu_f2 = 0.0;
    let mut u_f2 = 0.0;
    for i in 0..n {
        for k in 0..m {
            let uik = at.u[i * m + k];
            eu_f2 += uik.e * uik.e;
            u_f2 += uik.c.norm_sqr();
            for l in 0..m {
                a[(k, l)] += uik.c.conj() * at.u[i * m + l].c;
            }
        }
    }
    a *= Complex64::new(g, 0.0);
    for k in 0..m {
        a[(k, k)] -= 1.0;
    }
    let e_a = g * (2.0 * u_f2.sqrt() * eu_f2.sqrt() + (n as f64 + 2.0) * U * u_f2) + U;
    err += e_a / (g * g) + 4.0 * U * (a.norm() / (g * g) + (2.0 * m as f64).sqrt() / g);
    let s = small.len();
    let size = s + w_cols;
    let mut q = DMatrix::<Complex64>::zeros(size, size);
    for (r, (lam, w)) in rows_s.iter().enumerate() {
        q[(r, r)] = Complex64::new(*lam, 0.0);
        for (b, wb) in w.iter().enumerate() {
            q[(r, s + b)] = *wb;
            q[(s + b, r)] = wb.conj();
        }
    }
    for k in 0..m {
        q[(s + k, s + m + k)] -= 1.0 / g;
        q[(s + m + k, s + k)] -= 1.0 / g;
        for l in 0..m {
            q[(s + m + k, s + m + l)] += a[(k, l)] / (g * g);
        }
    }
    for a_ in 0..w_cols {
        for b in 0..w_cols {
            q[(s + a_, s + b)] -= sum_r[(a_, b)];
        }
    }
    err += 8.0 * size as f64 * U * q.norm();
    let bound = 2.0 * err;
    let eig = q.symmetric_eigenvalues();
    let neg = eig.iter().filter(|x| **x < -bound).count();
    let pos = eig.iter().filter(|x| **x > bound).count();
    if neg_r + neg > m {
        return Some(false);
    }
    if neg + pos == size {
        return (neg_r + neg == m).then_some(true);
    }
    // Undecided by the norm-wise bound: the entry-wise one, weighted by the eigenvectors.
    let mut f = DMatrix::<f64>::zeros(size, size);
    for (r, (el, e)) in f_s.iter().enumerate() {
        f[(r, r)] = *el;
        for (b, eb) in e.iter().enumerate() {
            f[(r, s + b)] = *eb;
            f[(s + b, r)] = *eb;
        }
    }
    for k in 0..m {
        for l in 0..m {
            // −Z⁻¹'s entries: A/γ⁴ (A's error e_a, rounding) and −I/γ².
            f_w[(m + k, m + l)] += e_a / (g * g) + 4.0 * U * a[(k, l)].norm() / (g * g);
        }
        f_w[(k, m + k)] += 4.0 * U / g;
        f_w[(m + k, k)] += 4.0 * U / g;
    }
    for a_ in 0..w_cols {
        for b in 0..w_cols {
            // The assembly −Z⁻¹ − Σ: one more rounding of each term.
            let z = (q[(s + a_, s + b)] + sum_r[(a_, b)]).norm();
            f[(s + a_, s + b)] = f_w[(a_, b)] + 4.0 * U * (z + sum_r[(a_, b)].norm());
        }
    }
    let (neg, _) = super::weighted_inertia::weighted_inertia(&q, &f)?;
    match (neg_r + neg).cmp(&m) {
        std::cmp::Ordering::Greater => Some(false),
        std::cmp::Ordering::Equal => Some(true),
        std::cmp::Ordering::Less => None,
    }
}
