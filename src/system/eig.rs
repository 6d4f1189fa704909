//! Eigenvalues of real matrices through the real Schur form, always with an iteration cap
//! (nalgebra's uncapped `schur()` can hang; see the design notes).

use crate::error::{Error, Result};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Cap on the QR sweeps of the Schur iteration (nalgebra counts them per matrix).
const MAX_SWEEPS: usize = 100_000;

/// Diagonal balancing (Parlett & Reinsch 1969, as LAPACK `gebal` without permutations):
/// powers of two `d` such that `D⁻¹AD` has rows and columns of comparable norms. The
/// similarity is exact in floating point; it makes eigenvalues and the Hessenberg
/// reduction accurate for realizations with widely spread entries (companion forms).
pub fn balancing(a: &DMatrix<f64>) -> Vec<f64> {
    let n = a.nrows();
    let mut m = a.clone();
    let mut d = vec![1.0; n];
    for _ in 0..100 {
        let mut converged = true;
        for i in 0..n {
            let mut c = 0.0;
            let mut r = 0.0;
            for j in 0..n {
                if j != i {
                    c += m[(j, i)].abs();
                    r += m[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 || !(c.is_finite() && r.is_finite()) {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let mut cc = c;
            let mut rr = r;
            while cc < rr / 2.0 {
                f *= 2.0;
                cc *= 2.0;
                rr /= 2.0;
            }
            while cc >= rr * 2.0 {
                f /= 2.0;
                cc /= 2.0;
                rr *= 2.0;
            }
            if cc + rr < 0.95 * s {
                converged = false;
                d[i] *= f;
                for j in 0..n {
                    m[(j, i)] *= f;
                    m[(i, j)] /= f;
                }
            }
        }
        if converged {
            break;
        }
    }
    d
}

/// `D⁻¹AD` for the diagonal `d` of [`balancing`].
pub fn apply_balancing(a: &DMatrix<f64>, d: &[f64]) -> DMatrix<f64> {
    DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] * d[j] / d[i])
}

/// All eigenvalues of a real square matrix (real Schur form, Francis double-shift QR with a
/// sweep cap). Fails with a one-line error when the iteration does not converge.
pub fn eigenvalues(a: &DMatrix<f64>, what: &str) -> Result<Vec<Complex64>> {
    let n = a.nrows();
    if n == 0 {
        return Ok(Vec::new());
    }
    if a.iter().any(|x| !x.is_finite()) {
        return Err(Error::Invalid(format!(
            "{what}: the matrix has a non-finite entry"
        )));
    }
    let schur =
        nalgebra::linalg::Schur::try_new(a.clone(), f64::EPSILON, MAX_SWEEPS).ok_or_else(|| {
            Error::Invalid(format!(
                "{what}: the eigenvalue (Schur) iteration did not converge in {MAX_SWEEPS} sweeps"
            ))
        })?;
    Ok(schur.complex_eigenvalues().iter().copied().collect())
}

/// Largest real part of the eigenvalues (the spectral abscissa).
pub fn spectral_abscissa(eigs: &[Complex64]) -> f64 {
    eigs.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn companion_of_s10_minus_1_converges() {
        // The matrix on which nalgebra's uncapped schur() hangs (issues #611, #764).
        let mut a = DMatrix::zeros(10, 10);
        a[(0, 9)] = 1.0;
        for i in 1..10 {
            a[(i, i - 1)] = 1.0;
        }
        match eigenvalues(&a, "test") {
            Ok(e) => {
                assert_eq!(e.len(), 10);
                for z in e {
                    assert!((z.norm() - 1.0).abs() < 1e-8, "{z}");
                }
            }
            Err(e) => assert!(e.to_string().contains("did not converge")),
        }
    }

    #[test]
    fn oscillator_eigenvalues() {
        let (w, z) = (3.0, 1e-4);
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -w * w, -2.0 * z * w]);
        let e = eigenvalues(&a, "test").unwrap();
        for l in e {
            assert!((l.re + z * w).abs() < 1e-12);
            assert!((l.im.abs() - w * (1.0 - z * z).sqrt()).abs() < 1e-12);
        }
    }
}
