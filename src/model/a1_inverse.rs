//! Realizations of `M̃⁻¹` for the exact A1 proof: `σ_min(M̃(jω)) > |r(jω)|` on a band iff
//! `sup σ_max(M̃⁻¹(jω)·r(jω)) < 1` there (Boulet & Francis 1998, assumption A1), an `L∞`
//! norm that the Hamiltonian iteration computes with a proven upper bound
//! ([`crate::system::peak_gain_above`]) instead of sampling a grid that a notch 1e-7 wide
//! falls between.

use super::factorization::Factorization;
use crate::system::{StateSpace, TransferFunction};
use nalgebra::DMatrix;

/// `(A − BD⁻¹C, BD⁻¹, −D⁻¹C, D⁻¹)`, the inverse of a square system with `D` invertible
/// (by LU solves), or why not.
fn inverse(ss: &StateSpace) -> Result<StateSpace, String> {
    let p = ss.d.nrows();
    let lu = ss.d.clone().lu();
    let singular =
        || "M̃(∞) is singular (σ_min(M̃(j∞)) = 0), so no unit r satisfies A1 at ω = ∞".to_string();
    let d_inv = lu
        .solve(&DMatrix::<f64>::identity(p, p))
        .ok_or_else(singular)?;
    let d_inv_c = lu.solve(&ss.c).ok_or_else(singular)?;
    let sv = ss.d.clone().svd(false, false).singular_values;
    let well_posed = sv.min() > 1e-13 * sv.max();
    if !well_posed || !d_inv.iter().all(|x| x.is_finite()) {
        return Err(singular());
    }
    let b_d_inv = &ss.b * &d_inv;
    Ok(StateSpace {
        a: &ss.a - &ss.b * &d_inv_c,
        b: b_d_inv,
        c: -d_inv_c,
        d: d_inv,
    })
}

/// `1/m` for one scalar entry of a diagonal `M̃`.
fn scalar_inverse(m: &TransferFunction) -> Result<StateSpace, String> {
    if !m.is_biproper() || m.num.is_zero() {
        return Err(
            "a diagonal entry of M̃ vanishes at ω = ∞ (strictly proper), so no unit r satisfies A1 there"
                .into(),
        );
    }
    Ok(StateSpace::from_tf(&TransferFunction::new(
        m.den.coeffs().to_vec(),
        m.num.coeffs().to_vec(),
    )))
}

impl Factorization {
    /// Realizations of the diagonal blocks of `M̃⁻¹`, so that `σ_min(M̃(jω)) =
    /// min_k 1/σ_max(B_k(jω))`: one block `(A, −L·R̃^(1/2), C, R̃^(1/2))` for normalized
    /// factors (their zeros are the plant's poles), one scalar `1/m_ii` per entry of a
    /// diagonal `M̃` (a physical model: one row per mode), else the inverse of the
    /// realization of the whole `M̃`. `Err` says why there is none (`M̃(∞)` singular: A1
    /// fails at `ω = ∞` for every unit `r`).
    pub fn a1_inverse_blocks(&self) -> Result<Vec<StateSpace>, String> {
        if let Some(ncf) = &self.realization {
            let mi = ncf.plant_and_m_inverse();
            let (p, m) = ncf.shape();
            let n = mi.states();
            return Ok(vec![StateSpace {
                a: mi.a.clone(),
                b: mi.b.view((0, m), (n, p)).into_owned(),
                c: mi.c.clone(),
                d: mi.d.view((0, m), (p, p)).into_owned(),
            }]);
        }
        if self.m.is_diagonal() {
            return (0..self.m.rows())
                .map(|i| scalar_inverse(self.m.entry(i, i)))
                .collect();
        }
        inverse(&StateSpace::from_tf_matrix(&self.m)).map(|s| vec![s])
    }
}
