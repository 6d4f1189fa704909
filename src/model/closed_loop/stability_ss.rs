//! Internal stability of large loops (`m + p` beyond the exact polynomial route of
//! [`super::stability`]) from a state-space realization of `Λ` and the eigenvalues of its
//! inverse's state matrix.
//!
//! `Λ = [[D, N_k], [−N, D_k]]` (see [`super::stability`]) has stable proper entries.
//! Realize it entry by entry (controllable canonical form of each entry, block-diagonal
//! `A`): `Λ = C(sI − A)⁻¹B + Λ(∞)`, with `A` Hurwitz because every entry is stable.  When
//! `Λ(∞)` is invertible, `Λ⁻¹` has the realization
//! `(A − BΛ(∞)⁻¹C, BΛ(∞)⁻¹, −Λ(∞)⁻¹C, Λ(∞)⁻¹)`.  Its state matrix `A_× = A − BΛ(∞)⁻¹C`
//! has as eigenvalues the poles of `Λ⁻¹` plus the uncontrollable or unobservable modes of
//! `(A, B, C)` (output injection leaves them in place), which are eigenvalues of `A` and so
//! lie in `Re s < 0`.  Hence `Λ` is a unit of RH∞ (the loop is internally stable) iff
//! every eigenvalue of `A_×` lies in `Re s < 0`, and the eigenvalues of `A_×` in
//! `Re s ≥ 0` are exactly the closed-loop poles there.  The realization need not be
//! minimal.  The realization is [`StateSpace::from_tf_matrix`] (one controllable-canonical
//! block per entry); the eigenvalues come from [`eig::eigenvalues`] (real Schur form with a
//! capped iteration) after a diagonal balancing of `A_×`.

use super::stability::LoopInstability;
use crate::system::{eig, StateSpace, TfMatrix, TransferFunction};
use num_complex::Complex64;

/// Largest number of states of the realization of `Λ` accepted.
pub const MAX_STATES: usize = 1500;

/// Internal stability of the loop whose `Λ` is given (rows of transfer functions), by the
/// eigenvalues of the state matrix of `Λ⁻¹` (module docs).  `Λ(∞)` must be invertible
/// (checked by the caller).
pub fn check_lambda(lambda: &[Vec<TransferFunction>]) -> Result<(), LoopInstability> {
    let rows = lambda.to_vec();
    let ss =
        StateSpace::from_tf_matrix(&TfMatrix::from_rows(rows).ok_or(LoopInstability::IllPosed)?);
    let k = ss.a.nrows();
    if k > MAX_STATES {
        return Err(LoopInstability::TooLarge(k));
    }
    let a_cross = match ss.d.clone().lu().solve(&ss.c) {
        Some(x) => &ss.a - &ss.b * x,
        None => return Err(LoopInstability::IllPosed),
    };
    // Diagonal balancing first: companion blocks mix coefficients of very different sizes.
    let balanced = eig::apply_balancing(&a_cross, &eig::balancing(&a_cross));
    let ev = eig::eigenvalues(&balanced, "closed-loop poles")
        .map_err(|_| LoopInstability::RootsDidNotConverge)?;
    let bad: Vec<Complex64> = ev
        .into_iter()
        .filter(|z| z.re >= -1e-10 * z.norm().max(1.0))
        .collect();
    if bad.is_empty() {
        Ok(())
    } else {
        Err(LoopInstability::RightHalfPlaneZeros(bad))
    }
}
