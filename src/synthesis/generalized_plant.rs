//! The generalized plant of the weighted coprime-factor problem
//! `min_K ‖ r · [K; I](I + GK)⁻¹M̃⁻¹ ‖∞` (Theorem 1 of Boulet & Francis with a
//! frequency-dependent bound `r`), and its normalization to the form of Zhou, Doyle &
//! Glover, *Robust and Optimal Control* (ZDG), §17.1: `D₁₂ = [0; I]`, `D₂₁ = I`, `D₂₂ = 0`.
//!
//! With the loop `u = −K·y` and a disturbance `w` entering through `M̃⁻¹·r`
//! (`y = G·u + M̃⁻¹·r·w`), the map `w ↦ z = [u; y]` is `[−K; I](I + GK)⁻¹M̃⁻¹·r`, whose H∞
//! norm is that of `r·T` (`diag(−I, I)` is unitary and the scalar `r` commutes). With the
//! normalized factors `M̃⁻¹[Ñ  I] = (A, [B  −L·R̃^(1/2)], C, [D  R̃^(1/2)])` (the inverse of
//! the realization in [`crate::system::ncf`]) and `r = (A_r, B_r, C_r, d_r)` repeated on the
//! `p` channels of `w`:
//!
//! `P = [A_P | B₁  B₂; C₁ | D₁₁  D₁₂; C₂ | D₂₁  D₂₂]`,
//! `A_P = [A  B_w·C_r; 0  A_r]`, `B₁ = [B_w·d_r; B_r]`, `B₂ = [B; 0]`,
//! `C₁ = [0  0; C  D_w·C_r]`, `D₁₁ = [0; D_w·d_r]`, `D₁₂ = [I; D]`,
//! `C₂ = [C  D_w·C_r]`, `D₂₁ = D_w·d_r`, `D₂₂ = D`,
//!
//! with `B_w = −L·R̃^(1/2)`, `D_w = R̃^(1/2)`. The problem is regular because `r` is
//! biproper: `D₁₂` has full column rank and `D₂₁ = d_r·R̃^(1/2)` is invertible. The
//! `jω`-axis rank conditions (ZDG (A3), (A4)) hold too: `P₁₂ = [I; G]` has no zeros and
//! `A_P − B₁D₂₁⁻¹C₂` has the poles of `r⁻¹·M̃`, stable because `r` is a unit.

use crate::error::{Error, Result};
use crate::system::ncf::NormalizedLcf;
use crate::system::StateSpace;
use nalgebra::DMatrix;

/// A generalized plant `P` with exogenous input `w`, control `u`, error `z` and measurement
/// `y` (the notation of ZDG ch. 14–17).
#[derive(Debug, Clone)]
pub struct GeneralizedPlant {
    /// `A`.
    pub a: DMatrix<f64>,
    /// `B₁` (from `w`).
    pub b1: DMatrix<f64>,
    /// `B₂` (from `u`).
    pub b2: DMatrix<f64>,
    /// `C₁` (to `z`).
    pub c1: DMatrix<f64>,
    /// `C₂` (to `y`).
    pub c2: DMatrix<f64>,
    /// `D₁₁`.
    pub d11: DMatrix<f64>,
    /// `D₁₂`.
    pub d12: DMatrix<f64>,
    /// `D₂₁`.
    pub d21: DMatrix<f64>,
    /// `D₂₂`.
    pub d22: DMatrix<f64>,
}

/// `P^(power)` of a symmetric positive definite matrix.
pub(crate) fn spd_power(p: &DMatrix<f64>, power: f64) -> DMatrix<f64> {
    let eig = nalgebra::linalg::SymmetricEigen::new((p + p.transpose()) * 0.5);
    let d = DMatrix::from_diagonal(&eig.eigenvalues.map(|l| l.powf(power)));
    &eig.eigenvectors * d * eig.eigenvectors.transpose()
}

