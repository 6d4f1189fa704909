//! Robust stability with a perturbed coprime-factor model: Theorem 1 of Boulet & Francis
//! (1998, and the short paper; Vidyasagar 1985).
//!
//! For the standard factorization `G = M̃⁻¹Ñ`, perturbations `‖[Δ_N −Δ_M](jω)‖ < |r(jω)|`
//! and the loop `u = −K·y`, every plant of the set is stabilized by `K` iff
//! 1. `K` internally stabilizes `G` (tested here on the eigenvalues of the closed-loop
//!    state matrix), and
//! 2. `‖r·T‖∞ ≤ 1` with `T = [K; I](I + GK)⁻¹M̃⁻¹` (the paper writes `(I − GK)⁻¹` for
//!    `u = +K·y`; the norm is the same).
//!
//! The robust-stability margin `α* = 1/‖r·T‖∞` is the largest scale of `r` still proven
//! robust; it is computed **exactly** as an H∞ norm ([`crate::system::hinf`]), and a grid
//! curve `1/σ_max(T(jω))` is computed independently from the factor values for the figure.
//! For normalized factors `‖T‖∞` equals `1/b(G, K)`, the normalized-coprime-factor
//! stability margin `b(G, K) = 1/‖[K; I](I + GK)⁻¹[I G]‖∞`: the crate computes both as a
//! cross-check.
pub mod theorem1;

pub use theorem1::{
    analyze, factor_system, gang_of_four, theorem1_system, GridCurve, MarginRow, RobustStability,
};
