//! Small dense linear-algebra helpers: extreme singular values with closed forms for the
//! 1×1 and 2×2 cases that dominate SISO and two-channel data (the general case uses the SVD).

use nalgebra::DMatrix;
use num_complex::Complex64;

/// Largest and smallest singular values `(σ_max, σ_min)` of a complex matrix
/// (`σ_min` is the `min(rows, cols)`-th singular value).
///
/// For 2×2 matrices: `σ_max² + σ_min² = ‖A‖_F²` and `σ_max·σ_min = |det A|`, so
/// `σ_max = √((F² + √(F⁴ − 4|det|²))/2)` and `σ_min = |det|/σ_max`, free of cancellation.
pub fn extreme_singular_values(a: &DMatrix<Complex64>) -> (f64, f64) {
    match (a.nrows(), a.ncols()) {
        (1, 1) => {
            let s = a[(0, 0)].norm();
            (s, s)
        }
        (2, 2) => {
            let f2: f64 = a.iter().map(|z| z.norm_sqr()).sum();
            let det = (a[(0, 0)] * a[(1, 1)] - a[(0, 1)] * a[(1, 0)]).norm();
            let disc = (f2 * f2 - 4.0 * det * det).max(0.0).sqrt();
            let smax = ((f2 + disc) / 2.0).sqrt();
            let smin = if smax > 0.0 { det / smax } else { 0.0 };
            (smax, smin)
        }
        _ if diagonal_fast_path(a) => {
            // The singular values of a square diagonal matrix are the moduli of its entries
            // (a physical model's M̃ is diagonal: one row per mode); no O(n³) SVD.
            extreme_moduli(a.diagonal().iter().copied())
        }
        _ => {
            let sv = a.clone().svd(false, false).singular_values;
            (sv.max(), sv.min())
        }
    }
}

/// Size from which the diagonal fast paths (σ of a diagonal `M̃`, its solves, Theorem 4's
/// low-rank μ search) are taken.  Below it the dense factorizations cost microseconds, and
/// the shipped 5-mode robot keeps its dense arithmetic: its fitted `r` (and `α*`) moves with
/// the envelope's last bits (docs/internals-fit-speed.md).
pub const DIAGONAL_FROM: usize = 8;

/// True when the diagonal fast paths apply to `a`: at least [`DIAGONAL_FROM`] rows, and
/// diagonal ([`is_diagonal`]).
pub fn diagonal_fast_path(a: &DMatrix<Complex64>) -> bool {
    a.nrows() >= DIAGONAL_FROM && is_diagonal(a)
}

/// `(max, min)` of the moduli of `values` (the singular values of a diagonal matrix); both
/// NaN when one modulus is.
pub fn extreme_moduli(values: impl IntoIterator<Item = Complex64>) -> (f64, f64) {
    let (mut max, mut min) = (0.0f64, f64::INFINITY);
    for z in values {
        let v = z.norm();
        if v.is_nan() {
            return (f64::NAN, f64::NAN);
        }
        max = max.max(v);
        min = min.min(v);
    }
    (max, min)
}

/// True when `a` is square with every off-diagonal entry exactly zero.
pub fn is_diagonal(a: &DMatrix<Complex64>) -> bool {
    a.is_square()
        && a.column_iter().enumerate().all(|(j, col)| {
            col.iter()
                .enumerate()
                .all(|(i, z)| i == j || *z == Complex64::default())
        })
}

/// Relative threshold under which the smallest singular value counts as zero.
pub const SINGULAR_RTOL: f64 = 1e-13;

/// True when a matrix with extreme singular values `(σ_max, σ_min)` is singular to working
/// precision (`σ_min ≤ 1e-13·σ_max`, or non-finite values).
pub fn is_singular((max, min): (f64, f64)) -> bool {
    !max.is_finite() || min.is_nan() || min <= SINGULAR_RTOL * max
}

/// Spectral norm `σ_max` of a complex matrix; 1×k, k×1 and 2×k/k×2 shapes use the Gram
/// matrix of the short side in closed form.
pub fn spectral_norm(a: &DMatrix<Complex64>) -> f64 {
    let (r, c) = (a.nrows(), a.ncols());
    if r == 1 || c == 1 {
        return a.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    }
    if r == 2 || c == 2 {
        // G = A A^* (if r = 2) or A^* A (if c = 2): a 2×2 Hermitian matrix.
        let (g00, g11, g01) = if r == 2 {
            let (mut g00, mut g11, mut g01) = (0.0, 0.0, Complex64::new(0.0, 0.0));
            for j in 0..c {
                g00 += a[(0, j)].norm_sqr();
                g11 += a[(1, j)].norm_sqr();
                g01 += a[(0, j)] * a[(1, j)].conj();
            }
            (g00, g11, g01)
        } else {
            let (mut g00, mut g11, mut g01) = (0.0, 0.0, Complex64::new(0.0, 0.0));
            for i in 0..r {
                g00 += a[(i, 0)].norm_sqr();
                g11 += a[(i, 1)].norm_sqr();
                g01 += a[(i, 0)].conj() * a[(i, 1)];
            }
            (g00, g11, g01)
        };
        let half = 0.5 * (g00 - g11);
        let lmax = 0.5 * (g00 + g11) + (half * half + g01.norm_sqr()).sqrt();
        return lmax.max(0.0).sqrt();
    }
    a.clone().svd(false, false).singular_values.max()
}

/// Scales every column of `a` to unit 2-norm in place and returns the scales `s_j` (so the
/// scaled matrix is `A S⁻¹`, and `x = S⁻¹ x̃` undoes it): the column equilibration before a
/// least-squares QR, which keeps parameters of very different units from hiding a small
/// pivot.  A zero column keeps a tiny positive scale instead of dividing by zero.
pub(crate) fn equilibrate_columns(a: &mut DMatrix<f64>) -> Vec<f64> {
    let scale: Vec<f64> = (0..a.ncols())
        .map(|j| a.column(j).norm().max(f64::MIN_POSITIVE))
        .collect();
    for (j, s) in scale.iter().enumerate() {
        a.column_mut(j).scale_mut(1.0 / s);
    }
    scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms_match_svd() {
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for (r, c) in [(2, 2), (2, 3), (3, 2), (1, 4), (4, 1), (2, 5)] {
            for _ in 0..50 {
                let a = DMatrix::from_fn(r, c, |_, _| Complex64::new(rnd(), rnd()));
                let sv = a.clone().svd(false, false).singular_values;
                assert!((spectral_norm(&a) - sv.max()).abs() < 1e-12 * sv.max());
                if r == c {
                    let (smax, smin) = extreme_singular_values(&a);
                    assert!((smax - sv.max()).abs() < 1e-12 * sv.max());
                    assert!((smin - sv.min()).abs() < 1e-11 * sv.max());
                }
            }
        }
    }
}