fn block_diag_repeat(m: &DMatrix<f64>, k: usize) -> DMatrix<f64> {
    let (r, c) = m.shape();
    let mut out = DMatrix::zeros(r * k, c * k);
    for i in 0..k {
        out.view_mut((i * r, i * c), (r, c)).copy_from(m);
    }
    out
}

/// Stacks `[top; bottom]`.
pub(crate) fn vstack(top: &DMatrix<f64>, bottom: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(top.nrows() + bottom.nrows(), top.ncols());
    out.view_mut((0, 0), top.shape()).copy_from(top);
    out.view_mut((top.nrows(), 0), bottom.shape())
        .copy_from(bottom);
    out
}

/// Joins `[left  right]`.
pub(crate) fn hstack(left: &DMatrix<f64>, right: &DMatrix<f64>) -> DMatrix<f64> {
    vstack(&left.transpose(), &right.transpose()).transpose()
}

impl GeneralizedPlant {
    /// The plant of the module docs for the normalized factors `ncf` and a SISO realization
    /// `r` of the bound (any realization; a constant `r` has none).
    pub fn weighted_factors(ncf: &NormalizedLcf, r: &StateSpace) -> Self {
        let g = &ncf.plant;
        let (p, m) = g.d.shape();
        let n = g.states();
        let nr = r.states() * p;
        let dw = ncf.r_half.clone();
        let bw = -(&ncf.l * &ncf.r_half);
        let dr = r.d[(0, 0)];
        let (ar, br, cr) = (
            block_diag_repeat(&r.a, p),
            block_diag_repeat(&r.b, p),
            block_diag_repeat(&r.c, p),
        );
        let a = vstack(
            &hstack(&g.a, &(&bw * &cr)),
            &hstack(&DMatrix::zeros(nr, n), &ar),
        );
        let c2 = hstack(&g.c, &(&dw * &cr));
        Self {
            a,
            b1: vstack(&(&bw * dr), &br),
            b2: vstack(&g.b, &DMatrix::zeros(nr, m)),
            c1: vstack(&DMatrix::zeros(m, n + nr), &c2),
            c2,
            d11: vstack(&DMatrix::zeros(m, p), &(&dw * dr)),
            d12: vstack(&DMatrix::identity(m, m), &g.d),
            d21: &dw * dr,
            d22: g.d.clone(),
        }
    }

    /// States, `(dim w, dim u, dim z, dim y)`.
    pub fn dims(&self) -> (usize, usize, usize, usize, usize) {
        (
            self.a.nrows(),
            self.b1.ncols(),
            self.b2.ncols(),
            self.c1.nrows(),
            self.c2.nrows(),
        )
    }

    /// The closed loop `w ↦ z` with `u = K·y` (positive feedback, the convention of ZDG);
    /// states `[x_P; x_K]`. Errors when the loop is ill-posed (`I − D_K·D₂₂` singular).
    pub fn closed_loop(&self, k: &StateSpace) -> Result<StateSpace> {
        let mu = self.b2.ncols();
        let e = DMatrix::<f64>::identity(mu, mu) - &k.d * &self.d22;
        let bad = || {
            Error::numerical(
                "H∞ synthesis",
                "the loop is ill-posed (I − K(∞)·D₂₂ singular)",
            )
        };
        let lu = e.lu();
        // u = E⁻¹(C_K x_K + D_K (C₂ x + D₂₁ w)), y = C₂x + D₂₁w + D₂₂u.
        let ux = lu.solve(&(&k.d * &self.c2)).ok_or_else(bad)?;
        let uk = lu.solve(&k.c).ok_or_else(bad)?;
        let uw = lu.solve(&(&k.d * &self.d21)).ok_or_else(bad)?;
        let yx = &self.c2 + &self.d22 * &ux;
        let yk = &self.d22 * &uk;
        let yw = &self.d21 + &self.d22 * &uw;
        let a = vstack(
            &hstack(&(&self.a + &self.b2 * &ux), &(&self.b2 * &uk)),
            &hstack(&(&k.b * &yx), &(&k.a + &k.b * &yk)),
        );
        let b = vstack(&(&self.b1 + &self.b2 * &uw), &(&k.b * &yw));
        let c = hstack(&(&self.c1 + &self.d12 * &ux), &(&self.d12 * &uk));
        let d = &self.d11 + &self.d12 * &uw;
        Ok(StateSpace { a, b, c, d })
    }
}

