//! The largest singular value of a matrix given only as products `x ↦ T·x` and `y ↦ Tᴴ·y`:
//! Lanczos on `TᴴT` with full reorthogonalization (Golub & Van Loan §10.1), the answer
//! `‖T·v‖` for the unit Ritz vector `v` of the largest Ritz value.
//!
//! Why it is safe where a bound is needed: `‖T·v‖ ≤ σ_max(T)` for every unit `v`, so the
//! value returned is a lower bound of `σ_max` whatever the convergence (a grid of such
//! values bounds a margin `1/‖r·T‖∞` from above, as the dense SVD does); it is returned only
//! when the Ritz residual says it is `σ_max` to about `1e-13` relative (or the Krylov space
//! is invariant), else `None` and the caller takes its dense route.

use nalgebra::{DMatrix, SymmetricEigen};
use num_complex::Complex64;

/// Largest Krylov dimension tried.
const MAX_STEPS: usize = 80;
/// Relative residual `‖TᴴT·v − θ·v‖/θ` accepted.
const RTOL: f64 = 1e-13;

fn dot(a: &[Complex64], b: &[Complex64]) -> Complex64 {
    a.iter().zip(b).map(|(x, y)| x.conj() * y).sum()
}

fn norm(a: &[Complex64]) -> f64 {
    a.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt()
}

/// `σ_max(T)` for `T` with `cols` columns, given `t(x) = T·x` and `th(y) = Tᴴ·y`; the first
/// Krylov vector is a fixed one with no zero component (results are reproducible).
pub(crate) fn largest_singular_value(
    cols: usize,
    t: impl Fn(&[Complex64]) -> Vec<Complex64>,
    th: impl Fn(&[Complex64]) -> Vec<Complex64>,
) -> Option<f64> {
    if cols == 0 {
        return Some(0.0);
    }
    // A start with every component nonzero and no structure (golden-ratio sequence).
    let mut q: Vec<Complex64> = (0..cols)
        .map(|i| {
            let a = ((i as f64 + 1.0) * 0.618_033_988_749_895).fract() + 0.5;
            let b = ((i as f64 + 1.0) * 0.754_877_666_246_692_7).fract() - 0.5;
            Complex64::new(a, b)
        })
        .collect();
    let q0 = norm(&q);
    q.iter_mut().for_each(|z| *z /= q0);
    let mut basis: Vec<Vec<Complex64>> = Vec::new();
    let (mut alpha, mut beta): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    let steps = MAX_STEPS.min(cols);
    for j in 0..steps {
        let mut w = th(&t(&q));
        if w.len() != cols || w.iter().any(|z| !(z.re.is_finite() && z.im.is_finite())) {
            return None;
        }
        let a = dot(&q, &w).re;
        basis.push(q.clone());
        alpha.push(a);
        // Full reorthogonalization, twice (Kahan: twice is enough).
        for _ in 0..2 {
            for b in &basis {
                let c = dot(b, &w);
                w.iter_mut().zip(b).for_each(|(x, y)| *x -= c * y);
            }
        }
        let b = norm(&w);
        let k = j + 1;
        // Ritz values of the k×k tridiagonal.
        let tri = DMatrix::from_fn(k, k, |r, c| {
            if r == c {
                alpha[r]
            } else if r == c + 1 {
                beta[c]
            } else if c == r + 1 {
                beta[r]
            } else {
                0.0
            }
        });
        let eig = SymmetricEigen::new(tri);
        let (top, theta) =
            eig.eigenvalues
                .iter()
                .enumerate()
                .fold((0, f64::NEG_INFINITY), |acc, (i, v)| {
                    if *v > acc.1 {
                        (i, *v)
                    } else {
                        acc
                    }
                });
        let s = eig.eigenvectors.column(top);
        let invariant = b <= f64::EPSILON * theta.abs().max(f64::MIN_POSITIVE) * 16.0;
        let converged = theta > 0.0 && b * s[k - 1].abs() <= RTOL * theta;
        if invariant || converged || k == cols {
            if !(invariant || converged) {
                return None;
            }
            // The Ritz vector, and ‖T·v‖ on it (a lower bound of σ_max in any case).
            let mut v = vec![Complex64::new(0.0, 0.0); cols];
            for (bi, si) in basis.iter().zip(s.iter()) {
                v.iter_mut().zip(bi).for_each(|(x, y)| *x += y * *si);
            }
            let nv = norm(&v);
            if nv == 0.0 || !nv.is_finite() {
                return None;
            }
            v.iter_mut().for_each(|z| *z /= nv);
            return Some(norm(&t(&v)));
        }
        beta.push(b);
        q = w.iter().map(|z| z / b).collect();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_dense_svd() {
        // A diagonal-plus-rank-one matrix (the shape of the modal loop), 60 × 40, and a
        // random one; the dense SVD is the independent route.
        let mut x = 0.271_f64;
        let mut r = move || {
            x = (x * 3.987_654_321 + 0.1).fract();
            x - 0.5
        };
        for shape in [(60usize, 40usize), (41, 40), (5, 3)] {
            let (rows, cols) = shape;
            let mut a = DMatrix::from_fn(rows, cols, |i, j| {
                Complex64::new(if i == j { 1.0 + i as f64 } else { 0.0 }, 0.0)
            });
            let u: Vec<Complex64> = (0..rows).map(|_| Complex64::new(r(), r())).collect();
            let v: Vec<Complex64> = (0..cols).map(|_| Complex64::new(r(), r())).collect();
            for i in 0..rows {
                for j in 0..cols {
                    a[(i, j)] += u[i] * v[j] * 3.0 + Complex64::new(r(), r()) * 0.1;
                }
            }
            let ah = a.adjoint();
            let t = |x: &[Complex64]| {
                (&a * DMatrix::from_column_slice(cols, 1, x))
                    .as_slice()
                    .to_vec()
            };
            let th = |y: &[Complex64]| {
                (&ah * DMatrix::from_column_slice(rows, 1, y))
                    .as_slice()
                    .to_vec()
            };
            let got = largest_singular_value(cols, t, th).expect("converges");
            let want = a.singular_values().max();
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "{shape:?}: {got} vs {want}"
            );
        }
    }
}
