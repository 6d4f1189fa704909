//! The level test of the H∞ γ-iteration and its central controller, for the generalized
//! plant of [`super::generalized_plant`] normalized to `D₁₂ = [0; I]`, `D₂₁ = I` with `D₂₂`
//! removed by loop shifting (ZDG §17.2).
//!
//! The level `γ` is achievable iff (Glover & Doyle 1988; Zhou, Doyle & Glover, *Robust and
//! Optimal Control*, Theorem 17.1, with `m₁ = p₂`, so `D₁₁₁₁` and `D₁₁₂₁` are empty):
//!
//! 1. `γ > σ̄(D₁₁₁₂)` (the rows of `z̃` that `u` does not reach);
//! 2. `X∞ = Ric(H∞) ≥ 0`, `H∞ = [A 0; −C₁ᵀC₁ −Aᵀ] − [B; −C₁ᵀD₁•]R⁻¹[D₁•ᵀC₁  Bᵀ]`,
//!    `B = [B₁ B₂]`, `D₁• = [D₁₁ D₁₂]`, `R = D₁•ᵀD₁• − diag(γ²I, 0)`;
//! 3. `Y∞ = Ric(J∞) ≥ 0`, the dual with `C = [C₁; C₂]`, `D•₁ = [D₁₁; D₂₁]`,
//!    `R̃ = D•₁D•₁ᵀ − diag(γ²I, 0)`;
//! 4. `ρ(X∞Y∞) < γ²`.
//!
//! The central controller (`Q = 0` in ZDG's parametrization, `u = K·y`) is, with
//! `F = −R⁻¹(D₁•ᵀC₁ + BᵀX∞) = [F₁₂; F₂]`, `L = −(B₁D•₁ᵀ + Y∞Cᵀ)R̃⁻¹ = [L₁₁ L₁₂ L₂]`,
//! `Z∞ = (I − γ⁻²Y∞X∞)⁻¹`, `D̂₁₁ = −D₁₁₂₂` and `E = −(C₂ + F₁₂)` (= `D̂₂₁⁻¹Ĉ₂`: the
//! factors `D̂₁₂`, `D̂₂₁` of the theorem cancel in the central controller):
//!
//! `K₀ = [A + BF + B̂₁E | B̂₁ ; F₂ + D̂₁₁E | D̂₁₁]`, `B̂₁ = −Z∞L₂ + Z∞(B₂ + L₁₂)D̂₁₁`.

use super::generalized_plant::{hstack, vstack, GeneralizedPlant, NormalizedPlant};
use crate::error::{Error, Result};
use crate::system::eig::{eigenvalues, spectral_abscissa};
use crate::system::riccati::care;
use crate::system::StateSpace;
use nalgebra::DMatrix;
use serde::Serialize;

/// Why a level `γ` is not achievable: the first of the four conditions of the module docs
/// that fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GammaFailure {
    /// `γ ≤ σ̄(D₁₁₁₂)`.
    FeedthroughBound,
    /// `H∞` has no stabilizing Riccati solution (or `R` is singular).
    ControlRiccati,
    /// `X∞` is not positive semidefinite.
    ControlNotPsd,
    /// `J∞` has no stabilizing Riccati solution.
    FilterRiccati,
    /// `Y∞` is not positive semidefinite.
    FilterNotPsd,
    /// `ρ(X∞Y∞) ≥ γ²`.
    Coupling,
}

/// One step of the γ-iteration.
#[derive(Debug, Clone, Serialize)]
pub struct GammaStep {
    /// The level tested (for the bound `r` as given, not the scaled one).
    pub gamma: f64,
    /// Whether it is achievable.
    pub achievable: bool,
    /// The failed condition, when not.
    pub failure: Option<GammaFailure>,
}

/// The Riccati solutions at an achievable level.
#[derive(Debug, Clone)]
pub struct GammaSolution {
    /// `X∞`.
    pub x: DMatrix<f64>,
    /// `Y∞`.
    pub y: DMatrix<f64>,
    /// `F`.
    pub f: DMatrix<f64>,
    /// `L`.
    pub l: DMatrix<f64>,
    /// `ρ(X∞Y∞)`.
    pub rho: f64,
}

fn min_sym_eig(m: &DMatrix<f64>) -> f64 {
    if m.is_empty() {
        return 0.0;
    }
    nalgebra::linalg::SymmetricEigen::new((m + m.transpose()) * 0.5)
        .eigenvalues
        .min()
}

/// `m ≥ 0` up to round-off: relative to `m` itself, with an absolute floor from the data of
/// its equation (`Y∞ = 0` exactly when `A − B₁D₂₁⁻¹C₂` is stable, as here, and comes out
/// as round-off of either sign).
fn is_psd(m: &DMatrix<f64>, floor: f64) -> bool {
    min_sym_eig(m) >= -1e-8 * m.amax() - floor
}