/// A plant in the normalized form `D₁₂ = [0; I]`, `D₂₁ = I` (ZDG §17.2): `z̃ = Uᵀz`
/// (orthogonal, so norms are kept), `u = S_u·ũ`, `ỹ = S_y·y`. A controller `K̃` of the
/// normalized plant (`ũ = K̃·ỹ`) is `K = S_u·K̃·S_y` for the original one; `D₂₂` is kept for
/// the loop shifting of `synthesis::hinf_weighted`.
#[derive(Debug, Clone)]
pub struct NormalizedPlant {
    /// The normalized plant (its `d22` is `S_y·D₂₂·S_u`).
    pub plant: GeneralizedPlant,
    /// `S_u = (D₁₂ᵀD₁₂)^(−1/2)`.
    pub s_u: DMatrix<f64>,
    /// `S_y = D₂₁⁻¹`.
    pub s_y: DMatrix<f64>,
}

/// Normalizes a plant with `D₁₂ = [I; D]` (the rows of `u` first) and a square invertible
/// `D₂₁`, as [`GeneralizedPlant::weighted_factors`] builds. With `R = I + DᵀD`,
/// `S = I + DDᵀ`, `U = [U⊥  U₁₂]`, `U₁₂ = D₁₂R^(−1/2)`, `U⊥ = [−DᵀS^(−1/2); S^(−1/2)]`
/// is orthogonal and `UᵀD₁₂R^(−1/2) = [0; I]`.
pub fn normalize(p: &GeneralizedPlant) -> Result<NormalizedPlant> {
    let (_, _, m, pz, py) = p.dims();
    if pz != m + py || p.d12.view((0, 0), (m, m)) != DMatrix::<f64>::identity(m, m) {
        return Err(Error::Invalid(
            "H∞ synthesis: the plant must have D₁₂ = [I; D] (z = [u; y])".into(),
        ));
    }
    let d = p.d12.view((m, 0), (py, m)).into_owned();
    let r = DMatrix::<f64>::identity(m, m) + d.transpose() * &d;
    let s = DMatrix::<f64>::identity(py, py) + &d * d.transpose();
    let s_u = spd_power(&r, -0.5);
    let s_mhalf = spd_power(&s, -0.5);
    let u = hstack(
        &vstack(&(-(d.transpose() * &s_mhalf)), &s_mhalf),
        &(&p.d12 * &s_u),
    );
    let sv = p.d21.clone().svd(false, false).singular_values;
    if p.d21.nrows() != p.d21.ncols() || sv.min().is_nan() || sv.min() <= 1e-13 * sv.max() {
        return Err(Error::Invalid(
            "H∞ synthesis: D₂₁ is singular: the bound r must be biproper (r(∞) ≠ 0)".into(),
        ));
    }
    let s_y = p
        .d21
        .clone()
        .try_inverse()
        .ok_or_else(|| Error::numerical("H∞ synthesis", "D₂₁ is singular"))?;
    let ut = u.transpose();
    let mut d12 = DMatrix::zeros(pz, m);
    d12.view_mut((py, 0), (m, m))
        .copy_from(&DMatrix::identity(m, m));
    Ok(NormalizedPlant {
        plant: GeneralizedPlant {
            a: p.a.clone(),
            b1: p.b1.clone(),
            b2: &p.b2 * &s_u,
            c1: &ut * &p.c1,
            c2: &s_y * &p.c2,
            d11: &ut * &p.d11,
            d12,
            d21: DMatrix::identity(py, py),
            d22: &s_y * &p.d22 * &s_u,
        },
        s_u,
        s_y,
    })
}
