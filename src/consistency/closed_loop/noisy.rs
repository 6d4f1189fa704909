//! Noisy closed-loop SISO data (Crowder & de Callafon, Sec. 3.2, Theorem 2, eqs. (12)–(18)).
//!
//! The datum is `Y = (F_u(M, Δ) + W_cl δ)R` (eq. (8)), `|δ| < 1`; with `Φ = Y/R` and the
//! noise radius `ρ = |W_cl(jω)|` on `Φ`, Theorem 2 says the datum is consistent with the
//! weight `|V|` iff `μ_Δs(K̂₁₁ − K̂₁₂K̂₂₂⁻¹K̂₂₁) > 1`, `Δ_s = diag(Δ, δ)`.  Dividing (15) by
//! `R` (which changes no determinant), the `2×2` matrix is
//!
//! ```text
//!   G(v) = diag(v, 1)·G₁,   G₁ = [ M₁₁ + M₁₂M₂₁/(Φ − M₂₂)    M₁₂/(Φ − M₂₂) ]
//!                                [ ρ·M₂₁/(Φ − M₂₂)            ρ/(Φ − M₂₂)   ]
//! ```
//!
//! with `M` of eq. (6) at `V = 1` ([`super::noise_free::lft_m`]); only the rows feeding `Δ`
//! carry `V`, and its phase is absorbed into `Δ`, so `v = |V|`.
//!
//! **Monotonicity (the bisection is valid).**  `Δ_s` is diagonal and commutes with
//! `D_v = diag(v, 1)`, so `det(I − D_vG₁Δ_s) = det(I − G₁Δ_sD_v) = det(I − G₁diag(vδ₁, δ₂))`.
//! Hence `(δ₁, δ₂)` singularizes `G(v)` iff `(ε₁, ε₂) = (vδ₁, δ₂)` singularizes `G₁`, and
//! `μ(G(v)) > 1` ⇔ some singularizing `(ε₁, ε₂)` of `G₁` has `|ε₁| < v`, `|ε₂| < 1`.  That
//! set of admissible `ε₁` grows with `v`: consistency at `v` implies consistency at every
//! `v' > v`, so `{v : μ(G(v)) > 1}` is an interval `(v_min, ∞)` and bisection on the sign
//! of `μ − 1` converges to `v_min`.  (The same argument shows `v_min = inf{|Δ̄(Φ − ρε₂)| :
//! |ε₂| < 1}`: the smallest noise-free envelope over the noise disk — the brute-force
//! cross-check of the tests.)
//!
//! `μ` for two complex scalar blocks is exact and closed-form
//! ([`crate::mu::two_scalar::mu_two_scalar`]).  For `C̄ = C`, `M₁₁ = 0` and `G₁` is rank one
//! (eq. (16)); eq. (17) gives `μ(G(v)) = v|M₁₂M₂₁|/|Φ − M₂₂| + ρ/|Φ − M₂₂|` and eq. (18) the
//! closed form `v_min = max(0, (|Φ − M₂₂| − ρ)/|M₁₂M₂₁|)` ([`v_min_eq18`]).

use super::noise_free::{delta_bar, lft_m};
use crate::model::closed_loop::ClosedLoopAt;
use crate::mu::two_scalar::mu_two_scalar;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Which route gave the noisy `v_min`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoisyRoute {
    /// `C̄ = C`: the closed form of eq. (18).
    Eq18ClosedForm,
    /// `C̄ ≠ C`: bisection on `|V|` with the exact two-scalar-block `μ`.
    MuBisection,
    /// `Φ = M₂₂` to rounding: the nominal explains the datum, `v_min = 0`.
    Nominal,
}

/// Result at one noisy datum.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClosedLoopNoisyDatum {
    /// Smallest `|V|` consistent with the datum and its noise disk: 0 when the noise alone
    /// explains it, `inf` when no `|V|` does.
    pub v_min: f64,
    /// `μ` at `|V| = 0`: `ρ/|Φ − M₂₂|` (> 1: the noise alone explains the datum).
    pub mu_at_zero: f64,
    /// The route taken.
    pub route: NoisyRoute,
    /// Number of `μ` evaluations.
    pub mu_evaluations: usize,
    /// True when the bisection hit its iteration cap.
    pub hit_iteration_cap: bool,
}

/// Settings of the bisection on `|V|`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VBisectionSettings {
    /// Stop when `hi − lo ≤ rel_tol·hi`.
    pub rel_tol: f64,
    /// Cap on the `μ` evaluations.
    pub max_iter: usize,
}

impl VBisectionSettings {
    /// Checks every field; the error names the first bad one ([`crate::settings`]).
    pub fn validate(&self) -> std::result::Result<(), crate::settings::InvalidSetting> {
        crate::settings::Checker::new("VBisectionSettings")
            .fraction("rel_tol", self.rel_tol)
            .at_least("max_iter", self.max_iter, 1, "must be at least 1")
            .finish()
    }
}

