//! Robust stability with a perturbed coprime-factor model: Theorem 1 of Boulet & Francis
//! (1998, and the short paper; Vidyasagar 1985).
//!
//! For any factorization `G = C·M̃⁻¹·Ñ·J` (eq. (1): standard, special, the export of a
//! physical model, the normalized factors of a plant), perturbations
//! `‖[Δ_N −Δ_M](jω)‖ < |r(jω)|` and the loop `u = −K·y`, every plant of the set is
//! stabilized by `K` iff
//! 1. `K` internally stabilizes the loop of Fig. 1 (tested here on the eigenvalues of the
//!    closed-loop state matrix), and
//! 2. `‖r·T‖∞ ≤ 1` with `T = [−J·K·C; I](M̃ + Ñ·J·K·C)⁻¹` ([`theorem1_system`]); for the
//!    standard factorization `T = [−K; I](I + GK)⁻¹M̃⁻¹` (the paper writes `(I − GK)⁻¹`
//!    for `u = +K·y`; the norm is the same).
//!
//! The robust-stability margin `α* = 1/‖r·T‖∞` is the largest scale of `r` still proven
//! robust; it is computed **exactly** as an H∞ norm ([`crate::system::hinf_norm`]), and a grid
//! curve `1/σ_max(T(jω))` is computed independently from the factor values for the figure.
//! For normalized factors `‖T‖∞` equals `1/b(G, K)`, the normalized-coprime-factor
//! stability margin `b(G, K) = 1/‖[K; I](I + GK)⁻¹[I G]‖∞`: the crate computes both as a
//! cross-check.
//!
//! What is here (the submodules are private; everything below is re-exported here):
//! [`analyze`] (the whole test: [`RobustStability`] with its [`Verdict`], the proven margin
//! and the grid curve [`GridCurve`] of [`MarginRow`]s, cross-checked within
//! [`CROSS_CHECK_RTOL`]), [`decide`] (the verdict from the norm's bounds), and the systems
//! it is computed on: [`theorem1_system`] (`r·T` of condition 2), [`gang_of_four`],
//! [`plant_system`], [`modal_system`] (for a large diagonal `M̃` row by row; the whole-matrix
//! [`modal_cascade`] below [`CASCADE_ROWS_FROM`]), the grid value [`t_sigma_max`] and the
//! closed-loop poles [`loop_poles`] (for a large diagonal `M̃` from the structure: the loop of
//! the cancelled rows and the factors' denominators).
pub(crate) mod centre_inertia;
pub(crate) mod certified_norm;
pub(crate) mod enclosure;
pub(crate) mod factor_loop;
pub(crate) mod gang_sweep;
pub(crate) mod loop_poles;
pub(crate) mod second_order;
pub(crate) mod theorem1;
pub(crate) mod weighted_inertia;

pub use certified_norm::{
    certified_gang_norm, certified_t_norm, sweep_applies, MAX_CONTROLLER_STATES, MAX_INTERVAL_TESTS,
};
pub use factor_loop::{
    gang_of_four, gang_sigma_max, modal_cascade, modal_system, plant_system, t_sigma_max,
    theorem1_system, CASCADE_ROWS_FROM,
};
pub use loop_poles::{loop_poles, LoopPoles, POLES_BY_STRUCTURE_FROM};
pub use theorem1::{
    analyze, analyze_gridded, analyze_with_stages, closed_loop_poles, controller_fits, decide,
    GridCurve, MarginRow, RobustStability, Verdict, CROSS_CHECK_RTOL,
};
