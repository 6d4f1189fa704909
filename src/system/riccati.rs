//! Continuous-time algebraic Riccati and Lyapunov equations.
//!
//! `AᵀX + XA − XGX + Q = 0` (G, Q symmetric positive semidefinite) is solved for its
//! **stabilizing** solution (A − GX Hurwitz) by the matrix sign function of the Hamiltonian
//! `H = [A  −G; −Q  −Aᵀ]` (Roberts 1971; determinant scaling of Byers 1987): the stable
//! invariant subspace is the null space of `sign(H) + I`, and `X` solves the overdetermined
//! system `[W₁₂; W₂₂ + I]·X = −[W₁₁ + I; W₂₁]` (by QR). The solution is then refined by
//! Newton–Kleinman steps (Kleinman 1968), each a Lyapunov equation solved again by the sign
//! function, and then by steps whose residual is computed in twice the precision
//! ([`super::compensated`]), which buys forward accuracy on ill-conditioned equations.
//! Every iteration is capped; the residual and the stabilizing property are checked
//! after the fact, and a failure is an error, never a silent wrong solution.

use super::compensated::{product_pair, Dot2};
use super::dense_inverse::inverse_with_logdet;
use super::eig::{eigenvalues, spectral_abscissa};
use crate::error::{Error, Result};
use nalgebra::DMatrix;

/// Cap on sign-function (Newton) iterations.
const MAX_SIGN_ITER: usize = 100;
/// Cap on Newton–Kleinman refinement steps.
const MAX_NEWTON_STEPS: usize = 6;
/// Cap on refinement steps with the residual in twice the precision.
const MAX_REFINE_STEPS: usize = 3;
/// Largest accepted relative residual.
const RESIDUAL_TOL: f64 = 1e-8;

/// The stabilizing solution of a Riccati equation with its checks.
#[derive(Debug, Clone)]
pub struct CareSolution {
    /// The solution `X` (symmetric).
    pub x: DMatrix<f64>,
    /// Relative residual `‖AᵀX + XA − XGX + Q‖_F / (2‖A‖‖X‖ + ‖G‖‖X‖² + ‖Q‖)`.
    pub residual: f64,
    /// Spectral abscissa of `A − GX` (negative: the solution is stabilizing).
    pub abscissa: f64,
    /// Sign-function iterations used.
    pub sign_iterations: usize,
    /// Newton–Kleinman refinement steps used.
    pub newton_steps: usize,
}

fn fro(a: &DMatrix<f64>) -> f64 {
    a.norm()
}

