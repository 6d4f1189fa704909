//! Exact structured singular value of a `2×2` complex matrix for two complex scalar blocks,
//! `Δ_s = diag(δ₁, δ₂)` (Crowder & de Callafon, eq. (12), SISO).
//!
//! With two blocks that are not repeated scalars (`2S + F = 2 ≤ 3`), `μ` equals its
//! D-scaled upper bound `inf_{d>0} σ̄(D A D⁻¹)`, `D = diag(d, 1)` (Packard and Doyle 1993,
//! the same fact [`crate::mu::mu_full_scalar`] uses for one full plus one scalar block; a
//! complex scalar is a `1×1` full block).  For `2×2` matrices the infimum has a closed form:
//! `D A D⁻¹ = [[a₁₁, d·a₁₂], [a₂₁/d, a₂₂]]` has `det` independent of `d` and
//! `σ̄² = (F + √(F² − 4|det A|²))/2` with `F = ‖D A D⁻¹‖_F²`, which is increasing in `F`;
//! `F(d) = |a₁₁|² + |a₂₂|² + d²|a₁₂|² + |a₂₁|²/d²` has the infimum
//! `F* = |a₁₁|² + |a₂₂|² + 2|a₁₂||a₂₁|` (at `d² = |a₂₁|/|a₁₂|`, or approached as `d → 0`
//! or `∞` when one of them vanishes; then `μ = max(|a₁₁|, |a₂₂|)`, as for a triangular
//! matrix).  So
//!
//! ```text
//!   μ(A) = √( (F* + √(F*² − 4|det A|²)) / 2 ).
//! ```
//!
//! No iteration, no decomposition: the closed-loop noisy envelope can afford a bisection
//! on `|V|` with one of these per step.

use num_complex::Complex64;

/// `μ` of `[[a11, a12], [a21, a22]]` for `Δ_s = diag(δ₁, δ₂)`, both complex scalars: the
/// inverse of the smallest `max(|δ₁|, |δ₂|)` with `det(I − AΔ_s) = 0` (0 if none).
pub fn mu_two_scalar(a11: Complex64, a12: Complex64, a21: Complex64, a22: Complex64) -> f64 {
    let f = a11.norm_sqr() + a22.norm_sqr() + 2.0 * a12.norm() * a21.norm();
    let det = (a11 * a22 - a12 * a21).norm();
    // F*² − 4|det|² ≥ 0 in exact arithmetic (|det| ≤ F*/2); clamp rounding.
    let disc = (f * f - 4.0 * det * det).max(0.0);
    ((f + disc.sqrt()) / 2.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    #[test]
    fn triangular_and_diagonal_cases() {
        assert!(
            (mu_two_scalar(c(0.3, 0.4), c(0.0, 0.0), c(5.0, 1.0), c(-2.0, 0.0)) - 2.0).abs()
                < 1e-15
        );
        assert!(
            (mu_two_scalar(c(0.5, 0.0), c(0.0, 0.0), c(0.0, 0.0), c(0.0, 0.25)) - 0.5).abs()
                < 1e-15
        );
    }

    #[test]
    fn rank_one_matrix_is_the_sum_of_moduli() {
        // eq. (17): μ([a; b][c d]) = |ac| + |bd|.
        let (a, b, cc, d) = (c(1.0, 2.0), c(-0.5, 0.1), c(0.3, -0.7), c(2.0, 0.0));
        let mu = mu_two_scalar(a * cc, a * d, b * cc, b * d);
        let want = (a * cc).norm() + (b * d).norm();
        assert!((mu - want).abs() < 1e-14 * want);
    }

    #[test]
    fn certificate_singularizes_at_one_over_mu() {
        // Brute force: the smallest max(|δ1|,|δ2|) on |δ1| = |δ2| = k making det zero is 1/μ.
        let (a11, a12, a21, a22) = (c(0.4, -0.2), c(1.5, 0.3), c(-0.2, 0.9), c(0.1, 0.6));
        let mu = mu_two_scalar(a11, a12, a21, a22);
        let k = 1.0 / mu;
        // For δ1 = k e^{iθ}, δ2 solves 1 − a11δ1 − a22δ2 + det·δ1δ2 = 0; min over θ of |δ2| = k.
        let det = a11 * a22 - a12 * a21;
        let min_d2 = (0..200_000)
            .map(|i| {
                let th = i as f64 * std::f64::consts::TAU / 200_000.0;
                let d1 = Complex64::from_polar(k, th);
                ((c(1.0, 0.0) - a11 * d1) / (a22 - det * d1)).norm()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            (min_d2 - k).abs() < 1e-6 * k,
            "min |δ2| = {min_d2}, k = {k}"
        );
    }
}
