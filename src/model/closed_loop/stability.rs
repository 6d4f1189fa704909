//! Internal stability of a feedback loop from right coprime factorizations, by exact root
//! computation of one polynomial.
//!
//! With `P = N D⁻¹` (`N` `p×m`, `D` `m×m`) and `K = N_k D_k⁻¹` (`N_k` `m×p`, `D_k` `p×p`), all
//! factors in RH∞, the loop `y = P u`, `u = r − K y` (Crowder & de Callafon, Sec. 2.2) is
//! internally stable iff
//!
//! ```text
//!     Λ = [  D    N_k ]
//!         [ −N    D_k ]
//! ```
//!
//! is a unit of RH∞ (Vidyasagar, *Control System Synthesis*, Sec. 5.1): writing `u = Dξ`,
//! `y = Nξ` and the controller as `e = D_k η`, `w = N_k η`, the loop equations with an
//! external input at each summing junction are `Λ·[ξ; η] = [r; d]`.  Λ has stable entries,
//! so it is a unit iff `det Λ` has no zero in `Re s ≥ 0` and `Λ(∞)` is invertible.
//!
//! For `m + p ≤ MAX_LOOP_SIZE`, `det Λ` is computed exactly as a polynomial: each row `i` is multiplied by the product
//! `q_i` of its entries' denominators (Hurwitz, since the entries are stable, so no zero is
//! added in the closed right half-plane), and the determinant of the resulting polynomial
//! matrix is expanded by cofactors.  Its roots come from the capped Aberth iteration.  A
//! unit `Λ` also proves that both factorizations are coprime (Λ⁻¹ stable gives the Bézout
//! identities), so a non-coprime pair shows up here as an "unstable" loop.  Larger loops
//! use the eigenvalues of the state matrix of a realization of `Λ⁻¹`
//! ([`super::stability_ss`]); [`check_loop_with`] picks the route explicitly.

use crate::system::{Polynomial, TfMatrix, TransferFunction};

/// Largest `m + p` of the exact polynomial route (cofactor expansion is `(m+p)!`); larger
/// loops go through the eigenvalues of a state-space realization of `Λ⁻¹`
/// ([`check_lambda`](super::check_lambda)).
pub const MAX_LOOP_SIZE: usize = 7;

/// Why a loop is not internally stable.
#[derive(Debug, Clone, PartialEq)]
pub enum LoopInstability {
    /// `det Λ` has zeros in `Re s ≥ 0` (closed-loop poles there), listed.
    RightHalfPlaneZeros(Vec<num_complex::Complex64>),
    /// `Λ(∞)` is singular: the loop is not well posed.
    IllPosed,
    /// The root computation did not converge within its cap.
    RootsDidNotConverge,
    /// The realization of `Λ` has more states than [`super::stability_ss::MAX_STATES`].
    TooLarge(usize),
}

impl std::fmt::Display for LoopInstability {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LoopInstability::RightHalfPlaneZeros(z) => {
                let list: Vec<String> = z
                    .iter()
                    .take(4)
                    .map(|s| format!("{:.4}{:+.4}j", s.re, s.im))
                    .collect();
                write!(
                    f,
                    "the closed loop has {} pole(s) in Re s ≥ 0 ({})",
                    z.len(),
                    list.join(", ")
                )
            }
            LoopInstability::IllPosed => {
                write!(f, "the loop is not well posed (I + P(∞)K(∞) singular)")
            }
            LoopInstability::RootsDidNotConverge => {
                write!(
                    f,
                    "the closed-loop poles could not be computed (root iteration cap)"
                )
            }
            LoopInstability::TooLarge(n) => write!(
                f,
                "the loop's realization has {n} states, more than the {} the stability check handles",
                super::stability_ss::MAX_STATES
            ),
        }
    }
}