fn one_norm(a: &DMatrix<f64>) -> f64 {
    a.column_iter()
        .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Riccati residual `AᵀX + XA − XGX + Q`.
pub fn care_residual(
    a: &DMatrix<f64>,
    g: &DMatrix<f64>,
    q: &DMatrix<f64>,
    x: &DMatrix<f64>,
) -> DMatrix<f64> {
    let ax = a.transpose() * x;
    &ax + ax.transpose() - x * g * x + q
}

fn relative_residual(
    a: &DMatrix<f64>,
    g: &DMatrix<f64>,
    q: &DMatrix<f64>,
    x: &DMatrix<f64>,
) -> f64 {
    let xn = fro(x);
    let scale = 2.0 * fro(a) * xn + fro(g) * xn * xn + fro(q);
    fro(&care_residual(a, g, q, x)) / scale.max(f64::MIN_POSITIVE)
}

/// Matrix sign function by the scaled Newton iteration `Z ← (cZ + (cZ)⁻¹)/2`,
/// `c = |det Z|^(−1/n)` while far from convergence. Errors when `Z` becomes singular
/// (eigenvalues on the imaginary axis) or the cap is reached.
fn sign(z0: DMatrix<f64>, what: &str) -> Result<(DMatrix<f64>, usize)> {
    let n = z0.nrows() as f64;
    let mut z = z0;
    let mut scaling = true;
    let mut prev_change = f64::INFINITY;
    for k in 1..=MAX_SIGN_ITER {
        let Some((zinv, logdet)) = inverse_with_logdet(&z) else {
            return Err(Error::numerical(what, "the Hamiltonian has eigenvalues on the imaginary axis (singular in the sign iteration): no stabilizing solution"));
        };
        let c = if scaling && logdet.is_finite() {
            (-logdet / n).exp()
        } else {
            1.0
        };
        let next = (&z * c + zinv / c) * 0.5;
        let change = one_norm(&(&next - &z)) / one_norm(&next).max(f64::MIN_POSITIVE);
        z = next;
        if change < 1e-2 {
            scaling = false;
        }
        if change < 1e-13 {
            return Ok((z, k));
        }
        // Quadratic convergence has stalled at the rounding floor of an ill-conditioned
        // Hamiltonian (a plant with a gain of 1e9 and a pole at 0): accept; the Riccati
        // residual check after the solve decides whether the result is good enough.
        if !scaling && change < 1e-8 && change > 0.5 * prev_change {
            return Ok((z, k));
        }
        prev_change = change;
        if !change.is_finite() {
            break;
        }
    }
    Err(Error::numerical(what, format!("the sign iteration did not converge in {MAX_SIGN_ITER} steps (eigenvalues on or near the imaginary axis): no stabilizing solution")))
}

/// Solves the Lyapunov equation `FᵀX + XF + Q = 0` for Hurwitz `F` by the sign function of
/// `[Fᵀ  Q; 0  −F]`, whose (1,2) block converges to `2X`.
pub fn lyapunov(f: &DMatrix<f64>, q: &DMatrix<f64>, what: &str) -> Result<DMatrix<f64>> {
    let n = f.nrows() as f64;
    let (mut fk, mut qk) = (f.clone(), q.clone());
    let mut scaling = true;
    for _ in 0..MAX_SIGN_ITER {
        let Some((finv, logdet)) = inverse_with_logdet(&fk) else {
            return Err(Error::numerical(
                what,
                "Lyapunov equation with a singular state matrix",
            ));
        };
        let c = if scaling && logdet.is_finite() {
            (-logdet / n).exp()
        } else {
            1.0
        };
        let fnext = (&fk * c + &finv / c) * 0.5;
        let qnext = (&qk * c + finv.transpose() * &qk * &finv / c) * 0.5;
        let change = one_norm(&(&fnext - &fk)) / one_norm(&fnext).max(f64::MIN_POSITIVE);
        fk = fnext;
        qk = qnext;
        if change < 1e-2 {
            scaling = false;
        }
        if change < 1e-13 {
            // sign(F) = −I exactly when F is Hurwitz.
            let id = DMatrix::<f64>::identity(f.nrows(), f.nrows());
            if one_norm(&(&fk + id)) > 1e-6 {
                return Err(Error::numerical(
                    what,
                    "the Lyapunov state matrix is not Hurwitz",
                ));
            }
            let x = qk * 0.5;
            return Ok((&x + x.transpose()) * 0.5);
        }
    }
    Err(Error::numerical(
        what,
        format!("the Lyapunov sign iteration did not converge in {MAX_SIGN_ITER} steps"),
    ))
}

/// Riccati residual `AᵀX + XA − XGX + Q` with compensated dot products
/// ([`super::compensated`]): accurate to about `eps·|residual| + eps²·(terms)` instead of
/// `eps·(terms)`, so it resolves residuals far below the rounding of the terms.
fn care_residual_accurate(
    a: &DMatrix<f64>,
    g: &DMatrix<f64>,
    q: &DMatrix<f64>,
    x: &DMatrix<f64>,
) -> DMatrix<f64> {
    let n = x.nrows();
    let (gx_hi, gx_lo) = product_pair(g, x);
    DMatrix::from_fn(n, n, |i, j| {
        let mut acc = Dot2::default();
        for k in 0..n {
            acc.add_product(a[(k, i)], x[(k, j)]);
            acc.add_product(x[(i, k)], a[(k, j)]);
            acc.add_product(-x[(i, k)], gx_hi[(k, j)]);
            acc.add_product(-x[(i, k)], gx_lo[(k, j)]);
        }
        acc.add(q[(i, j)]);
        acc.value()
    })
}

/// Iterative refinement of a backward-stable solution towards forward accuracy.
///
/// The Newton–Kleinman steps of [`care`] stop once the residual is at rounding level
/// (about `eps` relative to the terms); when the equation is ill-conditioned that still
/// leaves a forward error of `cond·eps` — an unstable mode that the output barely sees gives
/// `‖X‖ ≈ 4.5e7` and a relative error 5.5e-8, which the normalized factors of
/// [`super::ncf`] turn into a normalization error of 1e-6. The same Newton step with the
/// residual computed in twice the precision (Wilkinson's iterative refinement) removes that
/// error: the correction solves `(A − GX)ᵀΔ + Δ(A − GX) + R(X) = 0`. A step is kept only if
/// the accurate residual does not grow.
fn refine_forward(
    a: &DMatrix<f64>,
    g: &DMatrix<f64>,
    q: &DMatrix<f64>,
    mut x: DMatrix<f64>,
    what: &str,
) -> DMatrix<f64> {
    let mut res = care_residual_accurate(a, g, q, &x);
    for _ in 0..MAX_REFINE_STEPS {
        let Ok(dx) = lyapunov(&(a - g * &x), &res, what) else {
            break;
        };
        if dx.iter().any(|v| !v.is_finite()) {
            break;
        }
        let cand = &x + &dx;
        let cand = (&cand + cand.transpose()) * 0.5;
        let res_cand = care_residual_accurate(a, g, q, &cand);
        if fro(&res_cand) > 2.0 * fro(&res) {
            break;
        }
        let step = fro(&dx) / fro(&cand).max(f64::MIN_POSITIVE);
        x = cand;
        res = res_cand;
        if step < 4.0 * f64::EPSILON {
            break;
        }
    }
    x
}

/// The stabilizing solution of `AᵀX + XA − XGX + Q = 0`; `what` names the equation in
/// error messages.
pub fn care(
    a: &DMatrix<f64>,
    g: &DMatrix<f64>,
    q: &DMatrix<f64>,
    what: &str,
) -> Result<CareSolution> {
    let n = a.nrows();
    if a.ncols() != n || g.shape() != (n, n) || q.shape() != (n, n) {
        return Err(Error::Invalid(format!("{what}: A, G, Q must be {n}×{n}")));
    }
    if a.iter()
        .chain(g.iter())
        .chain(q.iter())
        .any(|v| !v.is_finite())
    {
        return Err(Error::Invalid(format!(
            "{what}: a coefficient is not finite"
        )));
    }
    if n == 0 {
        return Ok(CareSolution {
            x: DMatrix::zeros(0, 0),
            residual: 0.0,
            abscissa: f64::NEG_INFINITY,
            sign_iterations: 0,
            newton_steps: 0,
        });
    }
    match care_in_coordinates(a, g, q, what) {
        Ok(s) => Ok(s),
        Err(e) => care_balanced(a, g, q, what).ok_or(e),
    }
}

/// The Hamiltonian `[A −G; −Q −Aᵀ]`.
fn hamiltonian(a: &DMatrix<f64>, g: &DMatrix<f64>, q: &DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    let mut h = DMatrix::zeros(2 * n, 2 * n);
    h.view_mut((0, 0), (n, n)).copy_from(a);
    h.view_mut((0, n), (n, n)).copy_from(&(-g));
    h.view_mut((n, 0), (n, n)).copy_from(&(-q));
    h.view_mut((n, n), (n, n)).copy_from(&(-a.transpose()));
    h
}

/// The second try of [`care`]: the same equation after a symplectic diagonal scaling
/// `T = diag(D, D⁻¹)` of the Hamiltonian (`A ↦ D⁻¹AD`, `G ↦ D⁻¹GD⁻¹`, `Q ↦ DQD`,
/// `X = D⁻¹X'D⁻¹`), `D` from the Parlett–Reinsch balancing `diag(D₁, D₂)` of `H` as
/// `D = (D₁/D₂)^(1/2)` rounded to powers of two (exact in floating point; it keeps the
/// Hamiltonian structure that a plain balancing would break). A Hamiltonian whose blocks
/// span many decades (a large output gain in coordinates that mix the states) makes the
/// sign function's invariant subspace inaccurate; balanced, its entries are comparable.
fn care_balanced(
    a: &DMatrix<f64>,
    g: &DMatrix<f64>,
    q: &DMatrix<f64>,
    what: &str,
) -> Option<CareSolution> {
    let n = a.nrows();
    let d2 = super::eig::balancing(&hamiltonian(a, g, q));
    let d: Vec<f64> = (0..n)
        .map(|i| 2f64.powi((0.5 * (d2[i] / d2[n + i]).log2()).round() as i32))
        .collect();
    if d.iter().all(|v| *v == 1.0) || d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return None;
    }
    let ab = DMatrix::from_fn(n, n, |i, j| a[(i, j)] * d[j] / d[i]);
    let gb = DMatrix::from_fn(n, n, |i, j| g[(i, j)] / (d[i] * d[j]));
    let qb = DMatrix::from_fn(n, n, |i, j| q[(i, j)] * d[i] * d[j]);
    let mut s = care_in_coordinates(&ab, &gb, &qb, what).ok()?;
    s.x = DMatrix::from_fn(n, n, |i, j| s.x[(i, j)] / (d[i] * d[j]));
    Some(s)
}

