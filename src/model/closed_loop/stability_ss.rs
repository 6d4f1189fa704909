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
//! minimal.  Eigenvalues come from nalgebra's real Schur form with a capped iteration
//! (`try_new`), after a diagonal balancing of `A_×`.

use super::stability::LoopInstability;
use crate::system::{StateSpace, TransferFunction};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Largest number of states of the realization of `Λ` accepted.
pub const MAX_STATES: usize = 1500;

/// Entry-by-entry realization `(A, B, C, D)` of a square matrix of proper transfer
/// functions (block-diagonal `A`, not minimal in general).
pub fn realize(lambda: &[Vec<TransferFunction>]) -> StateSpace {
    let n = lambda.len();
    let parts: Vec<(usize, usize, StateSpace)> = lambda
        .iter()
        .enumerate()
        .flat_map(|(i, row)| {
            row.iter()
                .enumerate()
                .map(move |(j, t)| (i, j, StateSpace::from_tf(t)))
        })
        .collect();
    let states: usize = parts.iter().map(|(_, _, s)| s.a.nrows()).sum();
    let mut a = DMatrix::zeros(states, states);
    let mut b = DMatrix::zeros(states, n);
    let mut c = DMatrix::zeros(n, states);
    let mut d = DMatrix::zeros(n, n);
    let mut k = 0;
    for (i, j, s) in &parts {
        d[(*i, *j)] = s.d[(0, 0)];
        let ns = s.a.nrows();
        if ns == 0 || s.c.iter().all(|x| *x == 0.0) {
            // A zero strictly proper part needs no states.
            continue;
        }
        a.view_mut((k, k), (ns, ns)).copy_from(&s.a);
        b.view_mut((k, *j), (ns, 1)).copy_from(&s.b);
        c.view_mut((*i, k), (1, ns)).copy_from(&s.c);
        k += ns;
    }
    StateSpace {
        a: a.view((0, 0), (k, k)).into_owned(),
        b: b.rows(0, k).into_owned(),
        c: c.columns(0, k).into_owned(),
        d,
    }
}

/// Eigenvalues of a real square matrix by a balanced, capped real Schur form; `None` when
/// the iteration does not converge within its cap.
pub fn eigenvalues(m: &DMatrix<f64>) -> Option<Vec<Complex64>> {
    let n = m.nrows();
    if n == 0 {
        return Some(Vec::new());
    }
    // Diagonal balancing (Parlett–Reinsch, powers of 2, capped): companion blocks mix
    // coefficients of very different sizes.
    let mut a = m.clone();
    for _ in 0..50 {
        let mut done = true;
        for i in 0..n {
            let c: f64 = (0..n).filter(|&k| k != i).map(|k| a[(k, i)].abs()).sum();
            let r: f64 = (0..n).filter(|&k| k != i).map(|k| a[(i, k)].abs()).sum();
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let mut f = 1.0;
            let (mut cc, mut rr) = (c, r);
            while cc < rr / 2.0 {
                cc *= 2.0;
                rr /= 2.0;
                f *= 2.0;
            }
            while cc >= rr * 2.0 {
                cc /= 2.0;
                rr *= 2.0;
                f /= 2.0;
            }
            if (cc + rr) < 0.95 * (c + r) {
                done = false;
                for k in 0..n {
                    a[(k, i)] *= f;
                    a[(i, k)] /= f;
                }
            }
        }
        if done {
            break;
        }
    }
    let schur = nalgebra::Schur::try_new(a, f64::EPSILON, 100 * n.max(10))?;
    let ev: Vec<Complex64> = schur
        .complex_eigenvalues()
        .iter()
        .map(|z| Complex64::new(z.re, z.im))
        .collect();
    ev.iter().all(|z| z.is_finite()).then_some(ev)
}

/// Internal stability of the loop whose `Λ` is given (rows of transfer functions), by the
/// eigenvalues of the state matrix of `Λ⁻¹` (module docs).  `Λ(∞)` must be invertible
/// (checked by the caller).
pub fn check_lambda(lambda: &[Vec<TransferFunction>]) -> Result<(), LoopInstability> {
    let ss = realize(lambda);
    let k = ss.a.nrows();
    if k > MAX_STATES {
        return Err(LoopInstability::TooLarge(k));
    }
    let a_cross = match ss.d.clone().lu().solve(&ss.c) {
        Some(x) => &ss.a - &ss.b * x,
        None => return Err(LoopInstability::IllPosed),
    };
    let ev = eigenvalues(&a_cross).ok_or(LoopInstability::RootsDidNotConverge)?;
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