/// The absolute round-off floor of a Riccati solution with data `A`, `G`, `Q`.
fn riccati_floor(a: &DMatrix<f64>, g: &DMatrix<f64>, q: &DMatrix<f64>) -> f64 {
    1e-10 * (1.0 + q.amax()) / (1e-3 + a.amax()).min(1.0 + g.amax())
}

fn sym(m: DMatrix<f64>) -> DMatrix<f64> {
    (&m + m.transpose()) * 0.5
}

/// Whether `[A  −G; −Q  −Aᵀ]` has an eigenvalue on (to round-off, near) the imaginary axis:
/// then there is no stabilizing solution, whatever a sign iteration returns.
fn hamiltonian_touches_axis(a: &DMatrix<f64>, g: &DMatrix<f64>, q: &DMatrix<f64>) -> bool {
    let n = a.nrows();
    let mut h = DMatrix::zeros(2 * n, 2 * n);
    h.view_mut((0, 0), (n, n)).copy_from(a);
    h.view_mut((0, n), (n, n)).copy_from(&(-g));
    h.view_mut((n, 0), (n, n)).copy_from(&(-q));
    h.view_mut((n, n), (n, n)).copy_from(&(-a.transpose()));
    let scale = h.amax().max(1e-300);
    match eigenvalues(&h, "Hamiltonian") {
        // Relative to |λ| (a slow real eigenvalue, r's zero near the origin, is far from the
        // axis in its own scale), with an absolute floor at round-off of H.
        Ok(e) => e
            .iter()
            .any(|z| z.re.abs() <= 1e-8 * z.norm() + 1e-14 * scale),
        Err(_) => true,
    }
}

/// The four conditions of the module docs at level `gamma` on a normalized plant
/// (`D₁₂ = [0; I]`, `D₂₁ = I`; `D₂₂` is ignored, as loop shifting allows).
pub fn gamma_test(
    p: &GeneralizedPlant,
    gamma: f64,
) -> std::result::Result<GammaSolution, GammaFailure> {
    let (n, mw, mu, pz, _) = p.dims();
    let g2 = gamma * gamma;
    let d1112 = p.d11.view((0, 0), (pz - mu, mw)).into_owned();
    let sv = d1112.clone().svd(false, false).singular_values;
    if !(gamma.is_finite() && sv.iter().all(|s| *s < gamma * (1.0 - 1e-12))) {
        return Err(GammaFailure::FeedthroughBound);
    }
    // X∞: Āᵀ X + X Ā − X G X + Q = 0 with Ā = A − B R⁻¹ D₁•ᵀ C₁, G = B R⁻¹ Bᵀ,
    // Q = C₁ᵀ(I − D₁• R⁻¹ D₁•ᵀ)C₁.
    let b = hstack(&p.b1, &p.b2);
    let d1 = hstack(&p.d11, &p.d12);
    let mut r = d1.transpose() * &d1;
    for i in 0..mw {
        r[(i, i)] -= g2;
    }
    let r_lu = r.clone().lu();
    let (Some(r_dc), Some(r_bt)) = (
        r_lu.solve(&(d1.transpose() * &p.c1)),
        r_lu.solve(&b.transpose()),
    ) else {
        return Err(GammaFailure::ControlRiccati);
    };
    let ax = &p.a - &b * &r_dc;
    let gx = sym(&b * &r_bt);
    let qx = sym(p.c1.transpose() * &p.c1 - p.c1.transpose() * &d1 * &r_dc);
    if hamiltonian_touches_axis(&ax, &gx, &qx) {
        return Err(GammaFailure::ControlRiccati);
    }
    let x = care(&ax, &gx, &qx, "X∞")
        .map_err(|_| GammaFailure::ControlRiccati)?
        .x;
    if !is_psd(&x, riccati_floor(&ax, &gx, &qx)) {
        return Err(GammaFailure::ControlNotPsd);
    }
    // Y∞: the dual, A := Aᵀ, B := Cᵀ, C₁ := B₁ᵀ, D₁• := D•₁ᵀ.
    let c = vstack(&p.c1, &p.c2);
    let dd = vstack(&p.d11, &p.d21);
    let mut rt = &dd * dd.transpose();
    for i in 0..pz {
        rt[(i, i)] -= g2;
    }
    let rt_lu = rt.clone().lu();
    let (Some(rt_db), Some(rt_c)) = (rt_lu.solve(&(&dd * p.b1.transpose())), rt_lu.solve(&c))
    else {
        return Err(GammaFailure::FilterRiccati);
    };
    let ay = p.a.transpose() - c.transpose() * &rt_db;
    let gy = sym(c.transpose() * &rt_c);
    let qy = sym(&p.b1 * p.b1.transpose() - &p.b1 * dd.transpose() * &rt_db);
    // Disturbance feedforward (ZDG §16.8): with D₂₁ = I and A − B₁C₂ Hurwitz (here: the
    // poles of r⁻¹M̃), Y∞ = 0 solves the filter equation exactly (R̃⁻¹D•₁ = [0; I] makes
    // Q = 0, and A − B₁C₂ is the closed loop), so the coupling condition cannot bind. It is
    // taken exactly instead of from a Riccati solver fed with round-off.
    let df = spectral_abscissa(
        &eigenvalues(&(&p.a - &p.b1 * &p.c2), "A − B₁C₂")
            .map_err(|_| GammaFailure::FilterRiccati)?,
    ) < 0.0;
    let y = if df {
        DMatrix::zeros(n, n)
    } else {
        let y = care(&ay, &gy, &qy, "Y∞")
            .map_err(|_| GammaFailure::FilterRiccati)?
            .x;
        if !is_psd(&y, riccati_floor(&ay, &gy, &qy)) {
            return Err(GammaFailure::FilterNotPsd);
        }
        y
    };
    // ρ(XY) as the largest eigenvalue of the symmetric Y^(1/2) X Y^(1/2).
    let yh = {
        let e = nalgebra::linalg::SymmetricEigen::new(y.clone());
        let d = DMatrix::from_diagonal(&e.eigenvalues.map(|l| l.max(0.0).sqrt()));
        &e.eigenvectors * d * e.eigenvectors.transpose()
    };
    let rho = if n == 0 {
        0.0
    } else {
        nalgebra::linalg::SymmetricEigen::new(sym(&yh * &x * &yh))
            .eigenvalues
            .max()
    };
    if rho.is_nan() || rho >= g2 * (1.0 - 1e-12) {
        return Err(GammaFailure::Coupling);
    }
    let f = -r_lu
        .solve(&(d1.transpose() * &p.c1 + b.transpose() * &x))
        .ok_or(GammaFailure::ControlRiccati)?;
    let l = -rt_lu
        .solve(&(&dd * p.b1.transpose() + &c * &y))
        .ok_or(GammaFailure::FilterRiccati)?
        .transpose();
    Ok(GammaSolution { x, y, f, l, rho })
}

