//! Dense inverse of a general real matrix by a recursive (blocked) LU factorization with
//! partial pivoting (Toledo 1997; the same factorization as LAPACK `getrf`) and recursive
//! triangular solves, so that almost all the work is matrix–matrix products. This is the
//! kernel of the matrix sign iterations of the Riccati and Lyapunov solvers, where
//! nalgebra's level-2 LU and column-by-column triangular solves dominated the run time.

use nalgebra::DMatrix;

/// Below this size the factorization and the solves are unblocked.
const NB: usize = 32;

/// In-place LU with partial pivoting of an `m × n` matrix (`m ≥ n`): on return `a` holds
/// the unit lower factor below the diagonal and the upper factor on and above it, and at
/// step `j` row `j` was swapped with row `piv[j]`. Returns `false` on a zero or non-finite
/// pivot (a singular matrix).
fn getrf(a: &mut DMatrix<f64>, piv: &mut [usize]) -> bool {
    let (m, n) = a.shape();
    if n <= NB {
        for j in 0..n {
            let mut p = j;
            let mut best = a[(j, j)].abs();
            for i in j + 1..m {
                let v = a[(i, j)].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if best == 0.0 || !best.is_finite() {
                return false;
            }
            piv[j] = p;
            if p != j {
                a.swap_rows(j, p);
            }
            let data = a.as_mut_slice();
            let (left, right) = data.split_at_mut((j + 1) * m);
            let colj = &mut left[j * m..];
            let d = colj[j];
            for v in &mut colj[j + 1..m] {
                *v /= d;
            }
            for colk in right.chunks_exact_mut(m) {
                let f = colk[j];
                if f != 0.0 {
                    for (x, l) in colk[j + 1..m].iter_mut().zip(&colj[j + 1..m]) {
                        *x -= l * f;
                    }
                }
            }
        }
        return true;
    }
    let n1 = n / 2;
    let mut left = a.columns(0, n1).into_owned();
    if !getrf(&mut left, &mut piv[..n1]) {
        return false;
    }
    let mut right = a.columns(n1, n - n1).into_owned();
    for (j, &p) in piv[..n1].iter().enumerate() {
        if p != j {
            right.swap_rows(j, p);
        }
    }
    let mut a12 = right.rows(0, n1).into_owned();
    trsm_lower_unit(&left.rows(0, n1).into_owned(), &mut a12);
    let mut a22 = right.rows(n1, m - n1).into_owned();
    a22.gemm(-1.0, &left.rows(n1, m - n1), &a12, 1.0);
    if !getrf(&mut a22, &mut piv[n1..]) {
        return false;
    }
    let mut l21 = left.rows(n1, m - n1).into_owned();
    for (j, p) in piv[n1..].iter_mut().enumerate() {
        if *p != j {
            l21.swap_rows(j, *p);
        }
        *p += n1;
    }
    a.view_mut((0, 0), (n1, n1)).copy_from(&left.rows(0, n1));
    a.view_mut((n1, 0), (m - n1, n1)).copy_from(&l21);
    a.view_mut((0, n1), (n1, n - n1)).copy_from(&a12);
    a.view_mut((n1, n1), (m - n1, n - n1)).copy_from(&a22);
    true
}

/// `B ← L⁻¹B` for the unit lower triangle of `l` (its upper part is ignored).
fn trsm_lower_unit(l: &DMatrix<f64>, b: &mut DMatrix<f64>) {
    let n = l.nrows();
    if n <= NB {
        for mut col in b.column_iter_mut() {
            for j in 0..n {
                let x = col[j];
                if x != 0.0 {
                    for i in j + 1..n {
                        col[i] -= l[(i, j)] * x;
                    }
                }
            }
        }
        return;
    }
    let n1 = n / 2;
    let r = b.ncols();
    let mut b1 = b.rows(0, n1).into_owned();
    trsm_lower_unit(&l.view((0, 0), (n1, n1)).into_owned(), &mut b1);
    let mut b2 = b.rows(n1, n - n1).into_owned();
    b2.gemm(-1.0, &l.view((n1, 0), (n - n1, n1)), &b1, 1.0);
    trsm_lower_unit(&l.view((n1, n1), (n - n1, n - n1)).into_owned(), &mut b2);
    b.view_mut((0, 0), (n1, r)).copy_from(&b1);
    b.view_mut((n1, 0), (n - n1, r)).copy_from(&b2);
}

/// `B ← U⁻¹B` for the upper triangle of `u` (its strictly lower part is ignored).
fn trsm_upper(u: &DMatrix<f64>, b: &mut DMatrix<f64>) {
    let n = u.nrows();
    if n <= NB {
        for mut col in b.column_iter_mut() {
            for j in (0..n).rev() {
                let x = col[j] / u[(j, j)];
                col[j] = x;
                if x != 0.0 {
                    for i in 0..j {
                        col[i] -= u[(i, j)] * x;
                    }
                }
            }
        }
        return;
    }
    let n1 = n / 2;
    let r = b.ncols();
    let mut b2 = b.rows(n1, n - n1).into_owned();
    trsm_upper(&u.view((n1, n1), (n - n1, n - n1)).into_owned(), &mut b2);
    let mut b1 = b.rows(0, n1).into_owned();
    b1.gemm(-1.0, &u.view((0, n1), (n1, n - n1)), &b2, 1.0);
    trsm_upper(&u.view((0, 0), (n1, n1)).into_owned(), &mut b1);
    b.view_mut((0, 0), (n1, r)).copy_from(&b1);
    b.view_mut((n1, 0), (n - n1, r)).copy_from(&b2);
}

/// The inverse of a square matrix with `ln|det|` (from the LU factors), or `None` when a
/// pivot is zero or not finite (singular matrix) or the inverse has a non-finite entry.
pub fn inverse_with_logdet(z: &DMatrix<f64>) -> Option<(DMatrix<f64>, f64)> {
    let n = z.nrows();
    assert_eq!(n, z.ncols(), "inverse of a non-square matrix");
    let mut a = z.clone();
    let mut piv = vec![0; n];
    if !getrf(&mut a, &mut piv) {
        return None;
    }
    let logdet = a.diagonal().iter().map(|u| u.abs().ln()).sum();
    let mut x = DMatrix::identity(n, n);
    for (j, &p) in piv.iter().enumerate() {
        if p != j {
            x.swap_rows(j, p);
        }
    }
    trsm_lower_unit(&a, &mut x);
    trsm_upper(&a, &mut x);
    x.iter().all(|v| v.is_finite()).then_some((x, logdet))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_nalgebra_inverse_and_determinant() {
        // Sizes below, at and well above the block size, with pivoting forced by a
        // zero leading entry; checked against nalgebra's LU (an independent code path).
        for n in [1, 5, 32, 33, 100, 157] {
            let mut state = 0x2545_f491_4f6c_dd1d_u64 ^ n as u64;
            let mut z = DMatrix::from_fn(n, n, |_, _| {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            });
            if n > 1 {
                z[(0, 0)] = 0.0;
            }
            let (inv, logdet) = inverse_with_logdet(&z).unwrap();
            let reference = z.clone().try_inverse().unwrap();
            let err = (&inv - &reference).norm() / reference.norm();
            assert!(err < 1e-10, "n={n}: {err:e}");
            let id_err = (&z * &inv - DMatrix::<f64>::identity(n, n)).norm();
            assert!(id_err < 1e-9, "n={n}: {id_err:e}");
            let det = z.clone().lu().determinant();
            assert!((logdet - det.abs().ln()).abs() < 1e-9 * logdet.abs().max(1.0));
        }
    }

    #[test]
    fn singular_matrix_is_rejected() {
        let mut z = DMatrix::from_fn(70, 70, |i, j| {
            if j == 40 {
                0.0
            } else {
                (i * j % 11) as f64 + (i == j) as u8 as f64
            }
        });
        assert!(inverse_with_logdet(&z).is_none());
        z.column_mut(40).fill(1.0);
        z[(3, 3)] = f64::NAN;
        assert!(inverse_with_logdet(&z).is_none());
    }
}
