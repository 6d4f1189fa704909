//! Noise-free closed-loop data (Crowder & de Callafon, Sec. 3.1): the perturbation `Δ̄` of
//! eq. (2) that a datum determines, and the LFT of eq. (10) used by Theorem 1.
//!
//! **Derivation (the form the code uses).**  A plant `P₀` is in the set (2) with
//! perturbation `Δ̄` iff `P₀(D̂ − N_cΔ̄) = N̂ + D_cΔ̄`, i.e.
//! `(D_c + P₀N_c)Δ̄ = P₀D̂ − N̂`.  With `C = N_cD_c⁻¹` and `P̂ = N̂D̂⁻¹`:
//!
//! ```text
//!   Δ̄ = D_c⁻¹ (I + P₀C)⁻¹ (P₀ − P̂) D̂.                                  (*)
//! ```
//!
//! The sensitivity is the **true** plant's `(I + P₀C)⁻¹`.  Corollary 1 as printed has
//! `(I + P̂C)⁻¹` — its proof writes `(P₀D̂ − N̂) = (P̂N_c + D_c)Δ` where the factor is
//! `P₀N_c + D_c` — while Corollary 2 (`C̄ = C`) has `1/(1 + P₀C̄)`, which agrees with (*).
//! The test `tests/consistency/closed_loop_noise_free.rs` reconstructs `P₀` from both forms: (*)
//! reproduces it to rounding, the printed form does not.
//!
//! The data give the closed-loop map `Φ = (I + P₀C̄)⁻¹P₀` of the experiment (controller
//! `C̄`), so `P₀ = (I − ΦC̄)⁻¹Φ`.  Substituting and multiplying (*) through by
//! `I − ΦC̄ = (I + P₀C̄)⁻¹` gives a form that needs no open-loop plant:
//!
//! ```text
//!   Δ̄ = E⁻¹F,   E = (I − ΦC̄)D_c + ΦN_c,   F = ΦD̂ − (I − ΦC̄)N̂.              (**)
//! ```
//!
//! It stays finite where `P₀` has a pole on the axis (`I − ΦC̄` singular) and, for
//! `C̄ = C`, reduces to `E = D_c`: `Δ̄ = D_c⁻¹(Φ(D̂ + CN̂) − N̂)`, affine in `Φ` (the
//! `M₁₁ = 0` case of eq. (7)).  `E = (I + P₀C̄)⁻¹(I + P₀C)D_c` is singular exactly when the
//! loop of `P₀` with the *model's* controller `C` has a pole at `jω`: then no finite `Δ̄`
//! explains the datum and the envelope is `inf`.
//!
//! Since `V` is a scalar weight and `Δ̄ = VΔ` with `‖Δ‖ < 1`, the datum is explained iff
//! `|V(jω)| > σ̄(Δ̄)`: the closed-loop envelope is `σ̄(Δ̄)` (SISO: `|Δ̄|`).

use crate::model::closed_loop::ClosedLoopAt;
use crate::system::linalg::extreme_singular_values;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Below this `σ_min(I − ΦC̄)` the experiment's sensitivity is so small that `Φ ≈ C̄⁻¹`
/// whatever the plant: the datum says little about `P₀`, and `P₀ = (I − ΦC̄)⁻¹Φ` (the
/// open-loop equivalent) is not formed.
pub const UNINFORMATIVE_SENSITIVITY: f64 = 1e-8;

/// `E` of (**) is treated as singular when `σ_min(E) ≤ SINGULAR_E·σ_max(E)`.
pub const SINGULAR_E: f64 = 1e-13;

/// The perturbation determined by one noise-free datum.
#[derive(Debug, Clone)]
pub struct DeltaBar {
    /// `Δ̄` of (**) (`p×m`); `None` when `E` is singular (no finite `Δ̄`).
    pub delta: Option<DMatrix<Complex64>>,
    /// `σ̄(Δ̄)`, the smallest `|V|` that explains the datum (`inf` when `delta` is `None`).
    pub v_min: f64,
    /// `σ_min(I − ΦC̄)`: the experiment's sensitivity at this datum.
    pub sensitivity_sigma_min: f64,
    /// True when `sensitivity_sigma_min < UNINFORMATIVE_SENSITIVITY`.
    pub uninformative: bool,
}

