//! Linear time-invariant systems: polynomials, transfer functions, transfer-function
//! matrices and state-space models, all evaluated on the imaginary axis.
pub mod compensated;
pub mod dense_inverse;
pub mod eig;
pub mod freq_eval;
pub mod golden;
pub mod hinf;
pub mod interconnect;
pub mod linalg;
pub mod ncf;
pub mod polynomial;
pub mod realization;
pub mod riccati;
pub mod state_space;
pub mod tf_matrix;
pub mod transfer_function;

pub use polynomial::Polynomial;
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
