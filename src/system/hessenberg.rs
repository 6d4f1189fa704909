//! Reduction of a real square matrix to upper Hessenberg form by Householder similarities
//! (Golub & Van Loan, *Matrix Computations*, Algorithm 7.4.2; LAPACK `dgehd2`), without
//! accumulating the transformation: what an eigenvalue-only iteration ([`super::hqr`])
//! needs.
//!
//! Why not nalgebra's `Hessenberg`: it applies each reflection one row at a time, across the
//! column-major storage, and was 60 % of the time of a 1600 × 1600 Hamiltonian's eigenvalues
//! (the proof of `synthesize` on 200 modes, issue 34). Here both sides of each reflection
//! run down contiguous columns: `A ← (I − τvvᵀ)·A` as `w = τ·Aᵀv` then `A −= v·wᵀ`, and
//! `A ← A·(I − τvvᵀ)` as `u = τ·A·v` (column axpys) then `A −= u·vᵀ`.

use nalgebra::DMatrix;

/// An upper Hessenberg matrix orthogonally similar to `a` (entries below the subdiagonal
/// set to zero).
pub(crate) fn hessenberg_form(mut a: DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    assert_eq!(n, a.ncols(), "a square matrix");
    if n < 3 {
        return a;
    }
    let mut v = vec![0.0; n];
    let mut u = vec![0.0; n];
    let data = a.as_mut_slice();
    for k in 0..n - 2 {
        // The reflection that maps A[k+1.., k] onto a multiple of e₁.
        let m = n - k - 1;
        let col = &data[k * n + k + 1..k * n + n];
        let Some((tau, beta)) = reflector(col, &mut v[..m]) else {
            continue;
        };
        data[k * n + k + 1] = beta;
        for x in &mut data[k * n + k + 2..k * n + n] {
            *x = 0.0;
        }
        let v = &v[..m];
        // Left: rows k+1.. of columns k+1.. (column k is done above).
        for j in k + 1..n {
            let c = &mut data[j * n + k + 1..j * n + n];
            let s = tau * c.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
            if s != 0.0 {
                for (x, y) in c.iter_mut().zip(v) {
                    *x -= s * y;
                }
            }
        }
        // Right: every row, columns k+1.. .
        u.iter_mut().for_each(|x| *x = 0.0);
        for (i, vi) in v.iter().enumerate() {
            let c = &data[(k + 1 + i) * n..(k + 2 + i) * n];
            for (x, y) in u.iter_mut().zip(c) {
                *x += vi * y;
            }
        }
        for (i, vi) in v.iter().enumerate() {
            let s = tau * vi;
            if s != 0.0 {
                let c = &mut data[(k + 1 + i) * n..(k + 2 + i) * n];
                for (x, y) in c.iter_mut().zip(&u) {
                    *x -= s * y;
                }
            }
        }
    }
    a
}

/// The Householder vector `v` (`v₀ = 1`), `τ` and `β` with `(I − τvvᵀ)·x = β·e₁` (LAPACK
/// `dlarfg`, the norm computed on a scaled copy so that it neither overflows nor
/// underflows); `None` when `x` is already a multiple of `e₁`.
fn reflector(x: &[f64], v: &mut [f64]) -> Option<(f64, f64)> {
    let scale = x.iter().fold(0.0f64, |m, y| m.max(y.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    let tail = x[1..]
        .iter()
        .map(|y| (y / scale) * (y / scale))
        .sum::<f64>()
        .sqrt()
        * scale;
    if tail == 0.0 {
        return None;
    }
    let alpha = x[0];
    let beta = -alpha.signum() * alpha.hypot(tail);
    let tau = (beta - alpha) / beta;
    let d = alpha - beta;
    v[0] = 1.0;
    for (vi, xi) in v[1..].iter_mut().zip(&x[1..]) {
        *vi = xi / d;
    }
    Some((tau, beta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::system::hqr::hessenberg_eigenvalues;
    use num_complex::Complex64;

    fn random(n: usize, seed: f64) -> DMatrix<f64> {
        let mut x = seed;
        DMatrix::from_fn(n, n, |_, _| {
            x = (x * 997.0 + 0.123_456_789).fract();
            x - 0.5
        })
    }

    /// Every value of `a` has a distinct partner in `b` within `tol`.
    fn same_multiset(a: &[Complex64], b: &[Complex64], tol: f64) {
        assert_eq!(a.len(), b.len());
        let mut used = vec![false; b.len()];
        for z in a {
            let j = (0..b.len())
                .filter(|j| !used[*j])
                .min_by(|i, j| (b[*i] - z).norm().total_cmp(&(b[*j] - z).norm()))
                .unwrap();
            assert!((b[j] - z).norm() <= tol, "{z} vs {}", b[j]);
            used[j] = true;
        }
    }

    /// The form is upper Hessenberg, an orthogonal similarity (trace and Frobenius norm kept)
    /// and has the eigenvalues of nalgebra's Hessenberg form (both through `hqr`) and, on a
    /// matrix with known eigenvalues (`S·diag·S⁻¹`), those.
    #[test]
    fn hessenberg_form_is_an_orthogonal_similarity() {
        for (n, seed) in [(3, 0.31), (7, 0.11), (60, 0.42), (250, 0.77)] {
            let a = random(n, seed);
            let h = hessenberg_form(a.clone());
            for j in 0..n {
                for i in j + 2..n {
                    assert_eq!(h[(i, j)], 0.0);
                }
            }
            let scale = a.norm();
            assert!((h.trace() - a.trace()).abs() <= 1e-12 * scale * n as f64);
            assert!((h.norm() - a.norm()).abs() <= 1e-13 * scale * n as f64);
            let ours = hessenberg_eigenvalues(h).unwrap();
            let theirs = hessenberg_eigenvalues(nalgebra::linalg::Hessenberg::new(a).h()).unwrap();
            same_multiset(&ours, &theirs, 1e-9 * scale);
        }
        // Known eigenvalues 1..=40 under a well-conditioned similarity.
        let n = 40;
        let s = DMatrix::<f64>::identity(n, n) + random(n, 0.5) * 0.1;
        let d = DMatrix::from_diagonal(&nalgebra::DVector::from_fn(n, |i, _| (i + 1) as f64));
        let a = &s * d * s.clone().try_inverse().unwrap();
        let w = hessenberg_eigenvalues(hessenberg_form(a)).unwrap();
        let want: Vec<Complex64> = (1..=n).map(|k| Complex64::new(k as f64, 0.0)).collect();
        same_multiset(&w, &want, 1e-9 * n as f64);
    }
}
