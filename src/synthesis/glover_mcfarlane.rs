//! Glover–McFarlane robust stabilization of the normalized left coprime factors
//! (McFarlane & Glover 1990; Glover & McFarlane 1989; Skogestad & Postlethwaite,
//! *Multivariable Feedback Control*, 2nd ed., §9.4.1–9.4.2, eqs. (9.65)–(9.68)).
//!
//! With `R = I + DᵀD`, `S = I + DDᵀ`, `Ā = A − BR⁻¹DᵀC` and the stabilizing solutions of
//!
//! * the control Riccati equation `ĀᵀX + XĀ − XBR⁻¹BᵀX + CᵀS⁻¹C = 0`,
//! * the filter Riccati equation `ĀZ + ZĀᵀ − ZCᵀS⁻¹CZ + BR⁻¹Bᵀ = 0` (the `Y` of
//!   [`crate::system::NormalizedLcf`]),
//!
//! the largest normalized-coprime-factor stability margin any controller attains is, in
//! closed form (eq. (9.64)),
//!
//! `b_opt = (1 + ρ(XZ))^(−1/2) = √(1 − ‖[Ñ M̃]‖_H²)`.
//!
//! For `γ > γ_min = 1/b_opt` the central controller (eq. (9.67), written for `u = +K·y`)
//!
//! `K = [A + BF + γ²L⁻ᵀZCᵀ(C + DF) | γ²L⁻ᵀZCᵀ ; BᵀX | −Dᵀ]`,
//! `F = −R⁻¹(DᵀC + BᵀX)`, `L = (1 − γ²)I + XZ`,
//!
//! stabilizes `G` with `‖[K; I](I − GK)⁻¹M̃⁻¹‖∞ ≤ γ`, i.e. `b(G, K) ≥ 1/γ`. It is returned
//! here for the crate's convention `u = −K·y` (`C_K`, `D_K` negated). Every result is
//! checked after the fact by the caller's Theorem 1 test.

use crate::error::{Error, Result};
use crate::system::eig::{eigenvalues, spectral_abscissa};
use crate::system::ncf::NormalizedLcf;
use crate::system::riccati::care;
use crate::system::StateSpace;
use nalgebra::DMatrix;
use serde::Serialize;

/// The optimum of the normalized-coprime-factor robust stabilization problem.
#[derive(Debug, Clone)]
pub struct GmOptimum {
    /// The control Riccati solution `X`.
    pub x: DMatrix<f64>,
    /// The filter Riccati solution `Z`.
    pub z: DMatrix<f64>,
    /// `ρ(XZ)`.
    pub rho: f64,
    /// `b_opt = (1 + ρ(XZ))^(−1/2)`.
    pub b_opt: f64,
    /// Relative residuals of the two Riccati equations.
    pub residuals: [f64; 2],
}

/// A synthesized Glover–McFarlane controller.
#[derive(Debug, Clone, Serialize)]
pub struct GmController {
    /// `b_opt`, the largest attainable `b(G, K)`.
    pub b_opt: f64,
    /// `γ_min = 1/b_opt`.
    pub gamma_min: f64,
    /// The `γ` of the central controller (`γ_min` times the suboptimality factor).
    pub gamma: f64,
    /// `ρ(XZ)`.
    pub rho: f64,
    /// Relative residuals of the control and filter Riccati equations.
    pub riccati_residuals: [f64; 2],
    /// The controller for `u = −K·y`.
    #[serde(skip)]
    pub k: StateSpace,
}

fn symmetric(m: &DMatrix<f64>) -> DMatrix<f64> {
    (m + m.transpose()) * 0.5
}

/// `P^(1/2)` of a symmetric positive semidefinite matrix (negative round-off eigenvalues
/// clamped to zero).
fn psd_sqrt(p: &DMatrix<f64>) -> DMatrix<f64> {
    let eig = nalgebra::linalg::SymmetricEigen::new(symmetric(p));
    let d = DMatrix::from_diagonal(&eig.eigenvalues.map(|l| l.max(0.0).sqrt()));
    &eig.eigenvectors * d * eig.eigenvectors.transpose()
}

