//! Linear time-invariant systems: polynomials, transfer functions, transfer-function
//! matrices and state-space models, all evaluated on the imaginary axis.
//!
//! What is here (the submodules are private; everything below is re-exported here):
//! * models: [`Polynomial`] (with its [`Roots`]), [`TransferFunction`], [`TfMatrix`],
//!   [`StateSpace`], and [`FreqEvaluator`] for accurate responses of large state-space models;
//! * norms and spectra: [`hinf_norm`] (exact H∞ norm, [`HinfNorm`], accuracy [`HINF_RTOL`]),
//!   [`eigenvalues`] and [`spectral_abscissa`] (capped real Schur form), [`spectral_norm`]
//!   and [`extreme_singular_values`];
//! * Riccati and Lyapunov equations: [`care`] ([`CareSolution`], [`care_residual`]) and
//!   [`lyapunov`];
//! * factorizations and loops: [`NormalizedLcf`] (normalized left coprime factors of a
//!   plant) and [`negative_feedback`] (the loop `u = −K·y`);
//! * grids: [`logspace`].
pub(crate) mod compensated;
pub(crate) mod dense_inverse;
pub(crate) mod eig;
pub(crate) mod freq_eval;
pub(crate) mod golden;
pub(crate) mod hinf;
pub(crate) mod hqr;
pub(crate) mod interconnect;
pub(crate) mod lanczos;
pub(crate) mod linalg;
pub(crate) mod ncf;
pub(crate) mod polynomial;
pub(crate) mod realization;
pub(crate) mod riccati;
pub(crate) mod state_space;
pub(crate) mod tf_matrix;
pub(crate) mod transfer_function;

pub use eig::{eigenvalues, spectral_abscissa};
pub use freq_eval::FreqEvaluator;
pub use hinf::{
    hinf_norm, hinf_norm_near, hinf_norm_near_with_poles, peak_gain_above, HinfNorm, HINF_RTOL,
};
pub use interconnect::negative_feedback;
pub use linalg::{extreme_singular_values, spectral_norm};
pub use ncf::NormalizedLcf;
pub use polynomial::{Polynomial, Roots};
pub use riccati::{care, care_residual, lyapunov, CareSolution};
pub use state_space::StateSpace;
pub use tf_matrix::TfMatrix;
pub use transfer_function::TransferFunction;

/// Logarithmically spaced grid of `n` points from `lo` to `hi` (inclusive).
pub fn logspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if n == 1 {
        return vec![lo];
    }
    let (a, b) = (lo.log10(), hi.log10());
    (0..n)
        .map(|k| 10f64.powf(a + (b - a) * k as f64 / (n - 1) as f64))
        .collect()
}
