//! The search's evaluation in O(n) when `M = E + a·bᴴ`, `E` with at most one nonzero per row
//! and per column inside the `Δ̃` block (`M₁₁`): the noisy SISO test of a model whose `M̃` is
//! diagonal (a `[physical]` model, one row per mode), where `F_L(V, φ⁻¹) = V₁₁ + V₁₂V₂₁/k`
//! (eq. (15)) and `V₁₁ = [0; M̃⁻¹ 0; 0]` (eq. (14)).
//!
//! The scaling `D_l M D_r⁻¹` keeps `E` (it has no entry in the last row or column) and scales
//! `a_k` by `d` and `b_q` by `1/d`, so the Gram matrix of the scaled matrix is diagonal plus
//! rank two: `H = Eᴴ E + W C Wᴴ`, `W = [Eᴴa, b]`, `C = [[0, 1], [1, ‖a‖²]]`.  Its largest
//! eigenvalue is found by bisection on the eigenvalue count of `H − σI`, which Haynsworth's
//! inertia additivity gives from the 2×2 Schur complement of the bordered matrix
//! `[[D − σ, W], [Wᴴ, −C⁻¹]]`: `ν₊(H − σ) = ν₊(D − σ) + ν₊(−C⁻¹ − Wᴴ(D − σ)⁻¹W) − 1`
//! (one positive eigenvalue in `−C⁻¹`, whose determinant is −1).  The eigenvector is
//! `x = (λ − D)⁻¹ W c` with `c` the null vector of that 2×2 matrix (Bunch, Nielsen and Sorensen
//! 1978 for the rank-one case); it is accepted only when its residual `‖Hx − λx‖` is at
//! rounding level, otherwise the caller falls back to the dense eigenproblem.

use nalgebra::DVector;
use num_complex::Complex64;

/// `M = E + a·bᴴ` with `E` given by its nonzeros `(row, column, value)`: rows `< k`,
/// columns `< q`, no row or column twice (the `(k+1)×(q+1)` shape of [`super::FullPlusScalar`]).
#[derive(Debug, Clone)]
pub struct LowRank {
    /// Nonzeros of `E`.
    pub entries: Vec<(usize, usize, Complex64)>,
    /// `a` (`k + 1` entries).
    pub a: DVector<Complex64>,
    /// `b` (`q + 1` entries); `M = E + a·bᴴ`.
    pub b: DVector<Complex64>,
}

/// The top eigenpair of `H = M_dᴴ M_d` found by [`top_pair`].
pub(super) struct TopPair {
    /// `λ_max(H)`, rounded up (the upper end of the bisection).
    pub lambda: f64,
    /// Unit eigenvector.
    pub x: DVector<Complex64>,
    /// `M_d x`.
    pub y: DVector<Complex64>,
}

/// `H` in the form `D + W C Wᴴ` at `t = ln d`.
struct Gram {
    d: Vec<f64>,
    g: Vec<Complex64>,
    b: Vec<Complex64>,
    alpha: f64,
}

impl LowRank {
    /// Checks the shape and that `E` has at most one nonzero per row and column.
    pub fn fits(&self, q: usize, k: usize) -> bool {
        let mut rows = vec![false; k];
        let mut cols = vec![false; q];
        self.a.len() == k + 1
            && self.b.len() == q + 1
            && self.entries.iter().all(|&(i, j, _)| {
                let fresh = i < k && j < q && !rows[i] && !cols[j];
                if fresh {
                    rows[i] = true;
                    cols[j] = true;
                }
                fresh
            })
    }

    /// True when `m` equals `E + a·bᴴ` entry by entry to rounding (relative to the size of
    /// the terms, in the 1-norm of ℂ = ℝ², which needs no square roots), so that the
    /// structured evaluation describes the matrix of the search.
    pub fn matches(&self, m: &nalgebra::DMatrix<Complex64>) -> bool {
        let l1 = |z: Complex64| z.re.abs() + z.im.abs();
        let mut e_of_col = vec![None; m.ncols()];
        for &(i, j, v) in &self.entries {
            e_of_col[j] = Some((i, v));
        }
        m.column_iter().enumerate().all(|(j, col)| {
            let bj = self.b[j].conj();
            col.iter().enumerate().all(|(i, mij)| {
                let ab = self.a[i] * bj;
                let e = match e_of_col[j] {
                    Some((r, v)) if r == i => v,
                    _ => Complex64::default(),
                };
                l1(*mij - e - ab) <= 1e-12 * (l1(e) + l1(ab) + l1(*mij))
            })
        })
    }

    /// `M x` for the unscaled `M` (`O(n)`).
    pub(super) fn times(&self, x: &DVector<Complex64>) -> DVector<Complex64> {
        let (q, k) = (self.b.len() - 1, self.a.len() - 1);
        self.apply(q, k, 0.0, x)
    }

