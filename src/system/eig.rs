//! Eigenvalues of real matrices through the real Schur form, always with an iteration cap
//! (nalgebra's uncapped `schur()` can hang; see the design notes).

use crate::error::{Error, Result};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Cap on the QR sweeps of the Schur iteration (nalgebra counts them per matrix).
const MAX_SWEEPS: usize = 100_000;

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