fn identity(p: usize) -> DMatrix<Complex64> {
    DMatrix::identity(p, p)
}

/// `Δ̄ = E⁻¹F` of (**) from the closed-loop datum `Φ` (`p×m`).
pub fn delta_bar(at: &ClosedLoopAt, phi: &DMatrix<Complex64>) -> DeltaBar {
    let p = phi.nrows();
    let s = identity(p) - phi * &at.c_bar;
    let sens = extreme_singular_values(&s).1;
    let e = &s * &at.d_c + phi * &at.n_c;
    let f = phi * &at.d_hat - &s * &at.n_hat;
    let (emax, emin) = extreme_singular_values(&e);
    let delta = if emin > SINGULAR_E * emax && emin.is_finite() {
        e.lu().solve(&f).filter(|d| d.iter().all(|x| x.is_finite()))
    } else {
        None
    };
    let v_min = delta
        .as_ref()
        .map_or(f64::INFINITY, |d| extreme_singular_values(d).0);
    DeltaBar {
        delta,
        v_min,
        sensitivity_sigma_min: sens,
        uninformative: sens < UNINFORMATIVE_SENSITIVITY,
    }
}

/// The plant `P₀ = (I − ΦC̄)⁻¹Φ` that produced the closed-loop datum `Φ` with the
/// experiment's controller `C̄` (`None` where `I − ΦC̄` is singular).
pub fn recover_plant(at: &ClosedLoopAt, phi: &DMatrix<Complex64>) -> Option<DMatrix<Complex64>> {
    let s = identity(phi.nrows()) - phi * &at.c_bar;
    s.lu()
        .solve(phi)
        .filter(|x| x.iter().all(|v| v.is_finite()))
}

/// The closed-loop map `(I + P₀C̄)⁻¹P₀` of a plant with the experiment's controller.
pub fn closed_loop_map(at: &ClosedLoopAt, p0: &DMatrix<Complex64>) -> Option<DMatrix<Complex64>> {
    let s = identity(p0.nrows()) + p0 * &at.c_bar;
    s.lu().solve(p0)
}

/// The perturbed plant of eq. (2), `(N̂ + D_cΔ̄)(D̂ − N_cΔ̄)⁻¹` (`None` if `D` is singular).
pub fn perturbed_plant(
    at: &ClosedLoopAt,
    delta: &DMatrix<Complex64>,
) -> Option<DMatrix<Complex64>> {
    let n = &at.n_hat + &at.d_c * delta;
    let d = &at.d_hat - &at.n_c * delta;
    // P = N D⁻¹ ⇔ Pᵀ = D⁻ᵀNᵀ.
    let pt = d.transpose().lu().solve(&n.transpose())?;
    Some(pt.transpose())
}

/// (*) from a known plant: `D_c⁻¹(I + P₀C)⁻¹(P₀ − P̂)D̂`.
pub fn delta_bar_from_plant(
    at: &ClosedLoopAt,
    p0: &DMatrix<Complex64>,
) -> Option<DMatrix<Complex64>> {
    let s = identity(p0.nrows()) + p0 * &at.c;
    let x = s.lu().solve(&((p0 - &at.p_hat) * &at.d_hat))?;
    at.d_c.clone().lu().solve(&x)
}

/// Corollary 1 **as printed**: `D_c⁻¹(I + P̂C)⁻¹(P₀ − P̂)D̂`, kept only so that a test can
/// show it does not reproduce `P₀` (see the module documentation).
pub fn delta_bar_corollary1_printed(
    at: &ClosedLoopAt,
    p0: &DMatrix<Complex64>,
) -> Option<DMatrix<Complex64>> {
    let s = identity(p0.nrows()) + &at.p_hat * &at.c;
    let x = s.lu().solve(&((p0 - &at.p_hat) * &at.d_hat))?;
    at.d_c.clone().lu().solve(&x)
}