    fn gram(&self, q: usize, k: usize, t: f64) -> Gram {
        let dd = t.exp();
        let a_at = |i: usize| if i == k { self.a[i] * dd } else { self.a[i] };
        let mut b: Vec<Complex64> = self.b.iter().copied().collect();
        b[q] /= dd;
        let mut d = vec![0.0; q + 1];
        let mut g = vec![Complex64::default(); q + 1];
        for &(i, j, v) in &self.entries {
            d[j] = v.norm_sqr();
            g[j] = v.conj() * a_at(i);
        }
        let alpha = (0..=k).map(|i| a_at(i).norm_sqr()).sum();
        Gram { d, g, b, alpha }
    }

    /// `M_d x` (`O(n)`).
    fn apply(&self, q: usize, k: usize, t: f64, x: &DVector<Complex64>) -> DVector<Complex64> {
        let dd = t.exp();
        let bx: Complex64 = (0..=q)
            .map(|j| {
                let bj = if j == q { self.b[j] / dd } else { self.b[j] };
                bj.conj() * x[j]
            })
            .sum();
        let mut y = DVector::from_fn(k + 1, |i, _| {
            let ai = if i == k { self.a[i] * dd } else { self.a[i] };
            ai * bx
        });
        for &(i, j, v) in &self.entries {
            y[i] += v * x[j];
        }
        y
    }
}

impl Gram {
    /// Number of eigenvalues of `H` above `sigma` (`sigma` not an eigenvalue of `D`).
    fn count_above(&self, sigma: f64) -> usize {
        // T = −C⁻¹ − Wᴴ(D − σ)⁻¹W, −C⁻¹ = [[α, −1], [−1, 0]].
        let (mut p, mut r, mut c) = (self.alpha, 0.0, Complex64::new(-1.0, 0.0));
        let mut above = 0;
        for ((&dj, gj), bj) in self.d.iter().zip(&self.g).zip(&self.b) {
            let den = dj - sigma;
            if den > 0.0 {
                above += 1;
            }
            p -= gj.norm_sqr() / den;
            r -= bj.norm_sqr() / den;
            c -= gj.conj() * bj / den;
        }
        let det = p * r - c.norm_sqr();
        let pos = if det < 0.0 {
            1
        } else if det > 0.0 {
            if p + r > 0.0 {
                2
            } else {
                0
            }
        } else {
            usize::from(p + r > 0.0)
        };
        (above + pos).saturating_sub(1)
    }

    /// `σ` moved off the eigenvalues of `D` (where the count is undefined) by a few ulps.
    fn off_poles(&self, mut sigma: f64) -> f64 {
        for _ in 0..8 {
            if !self.d.contains(&sigma) {
                break;
            }
            sigma = f64::from_bits(sigma.to_bits() + 4);
        }
        sigma
    }

    /// `H x` (`O(n)`).
    fn apply(&self, x: &DVector<Complex64>) -> DVector<Complex64> {
        let gx: Complex64 = self.g.iter().zip(x.iter()).map(|(g, v)| g.conj() * v).sum();
        let bx: Complex64 = self.b.iter().zip(x.iter()).map(|(b, v)| b.conj() * v).sum();
        // W C Wᴴ x = g·(bᴴx) + b·(gᴴx + α·bᴴx).
        let (cg, cb) = (bx, gx + self.alpha * bx);
        DVector::from_fn(x.len(), |j, _| {
            self.d[j] * x[j] + self.g[j] * cg + self.b[j] * cb
        })
    }
}

