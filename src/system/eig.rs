//! Eigenvalues of real matrices through the real Schur form, always with an iteration cap
//! (nalgebra's uncapped `schur()` can hang; docs/design/lessons.md, crate notes).

use crate::error::{Error, Result};
use crate::system::hqr::hessenberg_eigenvalues;
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
    // nalgebra deflates a subdiagonal entry only below `eps·(|h_ii| + |h_{i+1,i+1}|)`; with
    // `eps` = one ulp, clusters of equal eigenvalues (a scalar weight repeated on every
    // channel, times a system with the same pole) can cycle forever. A few ulps more
    // (LAPACK's criterion is of that order) converges and keeps the backward error at
    // that level.
    // Failing that, the same on exact similarities of `A` (a diagonal balancing by powers
    // of two, then a fixed Householder reflection): the eigenvalues are the same, the
    // iteration's path is not.
    // The similarities are built only when the plain attempt fails (this is on the H∞
    // iteration's path, where a large Hamiltonian's extra products would cost every call).
    // Between the two, LAPACK's eigenvalue-only iteration (`hqr`), which converges where
    // nalgebra's stalls (the robot's weighted H∞ loop, issue 34).
    let schur_of = |m: &DMatrix<f64>| {
        DEFLATION_ULPS.iter().find_map(|ulps| {
            nalgebra::linalg::Schur::try_new(m.clone(), ulps * f64::EPSILON, MAX_SWEEPS)
                .map(|s| s.complex_eigenvalues().iter().copied().collect::<Vec<_>>())
        })
    };
    // The eigenvalue-only Francis iteration of `hqr` on the balanced Hessenberg form: no
    // Schur vectors, so about twice as fast as nalgebra's Schur form from a few hundred
    // states on (1600 × 1600: 21 s against 46 s, release, loaded), and it converges on the
    // clustered spectra where nalgebra's iteration stalls (see `hqr`).
    let francis = |m: &DMatrix<f64>| {
        let balanced = apply_balancing(m, &balancing(m));
        hessenberg_eigenvalues(nalgebra::linalg::Hessenberg::new(balanced).h())
            .filter(|w| w.iter().all(|z| z.re.is_finite() && z.im.is_finite()))
    };
    let first = if n >= FRANCIS_FIRST_FROM {
        francis(a).or_else(|| schur_of(a))
    } else {
        schur_of(a).or_else(|| francis(a))
    };
    let eigs = first.or_else(|| {
        let balanced = apply_balancing(a, &balancing(a));
        schur_of(&balanced).or_else(|| {
            let n = a.nrows();
            let v = nalgebra::DVector::from_fn(n, |i, _| {
                ((i as f64 + 1.0) * 0.754_877_666_246_692_7).fract() - 0.5
            });
            let v = &v / v.norm();
            let h = DMatrix::identity(n, n) - (&v * v.transpose()) * 2.0;
            schur_of(&(&h * &balanced * &h))
        })
    });
    eigs.ok_or_else(|| {
        Error::numerical(
            what,
            format!("the eigenvalue (Schur) iteration did not converge in {MAX_SWEEPS} sweeps"),
        )
    })
}

/// From this size on the eigenvalue-only iteration (`hqr`) is tried first (it is faster);
/// below it nalgebra's Schur form is, so small models keep the figures they always had.
const FRANCIS_FIRST_FROM: usize = 200;

/// Deflation tolerances tried in turn, in units of `f64::EPSILON`.
const DEFLATION_ULPS: [f64; 3] = [1.0, 8.0, 64.0];

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
    fn cluster_of_equal_eigenvalues_converges() {
        // Found by a random search: four copies of −1 (a weight 1/(s + 1) on four
        // channels) above a block with the eigenvalue −1 too; nalgebra's Schur iteration
        // with a one-ulp deflation tolerance does not converge on it.
        let a = DMatrix::from_column_slice(
            7,
            7,
            &[
                -1.0,
                0.0,
                0.0,
                0.0,
                -0.2381798125540424,
                1.6303181473403892,
                -1.4494677199642036,
                0.0,
                -1.0,
                0.0,
                0.0,
                -0.4801095731488747,
                1.9204048193658174,
                1.6673669598166971,
                0.0,
                0.0,
                -1.0,
                0.0,
                -1.7165377346857165,
                0.6305529622950821,
                0.9145140886880374,
                0.0,
                0.0,
                0.0,
                -1.0,
                1.1856837761171448,
                -0.25858827648991634,
                0.3524530583564345,
                0.0,
                0.0,
                0.0,
                0.0,
                -0.4921160469739889,
                -0.8823026074761677,
                0.7224103831131576,
                0.0,
                0.0,
                0.0,
                0.0,
                0.5038421783213738,
                -2.17974365429053,
                1.864621858719124,
                0.0,
                0.0,
                0.0,
                0.0,
                -1.4964098332525753,
                1.4513133144242634,
                1.2010095047577538,
            ],
        );
        assert!(nalgebra::linalg::Schur::try_new(a.clone(), f64::EPSILON, 1000).is_none());
        let e = eigenvalues(&a, "test").unwrap();
        assert_eq!(e.len(), 7);
        // Independent check: the eigenvalues of the lower 3×3 block and four times −1,
        // matched through det(λI − A) ≈ 0 relative to the scale, and the trace.
        let tr: f64 = (0..7).map(|i| a[(i, i)]).sum();
        let sum: Complex64 = e.iter().sum();
        assert!(
            (sum.re - tr).abs() < 1e-10 && sum.im.abs() < 1e-10,
            "{sum} vs {tr}"
        );
        let low = a.view((4, 4), (3, 3)).into_owned();
        let mut want: Vec<Complex64> = low.complex_eigenvalues().iter().copied().collect();
        want.extend([Complex64::new(-1.0, 0.0); 4]);
        for w in &want {
            let near = e
                .iter()
                .map(|z| (z - w).norm())
                .fold(f64::INFINITY, f64::min);
            // −1 is an eigenvalue of multiplicity five (possibly defective): allow more
            // than ε.
            assert!(near < 1e-6, "{w} not found in {e:?}");
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
