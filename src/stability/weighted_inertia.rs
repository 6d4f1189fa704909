//! The inertia of a small Hermitian matrix known up to an entry-wise error bound, decided
//! with the error weighted by the eigenvectors (issue 34 item 9, light damping): the
//! certified sweep's inertia tests ([`certified_norm`](super::certified_norm)) whose decisive
//! eigenvalue is far below the matrix's norm (`gap/γ²` next to a resonance damped 1e-4)
//! while the error of its entries is small where that eigenvector lives.
//!
//! Let `Q = Q̂ + E` be Hermitian with `|Eᵢⱼ| ≤ Fᵢⱼ`, `Q̂` the stored matrix. With `X` the
//! computed eigenvectors of `Q̂` and `C = fl(XᴴQ̂X)`,
//!
//! `XᴴQX = Λ + G`, `Λ = diag(Re Cᵢᵢ)`, `|Gᵢⱼ| ≤ Bᵢⱼ := |Cᵢⱼ|₍ᵢ≠ⱼ₎ + |Im Cᵢᵢ|₍ᵢ₌ⱼ₎ + (|X|ᵀ(c·u·|Q̂| + F)|X|)ᵢⱼ`
//!
//! (`c·u·|X|ᵀ|Q̂||X|` bounds the rounding of the two products, `|XᴴEX| ≤ |X|ᵀF|X|`). With
//! `D = diag(|Λᵢ|^(−1/2))`, `D·XᴴQX·D = sign(Λ) + DGD` and `‖DGD‖₂ ≤ ρ(DBD) ≤
//! maxᵢ Σⱼ Bᵢⱼ/√(|Λᵢ||Λⱼ|)`. When that is below 1 (we ask `1/2`, a margin for the rounding of
//! the test itself), every eigenvalue of `sign(Λ) + tDGD`, `t ∈ [0, 1]`, stays at distance
//! `≥ 1/2` from 0 (Weyl), so `XᴴQX` is nonsingular (hence `X` is) and by Sylvester's law of
//! inertia `Q` has as many negative (positive) eigenvalues as `Λ`. A bound applied row by
//! row in the eigenvector basis: an error of `Q̂`'s large entries enters only through the
//! small components the decisive eigenvector has there.

use nalgebra::DMatrix;
use num_complex::Complex64;

const U: f64 = f64::EPSILON / 2.0;

/// `(negative, positive)` eigenvalue counts of every Hermitian `Q` with `|Q − q| ≤ f`
/// entry-wise, or `None` when the bound does not decide (module docs).
pub(super) fn weighted_inertia(q: &DMatrix<Complex64>, f: &DMatrix<f64>) -> Option<(usize, usize)> {
    let n = q.nrows();
    if n == 0 || !q.iter().all(|z| z.re.is_finite() && z.im.is_finite()) {
        return None;
    }
    let x = q.clone().symmetric_eigen().eigenvectors;
    let c = x.adjoint() * q * &x;
    let xa = x.map(|z| z.norm());
    let weight = q.map(|z| z.norm()) * ((8.0 * n as f64 + 16.0) * U) + f;
    let b = xa.transpose() * weight * &xa;
    let lam: Vec<f64> = (0..n).map(|i| c[(i, i)].re).collect();
    if !lam.iter().all(|l| l.is_normal()) {
        return None;
    }
    let mut worst = 0.0f64;
    for i in 0..n {
        let mut row = 0.0;
        for j in 0..n {
            let off = if i == j {
                c[(i, i)].im.abs()
            } else {
                c[(i, j)].norm()
            };
            row += (off + b[(i, j)]) / (lam[i].abs() * lam[j].abs()).sqrt();
        }
        worst = worst.max(row);
    }
    if worst.is_nan() || worst >= 0.5 {
        return None;
    }
    let neg = lam.iter().filter(|l| **l < 0.0).count();
    Some((neg, n - neg))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Q = XΛXᴴ` with a known spectrum spread over 12 decades (a unitary `X` from a
    /// Householder reflector, computed independently of the eigensolver): the inertia is
    /// `Λ`'s while the entry-wise error stays below the small eigenvalue where its
    /// eigenvector lives, and undecided once the error could move it through 0.
    #[test]
    fn inertia_of_a_known_spectrum_and_its_limit() {
        let lam = [1.4e-3, -1.3e-3, 8.0e-15];
        // X = I − 2vvᴴ/‖v‖²: its last column is mostly e₃ (as the decisive eigenvector).
        let v = [
            Complex64::new(1e-3, 2e-4),
            Complex64::new(-5e-4, 1e-4),
            Complex64::new(1.0, 0.0),
        ];
        let vn2: f64 = v.iter().map(|z| z.norm_sqr()).sum();
        let x = DMatrix::from_fn(3, 3, |i, j| {
            let e = if i == j { 1.0 } else { 0.0 };
            Complex64::new(e, 0.0) - v[i] * v[j].conj() * (2.0 / vn2)
        });
        let l = DMatrix::from_fn(3, 3, |i, j| {
            Complex64::new(if i == j { lam[i] } else { 0.0 }, 0.0)
        });
        let q = &x * l * x.adjoint();
        // Errors of 1e-11 on the large entries (norm-wise: 1e-11 ≫ 8e-15) and 1e-18 on
        // the small corner.
        let mut f = DMatrix::from_element(3, 3, 1e-11);
        f[(2, 2)] = 1e-18;
        for k in 0..2 {
            f[(k, 2)] = 1e-16;
            f[(2, k)] = 1e-16;
        }
        assert_eq!(weighted_inertia(&q, &f), Some((1, 2)));
        let mut flipped = q.clone();
        for k in 0..3 {
            for m in 0..3 {
                flipped[(k, m)] -= x[(k, 2)] * x[(m, 2)].conj() * 1.6e-14;
            }
        }
        assert_eq!(weighted_inertia(&flipped, &f), Some((2, 1)));
        // An error on the corner as large as the eigenvalue: no verdict.
        f[(2, 2)] = 1e-14;
        assert_eq!(weighted_inertia(&q, &f), None);
    }
}