/// The top eigenpair of `M_dᴴ M_d` at `t = ln d`, or `None` when the eigenvector formula
/// does not pass its residual test (a decoupled or repeated top eigenvalue): the caller
/// then uses the dense eigenproblem.
pub(super) fn top_pair(lr: &LowRank, q: usize, k: usize, t: f64) -> Option<TopPair> {
    let h = lr.gram(q, k, t);
    let emax = h.d.iter().fold(0.0f64, |m, v| m.max(*v)).sqrt();
    let bn = h.b.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
    let mut hi =
        h.off_poles((emax + h.alpha.sqrt() * bn).powi(2) * (1.0 + 1e-12) + f64::MIN_POSITIVE);
    if !hi.is_finite() || h.count_above(hi) != 0 {
        return None;
    }
    // λ_max ≥ the largest squared column norm of M_d (a Rayleigh quotient of H).
    // λ_max ≥ H_jj = d_j + 2 Re(g_j b̄_j) + α|b_j|² (a Rayleigh quotient); half of the
    // largest is a safe lower end whatever the rounding.
    let lo0 = (0..=q)
        .map(|j| h.d[j] + 2.0 * (h.g[j] * h.b[j].conj()).re + h.alpha * h.b[j].norm_sqr())
        .fold(0.0f64, f64::max);
    let mut lo = 0.5 * lo0;
    if lo <= 0.0 {
        return None;
    }
    for _ in 0..200 {
        if hi - lo <= 4.0 * f64::EPSILON * hi {
            break;
        }
        let mid = if hi > 2.0 * lo {
            (lo * hi).sqrt()
        } else {
            0.5 * (lo + hi)
        };
        let mid = h.off_poles(mid);
        if !(mid > lo && mid < hi) {
            break;
        }
        if h.count_above(mid) >= 1 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let lambda = hi;
    // Null vector c of T(λ) = −C⁻¹ − Wᴴ(D − λ)⁻¹W, then x = (λ − D)⁻¹ W c.
    let (mut p, mut r, mut c) = (h.alpha, 0.0, Complex64::new(-1.0, 0.0));
    for ((&dj, gj), bj) in h.d.iter().zip(&h.g).zip(&h.b) {
        let den = dj - lambda;
        p -= gj.norm_sqr() / den;
        r -= bj.norm_sqr() / den;
        c -= gj.conj() * bj / den;
    }
    // Eigenvector of [[p, c], [c̄, r]] for its eigenvalue of smallest modulus.
    let mean = 0.5 * (p + r);
    let rad = (0.25 * (p - r) * (p - r) + c.norm_sqr()).sqrt();
    let l = if (mean + rad).abs() < (mean - rad).abs() {
        mean + rad
    } else {
        mean - rad
    };
    let v1 = [c, Complex64::new(l - p, 0.0)];
    let v2 = [Complex64::new(l - r, 0.0), c.conj()];
    let n1 = v1[0].norm_sqr() + v1[1].norm_sqr();
    let n2 = v2[0].norm_sqr() + v2[1].norm_sqr();
    let cv = if n1 >= n2 { v1 } else { v2 };
    let mut x = DVector::from_fn(q + 1, |j, _| {
        (h.g[j] * cv[0] + h.b[j] * cv[1]) / (lambda - h.d[j])
    });
    let nx = x.norm();
    if !(nx.is_finite() && nx > 0.0) {
        return None;
    }
    x /= Complex64::new(nx, 0.0);
    // The residual test: the formula loses accuracy when the top eigenvalue is decoupled
    // from W (an eigenvalue of D) or repeated.
    let hx = h.apply(&x);
    let res = (&hx - &x * Complex64::new(lambda, 0.0)).norm();
    if res.is_nan() || res > 1e-9 * lambda {
        return None;
    }
    let y = lr.apply(q, k, t, &x);
    Some(TopPair { lambda, x, y })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    fn dense(lr: &LowRank, q: usize, k: usize, t: f64) -> DMatrix<Complex64> {
        DMatrix::from_fn(k + 1, q + 1, |i, j| {
            let mut e = DVector::zeros(q + 1);
            e[j] = Complex64::new(1.0, 0.0);
            lr.apply(q, k, t, &e)[i]
        })
    }

    /// Against the dense Hermitian eigenproblem on random instances of the noisy test's
    /// shape (`k = q + 1`, `E` on the subdiagonal), several scalings.
    #[test]
    fn top_pair_matches_dense_eigen() {
        let mut seed = 11u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut checked = 0;
        for n in [1usize, 2, 5, 30, 120] {
            for _ in 0..6 {
                let (q, k) = (n, n + 1);
                let spread = 10f64.powf(4.0 * rnd());
                let lr = LowRank {
                    entries: (0..n)
                        .map(|j| (j + 1, j, Complex64::new(rnd(), rnd()) * spread.powf(rnd())))
                        .collect(),
                    a: DVector::from_fn(k + 1, |_, _| Complex64::new(rnd(), rnd())),
                    b: DVector::from_fn(q + 1, |_, _| Complex64::new(rnd(), rnd())),
                };
                assert!(lr.fits(q, k));
                for t in [-3.0, 0.0, 2.5] {
                    let md = dense(&lr, q, k, t);
                    let eig = (md.adjoint() * &md).symmetric_eigen();
                    let lmax = eig.eigenvalues.max();
                    let Some(tp) = top_pair(&lr, q, k, t) else {
                        continue;
                    };
                    assert!(
                        (tp.lambda - lmax).abs() <= 1e-10 * lmax,
                        "n {n} t {t}: {} vs {lmax}",
                        tp.lambda
                    );
                    let y = &md * &tp.x;
                    assert!((y.norm_squared() - lmax).abs() <= 1e-8 * lmax);
                    assert!((&tp.y - y).norm() <= 1e-10 * lmax.sqrt());
                    checked += 1;
                }
            }
        }
        assert!(
            checked >= 80,
            "only {checked} instances took the structured path"
        );
    }
}