fn poly_det(a: &[Vec<Polynomial>], rows: &[usize], cols: &[usize]) -> Polynomial {
    if rows.len() == 1 {
        return a[rows[0]][cols[0]].clone();
    }
    let r = rows[0];
    let mut acc = Polynomial::constant(0.0);
    for (k, &c) in cols.iter().enumerate() {
        if a[r][c].is_zero() {
            continue;
        }
        let sub_cols: Vec<usize> = cols.iter().copied().filter(|&x| x != c).collect();
        let minor = poly_det(a, &rows[1..], &sub_cols);
        let term = a[r][c].mul(&minor);
        acc = if k % 2 == 0 {
            acc.add(&term)
        } else {
            acc.add(&term.scale(-1.0))
        };
    }
    acc
}

/// `det` of a square matrix of transfer functions, up to the Hurwitz factor `Π q_i`:
/// returns the numerator polynomial `det(diag(q)·Λ)`.
pub fn scaled_determinant(lambda: &[Vec<TransferFunction>]) -> Polynomial {
    let n = lambda.len();
    let scaled: Vec<Vec<Polynomial>> = lambda
        .iter()
        .map(|row| {
            (0..row.len())
                .map(|j| {
                    row.iter()
                        .enumerate()
                        .filter(|(k, _)| *k != j)
                        .fold(row[j].num.clone(), |acc, (_, t)| acc.mul(&t.den))
                })
                .collect()
        })
        .collect();
    let idx: Vec<usize> = (0..n).collect();
    poly_det(&scaled, &idx, &idx)
}

fn neg(t: &TransferFunction) -> TransferFunction {
    TransferFunction {
        num: t.num.scale(-1.0),
        den: t.den.clone(),
    }
}

/// How [`check_loop_with`] finds the zeros of `det Λ` in `Re s ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopRoute {
    /// Exact polynomial `det Λ` for `m + p ≤ MAX_LOOP_SIZE`, state space beyond.
    Auto,
    /// The polynomial `det Λ` by cofactors and its roots (any size: `(m+p)!` cost).
    Polynomial,
    /// The eigenvalues of the state matrix of a realization of `Λ⁻¹`.
    StateSpace,
}

/// Checks that the loop of `P = N·D⁻¹` and `K = N_k·D_k⁻¹` (negative feedback) is
/// internally stable; see the module documentation.  The factors must be stable (checked by
/// the caller).
pub fn check_loop(
    n: &TfMatrix,
    d: &TfMatrix,
    n_k: &TfMatrix,
    d_k: &TfMatrix,
) -> Result<(), LoopInstability> {
    check_loop_with(n, d, n_k, d_k, LoopRoute::Auto)
}

/// [`check_loop`] by the given route.
pub fn check_loop_with(
    n: &TfMatrix,
    d: &TfMatrix,
    n_k: &TfMatrix,
    d_k: &TfMatrix,
    route: LoopRoute,
) -> Result<(), LoopInstability> {
    let (p, m) = (n.rows(), n.cols());
    let mut lambda: Vec<Vec<TransferFunction>> = Vec::with_capacity(m + p);
    for i in 0..m {
        let mut row: Vec<TransferFunction> = (0..m).map(|j| d.entry(i, j).clone()).collect();
        row.extend((0..p).map(|j| n_k.entry(i, j).clone()));
        lambda.push(row);
    }
    for i in 0..p {
        let mut row: Vec<TransferFunction> = (0..m).map(|j| neg(n.entry(i, j))).collect();
        row.extend((0..p).map(|j| d_k.entry(i, j).clone()));
        lambda.push(row);
    }
    // Λ(∞) invertible ⇔ well posed (relative test on the real matrix).
    let inf = nalgebra::DMatrix::from_fn(m + p, m + p, |i, j| lambda[i][j].at_infinity());
    let sv = inf.clone().svd(false, false).singular_values;
    let (smax, smin) = (sv.max(), sv.min());
    if smin.is_nan() || smin <= 1e-12 * smax.max(1e-300) {
        return Err(LoopInstability::IllPosed);
    }
    let state_space = match route {
        LoopRoute::Auto => m + p > MAX_LOOP_SIZE,
        LoopRoute::Polynomial => false,
        LoopRoute::StateSpace => true,
    };
    if state_space {
        return super::stability_ss::check_lambda(&lambda);
    }
    let det = scaled_determinant(&lambda);
    if det.is_zero() {
        return Err(LoopInstability::IllPosed);
    }
    let roots = det.roots_capped(500);
    if !roots.converged {
        return Err(LoopInstability::RootsDidNotConverge);
    }
    verdict(roots.roots)
}