/// `b_opt` of the plant in `ncf` from the two Riccati equations; `ρ(XZ)` as the largest
/// eigenvalue of the symmetric `Z^(1/2)XZ^(1/2)` (the same spectrum, computed stably).
pub fn optimum(ncf: &NormalizedLcf) -> Result<GmOptimum> {
    let plant = &ncf.plant;
    if plant.states() == 0 {
        // A static plant G = D: [Ñ M̃] is constant, its Hankel norm 0, so b_opt = 1
        // (attained by K = Dᵀ: b(D, Dᵀ) = 1, see `central_controller`).
        return Ok(GmOptimum {
            x: DMatrix::zeros(0, 0),
            z: DMatrix::zeros(0, 0),
            rho: 0.0,
            b_opt: 1.0,
            residuals: [0.0, 0.0],
        });
    }
    let (p, m) = plant.d.shape();
    let (a, b, c, d) = (&plant.a, &plant.b, &plant.c, &plant.d);
    let r = DMatrix::<f64>::identity(m, m) + d.transpose() * d;
    let s = DMatrix::<f64>::identity(p, p) + d * d.transpose();
    let r_lu = r.clone().lu();
    let s_lu = s.lu();
    let bad = || Error::numerical("synthesis", "I + DᵀD is singular");
    let abar = a - b * r_lu.solve(&(d.transpose() * c)).ok_or_else(bad)?;
    let g = symmetric(&(b * r_lu.solve(&b.transpose()).ok_or_else(bad)?));
    let q = symmetric(&(c.transpose() * s_lu.solve(c).ok_or_else(bad)?));
    let xs = care(&abar, &g, &q, "control Riccati equation of the plant").map_err(|e| {
        let hint = "Glover–McFarlane synthesis needs (A, B) stabilizable and (A, C) detectable";
        e.with_hint(hint)
            .unwrap_or_else(|other| Error::Invalid(format!("{other}; {hint}")))
    })?;
    let z = ncf.riccati.x.clone();
    let zh = psd_sqrt(&z);
    let sym = symmetric(&(&zh * &xs.x * &zh));
    let rho = nalgebra::linalg::SymmetricEigen::new(sym)
        .eigenvalues
        .iter()
        .copied()
        .fold(0.0, f64::max);
    Ok(GmOptimum {
        x: xs.x,
        z,
        rho,
        b_opt: 1.0 / (1.0 + rho).sqrt(),
        residuals: [xs.residual, ncf.riccati.residual],
    })
}

/// The central controller at `γ` (`γ > γ_min`) for `u = −K·y`; errors when `L` is singular
/// (`γ` too close to `γ_min`) or the controller does not stabilize the plant.
pub fn central_controller(ncf: &NormalizedLcf, opt: &GmOptimum, gamma: f64) -> Result<StateSpace> {
    let plant = &ncf.plant;
    let (a, b, c, d) = (&plant.a, &plant.b, &plant.c, &plant.d);
    let n = a.nrows();
    let m = d.ncols();
    let gamma_min = 1.0 / opt.b_opt;
    if !(gamma.is_finite() && gamma > gamma_min) {
        return Err(Error::Invalid(format!(
            "synthesis: γ = {gamma} must exceed γ_min = {gamma_min} (the central controller is undefined at the optimum)"
        )));
    }
    if n == 0 {
        // Eq. (9.67) with no states is the static K = −Dᵀ (u = +K·y), i.e. Dᵀ for
        // u = −K·y, for every γ: [I; Dᵀ](I + DDᵀ)⁻¹[I  D] is the orthogonal projector onto
        // the range of [I; Dᵀ], of norm 1, so b(D, Dᵀ) = 1 = b_opt.
        return Ok(StateSpace {
            a: DMatrix::zeros(0, 0),
            b: DMatrix::zeros(0, d.nrows()),
            c: DMatrix::zeros(m, 0),
            d: d.transpose(),
        });
    }
    let r = DMatrix::<f64>::identity(m, m) + d.transpose() * d;
    let f = -r
        .lu()
        .solve(&(d.transpose() * c + b.transpose() * &opt.x))
        .ok_or_else(|| Error::numerical("synthesis", "I + DᵀD is singular"))?;
    let g2 = gamma * gamma;
    let l = DMatrix::<f64>::identity(n, n) * (1.0 - g2) + &opt.x * &opt.z;
    // γ² can overflow (a huge factor times a large γ_min): never hand an infinite matrix
    // to the SVD (it panics or loops).
    if !g2.is_finite() || l.iter().any(|v| !v.is_finite()) {
        return Err(Error::Invalid(format!(
            "synthesis: γ = {gamma:.3e} is too large (γ² overflows); choose a smaller --gamma-factor"
        )));
    }
    let sv = l.clone().svd(false, false).singular_values;
    if n > 0 && (sv.min().is_nan() || sv.min() <= 1e-13 * sv.max().max(1.0)) {
        return Err(Error::numerical("synthesis", format!("L = (1 − γ²)I + XZ is singular at γ = {gamma} (too close to γ_min = {gamma_min}): raise the γ factor")));
    }
    let w = l
        .transpose()
        .lu()
        .solve(&(&opt.z * c.transpose()))
        .ok_or_else(|| Error::numerical("synthesis", "L is singular"))?;
    let k = StateSpace {
        a: a + b * &f + (&w * (c + d * &f)) * g2,
        b: &w * g2,
        // Eq. (9.67) is for u = +K·y: negate the output for u = −K·y.
        c: -(b.transpose() * &opt.x),
        d: d.transpose(),
    };
    if k.a.iter().chain(k.b.iter()).any(|v| !v.is_finite()) {
        return Err(Error::Invalid(format!(
            "synthesis: the central controller at γ = {gamma:.3e} is not finite; choose a smaller --gamma-factor"
        )));
    }
    Ok(k)
}