impl Default for VBisectionSettings {
    fn default() -> Self {
        Self {
            rel_tol: 1e-13,
            max_iter: 300,
        }
    }
}

/// `G₁` of the module documentation (`V = 1`), row-major `[g11, g12, g21, g22]`; `None`
/// when `M` does not exist at this frequency or `Φ = M₂₂` exactly.
pub fn theorem2_g1(at: &ClosedLoopAt, phi: Complex64, rho: f64) -> Option<[Complex64; 4]> {
    let [m11, m12, m21, m22] = lft_m(at)?;
    let k22 = phi - m22[(0, 0)];
    if k22 == Complex64::new(0.0, 0.0) {
        return None;
    }
    let (m11, m12, m21) = (m11[(0, 0)], m12[(0, 0)], m21[(0, 0)]);
    Some([m11 + m12 * m21 / k22, m12 / k22, rho * m21 / k22, rho / k22])
}

/// `μ_Δs(G(v))` of Theorem 2 for `|V| = v` (exact, two scalar blocks).
pub fn mu_at(g1: &[Complex64; 4], v: f64) -> f64 {
    mu_two_scalar(v * g1[0], v * g1[1], g1[2], g1[3])
}

/// Eq. (18) for `C̄ = C`: `max(0, (|Φ − M₂₂| − ρ)/|M₁₂M₂₁|)` with `V = 1` in `M₁₂`.
pub fn v_min_eq18(at: &ClosedLoopAt, phi: Complex64, rho: f64) -> Option<f64> {
    let [_, m12, m21, m22] = lft_m(at)?;
    let k22 = (phi - m22[(0, 0)]).norm();
    Some(((k22 - rho) / (m12[(0, 0)] * m21[(0, 0)]).norm()).max(0.0))
}

/// The smallest `|V|` consistent with the noisy SISO datum `Φ` and noise radius `ρ`:
/// bisection on `v` of the sign of `μ(G(v)) − 1` (valid by the monotonicity above).
/// The bracket starts at `[0, σ̄(Δ̄(Φ))·(1 + 1e-9)]` — the noise-free value at the disk's
/// centre is always consistent — and is doubled (capped) if `Δ̄(Φ)` is not finite.
pub fn v_min_mu_bisection(
    at: &ClosedLoopAt,
    phi: Complex64,
    rho: f64,
    settings: &VBisectionSettings,
) -> ClosedLoopNoisyDatum {
    let mut out = ClosedLoopNoisyDatum {
        v_min: 0.0,
        mu_at_zero: f64::INFINITY,
        route: NoisyRoute::MuBisection,
        mu_evaluations: 0,
        hit_iteration_cap: false,
    };
    let Some(g1) = theorem2_g1(at, phi, rho) else {
        out.route = NoisyRoute::Nominal;
        return out;
    };
    out.mu_at_zero = g1[3].norm();
    if out.mu_at_zero > 1.0 {
        return out;
    }
    let centre = delta_bar(at, &DMatrix::from_element(1, 1, phi)).v_min;
    let mut hi = if centre.is_finite() && centre > 0.0 {
        centre * (1.0 + 1e-9)
    } else {
        1.0
    };
    let mut lo = 0.0;
    let mut n = 0;
    while mu_at(&g1, hi) <= 1.0 {
        n += 1;
        lo = hi;
        hi *= 2.0;
        if n >= 2100 || !hi.is_finite() {
            out.mu_evaluations = n;
            out.v_min = f64::INFINITY;
            return out;
        }
    }
    n += 1;
    let mut iters = 0;
    while hi - lo > settings.rel_tol * hi {
        if iters >= settings.max_iter {
            out.hit_iteration_cap = true;
            break;
        }
        // Geometric midpoint once lo > 0: v spans many decades.
        let mid = if lo > 0.0 && hi / lo > 4.0 {
            (lo * hi).sqrt()
        } else {
            0.5 * (lo + hi)
        };
        if mu_at(&g1, mid) > 1.0 {
            hi = mid;
        } else {
            lo = mid;
        }
        iters += 1;
    }
    out.mu_evaluations = n + iters;
    out.v_min = hi;
    out
}

/// The noisy SISO envelope value at one datum: eq. (18) when `C̄ = C`, the exact-μ
/// bisection otherwise.
pub fn v_min_noisy(
    at: &ClosedLoopAt,
    phi: Complex64,
    rho: f64,
    settings: &VBisectionSettings,
) -> ClosedLoopNoisyDatum {
    if at.same_controller {
        if let Some(v) = v_min_eq18(at, phi, rho) {
            let mu0 = lft_m(at).map_or(f64::INFINITY, |m| rho / (phi - m[3][(0, 0)]).norm());
            return ClosedLoopNoisyDatum {
                v_min: v,
                mu_at_zero: mu0,
                route: NoisyRoute::Eq18ClosedForm,
                mu_evaluations: 0,
                hit_iteration_cap: false,
            };
        }
    }
    v_min_mu_bisection(at, phi, rho, settings)
}