/// The verdict from the closed-loop poles: a pole on the axis to working precision counts
/// as unstable, like one in the right half-plane.
pub(crate) fn verdict(
    poles: impl IntoIterator<Item = num_complex::Complex64>,
) -> Result<(), LoopInstability> {
    let bad: Vec<_> = poles
        .into_iter()
        .filter(|z| z.re >= -1e-10 * z.norm().max(1.0))
        .collect();
    if bad.is_empty() {
        Ok(())
    } else {
        Err(LoopInstability::RightHalfPlaneZeros(bad))
    }
}

/// True when every entry is proper with all poles strictly in the open left half-plane.
pub fn is_stable(m: &TfMatrix) -> bool {
    m.entries().iter().all(|t| {
        t.is_proper()
            && (t.num.is_zero() || {
                let r = t.den.roots_capped(500);
                r.converged && r.roots.iter().all(|p| p.re < -1e-10 * p.norm().max(1.0))
            })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tf(n: &[f64], d: &[f64]) -> TransferFunction {
        TransferFunction::new(n.to_vec(), d.to_vec())
    }
    fn one(t: TransferFunction) -> TfMatrix {
        TfMatrix::from_rows(vec![vec![t]]).unwrap()
    }

    #[test]
    fn siso_characteristic_polynomial() {
        // P = 1/(s−1) = N/D with N = 1/(s+1), D = (s−1)/(s+1); K = k (stable, (k, 1)).
        // Closed loop: s − 1 + k: stable iff k > 1.
        let n = one(tf(&[1.0], &[1.0, 1.0]));
        let d = one(tf(&[1.0, -1.0], &[1.0, 1.0]));
        let dk = one(tf(&[1.0], &[1.0]));
        assert!(check_loop(&n, &d, &one(tf(&[2.0], &[1.0])), &dk).is_ok());
        match check_loop(&n, &d, &one(tf(&[0.5], &[1.0])), &dk) {
            Err(LoopInstability::RightHalfPlaneZeros(z)) => {
                assert_eq!(z.len(), 1);
                assert!((z[0].re - 0.5).abs() < 1e-12 && z[0].im.abs() < 1e-12);
            }
            other => panic!("expected an unstable loop, got {other:?}"),
        }
        // k = 1: pole at s = 0, on the axis: not stable.
        assert!(check_loop(&n, &d, &one(tf(&[1.0], &[1.0])), &dk).is_err());
    }

    #[test]
    fn mimo_diagonal_loop_matches_channels() {
        // diag(1/(s−1), 1/(s−2)) with K = diag(3, 1.5): the second channel is unstable
        // (s − 2 + 1.5 = s − 0.5).
        let n = TfMatrix::diagonal(vec![tf(&[1.0], &[1.0, 1.0]), tf(&[1.0], &[1.0, 1.0])]);
        let d = TfMatrix::diagonal(vec![
            tf(&[1.0, -1.0], &[1.0, 1.0]),
            tf(&[1.0, -2.0], &[1.0, 1.0]),
        ]);
        let dk = TfMatrix::diagonal(vec![tf(&[1.0], &[1.0]), tf(&[1.0], &[1.0])]);
        let k_ok = TfMatrix::diagonal(vec![tf(&[3.0], &[1.0]), tf(&[3.0], &[1.0])]);
        let k_bad = TfMatrix::diagonal(vec![tf(&[3.0], &[1.0]), tf(&[1.5], &[1.0])]);
        assert!(check_loop(&n, &d, &k_ok, &dk).is_ok());
        match check_loop(&n, &d, &k_bad, &dk) {
            Err(LoopInstability::RightHalfPlaneZeros(z)) => {
                assert_eq!(z.len(), 1);
                assert!((z[0].re - 0.5).abs() < 1e-10);
            }
            other => panic!("expected an unstable loop, got {other:?}"),
        }
    }
}