/// The coefficient matrix `M` of eq. (6) at one frequency with `V = 1`:
/// `(M₁₁, M₁₂, M₂₁, M₂₂)` with
/// `M₁₁ = (D̂ + C̄N̂)⁻¹(C − C̄)D_c`, `M₁₂ = (D̂ + C̄N̂)⁻¹`,
/// `M₂₁ = (I + P̂C̄)⁻¹(I + P̂C)D_c`, `M₂₂ = (I + P̂C̄)⁻¹P̂`.
/// For a weight `V`, `M₁₁` and `M₁₂` are multiplied by `V`.
///
/// **Sign of `M₁₁`.**  The paper prints `M₁₁ = V(D̂ + C̄N̂)⁻¹(C̄ − C)D_c`.  Deriving it:
/// the closed loop of `P = ND⁻¹` is `Φ = N(D + C̄N)⁻¹`, and with eq. (2)
/// `D + C̄N = A + (C̄ − C)D_cΔ̄`, `A = D̂ + C̄N̂`, so
/// `(D + C̄N)⁻¹ = (I − M₁₁Δ̄)⁻¹A⁻¹` needs `M₁₁ = A⁻¹(C − C̄)D_c`; expanding
/// `N̂(I − M₁₁Δ̄)⁻¹` then gives exactly the printed `M₂₁` and `M₂₂`.  The test
/// `tests/consistency/closed_loop_noise_free.rs` checks `F_u(M, Δ̄) = Φ` with `C̄ ≠ C`: it holds with
/// this sign and fails with the printed one.  (For `C̄ = C` both give `M₁₁ = 0`.)
pub fn lft_m(at: &ClosedLoopAt) -> Option<[DMatrix<Complex64>; 4]> {
    let p = at.p_hat.nrows();
    let m = at.p_hat.ncols();
    let a = &at.d_hat + &at.c_bar * &at.n_hat;
    let a_lu = a.lu();
    let m12 = a_lu.solve(&DMatrix::identity(m, m))?;
    let m11 = a_lu.solve(&((&at.c - &at.c_bar) * &at.d_c))?;
    let s = (identity(p) + &at.p_hat * &at.c_bar).lu();
    let m21 = s.solve(&((identity(p) + &at.p_hat * &at.c) * &at.d_c))?;
    let m22 = s.solve(&at.p_hat)?;
    Some([m11, m12, m21, m22])
}

/// `F_u(M, Δ̄) = M₂₂ + M₂₁Δ̄(I − M₁₁Δ̄)⁻¹M₁₂` with `V = 1` (eq. (6)): the closed-loop map
/// of the plant of eq. (2) with perturbation `Δ̄` under the experiment's controller.
pub fn upper_lft(
    m: &[DMatrix<Complex64>; 4],
    delta: &DMatrix<Complex64>,
) -> Option<DMatrix<Complex64>> {
    let [m11, m12, m21, m22] = m;
    let k = m11.nrows();
    let inner = (DMatrix::identity(k, k) - m11 * delta).lu().solve(m12)?;
    Some(m22 + m21 * delta * inner)
}

/// Theorem 1's matrix `N₁₁ = M̂₁₁ − M̂₁₂M̂₂₂⁻¹M̂₂₁` of eq. (10) for square data `Φ`
/// (`R = I`, `Y = Φ`) with `V = 1`: `M₁₁ + M₁₂(Φ − M₂₂)⁻¹M₂₁`.  The datum is consistent
/// with `|V|` iff `μ_Δ(V·N₁₁) > 1`; for SISO `μ = |V·N₁₁|`, so the envelope is `1/|N₁₁|`.
pub fn theorem1_n11(at: &ClosedLoopAt, phi: &DMatrix<Complex64>) -> Option<DMatrix<Complex64>> {
    let [m11, m12, m21, m22] = lft_m(at)?;
    let x = (phi - &m22).lu().solve(&m21)?;
    Some(m11 + m12 * x)
}