/// `b_opt` and the central controller at `γ = factor·γ_min` (`factor > 1`; 1.1 is the usual
/// practice), with the closed loop's stability checked.
pub fn synthesize(ncf: &NormalizedLcf, factor: f64) -> Result<GmController> {
    check_gamma_factor(factor)?;
    let opt = optimum(ncf)?;
    let gamma_min = 1.0 / opt.b_opt;
    let gamma = factor * gamma_min;
    let k = central_controller(ncf, &opt, gamma)?;
    let abscissa = {
        let cl = closed_loop_matrix(&ncf.plant, &k)?;
        spectral_abscissa(&eigenvalues(&cl, "closed-loop poles")?)
    };
    if abscissa.is_nan() || abscissa >= 0.0 {
        return Err(Error::numerical("synthesis", format!("the central controller does not stabilize the plant (closed-loop pole with real part {abscissa:.3e}); the Riccati solutions are too inaccurate")));
    }
    Ok(GmController {
        b_opt: opt.b_opt,
        gamma_min,
        gamma,
        rho: opt.rho,
        riccati_residuals: opt.residuals,
        k,
    })
}

/// Largest `--gamma-factor`: `γ = factor·γ_min` beyond 1e3·γ_min buys nothing (the
/// central controller tends to a limit) and its `γ²` terms overflow long before 1e300.
pub const MAX_GAMMA_FACTOR: f64 = 1e3;

/// Validates `--gamma-factor` (`1 < factor ≤ 1e3`), before any work.
pub fn check_gamma_factor(factor: f64) -> Result<()> {
    if !(factor.is_finite() && factor > 1.0 && factor <= MAX_GAMMA_FACTOR) {
        return Err(Error::Argument {
            arg: format!("--gamma-factor {}", crate::report::fmt::sig(factor)),
            msg: "must be a number with 1 < factor ≤ 1000 (γ = factor·γ_min; the central controller is undefined at γ_min, and 1.1 is the usual practice)".into(),
        });
    }
    Ok(())
}

/// The state matrix of the loop `u = −K·y` around `G` (states `[x_G; x_K]`).
pub fn closed_loop_matrix(g: &StateSpace, k: &StateSpace) -> Result<DMatrix<f64>> {
    let m = g.d.ncols();
    let p = g.d.nrows();
    // A plant with one dummy input, so that negative_feedback returns the loop.
    let n = g.states();
    let mut b = DMatrix::zeros(n, m + 1);
    b.view_mut((0, 0), (n, m)).copy_from(&g.b);
    let mut d = DMatrix::zeros(p, m + 1);
    d.view_mut((0, 0), (p, m)).copy_from(&g.d);
    let pl = StateSpace {
        a: g.a.clone(),
        b,
        c: g.c.clone(),
        d,
    };
    Ok(crate::system::interconnect::negative_feedback(&pl, k, m)?.a)
}