/// The central controller at an achievable `gamma` for the *original* plant of `np`
/// (loop shifting of `D₂₂`, the scalings `S_u`, `S_y` undone), for `u = +K·y`.
pub fn central_controller(
    np: &NormalizedPlant,
    gamma: f64,
    sol: &GammaSolution,
) -> Result<StateSpace> {
    let p = &np.plant;
    let (n, _, mu, pz, py) = p.dims();
    let f12 = sol.f.rows(0, py).into_owned();
    let f2 = sol.f.rows(py, mu).into_owned();
    let l12 = sol.l.columns(pz - mu, mu).into_owned();
    let l2 = sol.l.columns(pz, py).into_owned();
    let dh = -p.d11.rows(pz - mu, mu).into_owned();
    let w = DMatrix::<f64>::identity(n, n) - &sol.y * &sol.x / (gamma * gamma);
    let w_lu = w.lu();
    let bad = || {
        Error::numerical("H∞ synthesis", format!("I − γ⁻²Y∞X∞ is singular at γ = {gamma} (too close to the optimum): raise the γ factor"))
    };
    let zb2 = w_lu.solve(&(&p.b2 + &l12)).ok_or_else(bad)?;
    let zl2 = w_lu.solve(&l2).ok_or_else(bad)?;
    let e = -(&p.c2 + &f12);
    let b_hat = -zl2 + zb2 * &dh;
    let bfull = hstack(&p.b1, &p.b2);
    let k0 = StateSpace {
        a: &p.a + &bfull * &sol.f + &b_hat * &e,
        b: b_hat,
        c: &f2 + &dh * &e,
        d: dh,
    };
    // Loop shifting: y = y₀ + D₂₂u and u = K₀y₀ give K = K₀(I + D₂₂K₀)⁻¹.
    let ed = DMatrix::<f64>::identity(mu, mu) + &k0.d * &p.d22;
    let ed_inv = ed.try_inverse().ok_or_else(|| {
        Error::numerical(
            "H∞ synthesis",
            "the loop shift is ill-posed (I + D̂₁₁D₂₂ singular)",
        )
    })?;
    let k = StateSpace {
        a: &k0.a - &k0.b * &p.d22 * &ed_inv * &k0.c,
        b: &k0.b * (DMatrix::<f64>::identity(py, py) - &p.d22 * &ed_inv * &k0.d),
        c: &ed_inv * &k0.c,
        d: &ed_inv * &k0.d,
    };
    Ok(StateSpace {
        a: k.a,
        b: k.b * &np.s_y,
        c: &np.s_u * k.c,
        d: &np.s_u * k.d * &np.s_y,
    })
}