fn care_in_coordinates(
    a: &DMatrix<f64>,
    g: &DMatrix<f64>,
    q: &DMatrix<f64>,
    what: &str,
) -> Result<CareSolution> {
    let n = a.nrows();
    let h = hamiltonian(a, g, q);
    let (w, sign_iterations) = sign(h, what)?;
    // [W12; W22 + I] X = −[W11 + I; W21]
    let mut lhs = DMatrix::zeros(2 * n, n);
    let mut rhs = DMatrix::zeros(2 * n, n);
    lhs.view_mut((0, 0), (n, n))
        .copy_from(&w.view((0, n), (n, n)));
    lhs.view_mut((n, 0), (n, n))
        .copy_from(&w.view((n, n), (n, n)));
    rhs.view_mut((0, 0), (n, n))
        .copy_from(&w.view((0, 0), (n, n)));
    rhs.view_mut((n, 0), (n, n))
        .copy_from(&w.view((n, 0), (n, n)));
    for i in 0..n {
        lhs[(n + i, i)] += 1.0;
        rhs[(i, i)] += 1.0;
    }
    let qr = lhs.qr();
    let qt_rhs = qr.q().transpose() * (-rhs);
    let r = qr.r();
    let rmax = r.diagonal().iter().map(|v| v.abs()).fold(0.0, f64::max);
    let rmin = r
        .diagonal()
        .iter()
        .map(|v| v.abs())
        .fold(f64::INFINITY, f64::min);
    if rmin.is_nan() || rmin <= 1e-13 * rmax {
        return Err(Error::numerical(what, "the stable invariant subspace of the Hamiltonian is not a graph (an unstable mode is unobservable or uncontrollable): no stabilizing solution"));
    }
    let mut x = r.solve_upper_triangular(&qt_rhs).ok_or_else(|| {
        Error::numerical(what, "singular subspace basis: no stabilizing solution")
    })?;
    x = (&x + x.transpose()) * 0.5;
    let mut residual = relative_residual(a, g, q, &x);
    let mut newton_steps = 0;
    while residual > 1e-15 && newton_steps < MAX_NEWTON_STEPS {
        let ac = a - g * &x;
        let res = care_residual(a, g, q, &x);
        let Ok(dx) = lyapunov(&ac, &res, what) else {
            break;
        };
        let cand = &x + dx;
        let cand = (&cand + cand.transpose()) * 0.5;
        let r2 = relative_residual(a, g, q, &cand);
        if r2.is_nan() || r2 >= residual {
            break;
        }
        newton_steps += 1;
        let gain = residual / r2;
        x = cand;
        residual = r2;
        if gain < 2.0 {
            break;
        }
    }
    if residual.is_finite() && residual < RESIDUAL_TOL {
        x = refine_forward(a, g, q, x, what);
        residual = relative_residual(a, g, q, &x);
    }
    if residual.is_nan() || residual >= RESIDUAL_TOL {
        return Err(Error::numerical(what, format!("relative residual {residual:.1e} after refinement (above {RESIDUAL_TOL:.0e}): the equation is too ill-conditioned or has no stabilizing solution")));
    }
    let abscissa = spectral_abscissa(&eigenvalues(&(a - g * &x), what)?);
    if abscissa.is_nan() || abscissa >= 0.0 {
        return Err(Error::numerical(what, format!("the solution is not stabilizing (closed-loop eigenvalue with real part {abscissa:.3e}): an unstable mode is unobservable or uncontrollable")));
    }
    Ok(CareSolution {
        x,
        residual,
        abscissa,
        sign_iterations,
        newton_steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_closed_form() {
        // a x·2 − g x² + q = 0 → x = (a + √(a² + g q))/g
        for (a, g, q) in [(1.0, 1.0, 1.0), (-2.0, 0.5, 3.0), (5.0, 2.0, 0.0)] {
            let s = care(
                &DMatrix::from_element(1, 1, a),
                &DMatrix::from_element(1, 1, g),
                &DMatrix::from_element(1, 1, q),
                "t",
            )
            .unwrap();
            let x = (a + (a * a + g * q).sqrt()) / g;
            assert!(
                (s.x[(0, 0)] - x).abs() < 1e-12 * x.max(1.0),
                "{} vs {x}",
                s.x
            );
            assert!(s.abscissa < 0.0);
        }
    }

    #[test]
    fn lyapunov_scalar_and_matrix() {
        let f = DMatrix::from_row_slice(2, 2, &[-1.0, 2.0, 0.0, -3.0]);
        let q = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 4.0]);
        let x = lyapunov(&f, &q, "t").unwrap();
        let r = f.transpose() * &x + &x * &f + &q;
        assert!(r.norm() < 1e-12);
        let unstable = DMatrix::from_row_slice(1, 1, &[1.0]);
        assert!(lyapunov(&unstable, &DMatrix::identity(1, 1), "t").is_err());
    }

    #[test]
    fn unobservable_unstable_mode_has_no_stabilizing_solution() {
        // A = diag(1, -1), G = e2 e2ᵀ: the unstable mode is not reached by G.
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, -1.0]);
        let g = DMatrix::from_row_slice(2, 2, &[0.0, 0.0, 0.0, 1.0]);
        let q = DMatrix::identity(2, 2);
        let e = care(&a, &g, &q, "filter Riccati equation").unwrap_err();
        assert!(
            matches!(&e, Error::Numerical { what, .. } if what == "filter Riccati equation"),
            "{e:?}"
        );
        assert!(
            e.to_string().contains("no stabilizing solution")
                || e.to_string().contains("not stabilizing"),
            "{e}"
        );
    }
}
