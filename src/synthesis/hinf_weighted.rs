//! H∞ synthesis with a frequency-dependent bound `r` as weight:
//! `γ_opt = min_K ‖ r · [K; I](I + GK)⁻¹M̃⁻¹ ‖∞`, so that `α_opt = 1/γ_opt` is the best
//! Theorem 1 margin any controller attains with the normalized factors and this `r`.
//!
//! **Method.** γ-iteration on the generalized plant of [`super::generalized_plant`]: each
//! level is tested, and the central controller built, by [`super::hinf_gamma`] (Glover &
//! Doyle 1988; ZDG Theorem 17.1, conditions 1–4 there).
//!
//! `γ` is bisected (geometrically) between proven bounds — `γ_GM·min|r|` below and
//! `γ_GM·‖r‖∞` above, `γ_GM = 1/b_opt` of Glover–McFarlane, since every controller has
//! `‖T‖∞ ≥ γ_GM` and the Glover–McFarlane optimum achieves `γ_GM` — to a relative tolerance,
//! with an iteration cap. `r` is scaled to `r/|r(∞)|` first (`γ` scales with it). The
//! controller is then verified after the fact: the closed loop's poles and its H∞ norm
//! (by [`crate::system::hinf`], not by the synthesis formulas) must confirm the level.

use super::generalized_plant::{normalize, GeneralizedPlant, NormalizedPlant};
use super::hinf_gamma::{central_controller, gamma_test, GammaStep};
use crate::error::{Error, Result};
use crate::system::eig::{eigenvalues, spectral_abscissa};
use crate::system::hinf::hinf_norm;
use crate::system::ncf::NormalizedLcf;
use crate::system::{StateSpace, TransferFunction};
use nalgebra::DMatrix;
use serde::Serialize;

/// How the γ-iteration ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum IterationStatus {
    /// The bracket `[γ_lower, γ_opt]` is within the relative tolerance.
    Converged,
    /// The iteration cap was reached first: `γ_opt` is achievable, the gap to `γ_lower`
    /// is wider than asked.
    IterationCap,
    /// The optimum is the `ω = ∞` bound `σ̄(D₁₁₁₂)` (a lower bound on `γ_opt` for every
    /// controller), reached by the controller to 1e-6: `γ_lower` is that bound.
    AtInfinity,
    /// The controller reaches a level below one the Riccati equations declared not
    /// achievable (their Hamiltonians are ill-conditioned near the optimum): `γ_opt` is the
    /// controller's level, `γ_lower` falls back to the a-priori bound.
    RiccatiLimited,
}

/// Settings of the γ-iteration.
#[derive(Debug, Clone)]
pub struct WeightedSettings {
    /// The controller is built at `γ = gamma_factor · γ_opt` (≥ 1; the central controller is
    /// ill-conditioned at the optimum).
    pub gamma_factor: f64,
    /// Relative width of the final bracket `[γ_lower, γ_opt]`.
    pub rtol: f64,
    /// Cap on γ tests.
    pub max_iter: usize,
    /// Override of the starting bracket `(lower, upper)` for the bound as given (tests use
    /// a wide one; by default the Glover–McFarlane bounds of the module docs).
    pub bracket: Option<(f64, f64)>,
}

impl Default for WeightedSettings {
    fn default() -> Self {
        Self {
            gamma_factor: 1.1,
            rtol: 1e-7,
            max_iter: 100,
            bracket: None,
        }
    }
}

/// A controller synthesized for a frequency-dependent `r`.
#[derive(Debug, Clone, Serialize)]
pub struct WeightedController {
    /// The smallest level found achievable: `γ_opt` within `rtol`.
    pub gamma_opt: f64,
    /// The largest level found not achievable (`γ_opt ≥ gamma_lower`).
    pub gamma_lower: f64,
    /// `α_opt = 1/γ_opt`, the best Theorem 1 margin (normalized factors).
    pub alpha_opt: f64,
    /// The level of the central controller.
    pub gamma: f64,
    /// `‖r·T‖∞` of the closed loop with the controller, computed independently.
    pub gamma_achieved: f64,
    /// `1/gamma_achieved`.
    pub alpha_achieved: f64,
    /// How the iteration ended.
    pub status: IterationStatus,
    /// Every γ tested.
    pub steps: Vec<GammaStep>,
    /// `ρ(X∞Y∞)/γ²` at the controller's level.
    pub coupling: f64,
    /// The controller for `u = −K·y`.
    #[serde(skip)]
    pub k: StateSpace,
}

/// The generalized plant of `ncf` with `r/|r(∞)|` and the scale `|r(∞)|`; errors when `r`
/// is not a unit of RH∞.
pub fn weighted_plant(
    ncf: &NormalizedLcf,
    r: &TransferFunction,
) -> Result<(GeneralizedPlant, f64, StateSpace)> {
    if !r.is_unit() {
        return Err(Error::Invalid(
            "H∞ synthesis: r is not a unit of RH∞ (stable, minimum phase, biproper)".into(),
        ));
    }
    // Scale to the geometric mean of max |r| and min |r| (a unit: both from H∞ norms of
    // r and r⁻¹), so that the scaled weight spans 1/√range … √range.
    let raw = if r.den.degree() == 0 {
        StateSpace {
            a: DMatrix::zeros(0, 0),
            b: DMatrix::zeros(0, 1),
            c: DMatrix::zeros(1, 0),
            d: DMatrix::from_element(1, 1, r.at_infinity()),
        }
    } else {
        // A Gramian-balanced realization: the companion form of a fitted r (poles and zeros
        // spread over decades) makes the Hamiltonians too ill-conditioned for the Riccati
        // solver.
        let companion = StateSpace::from_tf(r).balanced();
        companion
            .balanced_truncation(companion.states())
            .map(|(b, _)| b)
            .unwrap_or(companion)
    };
    let r_max = hinf_norm(&raw)?.upper;
    let r_min = 1.0 / hinf_norm(&raw.inverse("r")?)?.upper;
    let scale = (r_max * r_min).sqrt();
    let rss = StateSpace {
        c: &raw.c / scale,
        d: &raw.d / scale,
        ..raw
    };
    Ok((GeneralizedPlant::weighted_factors(ncf, &rss), scale, rss))
}

/// The γ-iteration and the central controller for `r` (module docs); every failure is one
/// line.
pub fn synthesize_weighted(
    ncf: &NormalizedLcf,
    r: &TransferFunction,
    settings: &WeightedSettings,
) -> Result<WeightedController> {
    if !(settings.gamma_factor.is_finite() && settings.gamma_factor >= 1.0) {
        return Err(Error::Invalid(format!(
            "γ factor {}: must be a number ≥ 1",
            settings.gamma_factor
        )));
    }
    let (plant, scale, rss) = weighted_plant(ncf, r)?;
    let np = normalize(&plant)?;
    let (mut lo, mut hi) = match settings.bracket {
        Some((lo, hi)) => (lo / scale, hi / scale),
        None => {
            let gamma_gm = 1.0 / super::glover_mcfarlane::optimum(ncf)?.b_opt;
            let r_max = hinf_norm(&rss)?.upper;
            let r_min = 1.0 / hinf_norm(&rss.inverse("r")?)?.upper;
            (
                gamma_gm * r_min * (1.0 - 1e-6),
                gamma_gm * r_max * (1.0 + 1e-6),
            )
        }
    };
    let lo_apriori = lo;
    let mut steps = Vec::new();
    let test = |g: f64, steps: &mut Vec<GammaStep>| {
        let out = gamma_test(&np.plant, g);
        steps.push(GammaStep {
            gamma: g * scale,
            achievable: out.is_ok(),
            failure: out.as_ref().err().copied(),
        });
        out
    };
    // The upper end must be achievable: widen it (capped) if round-off says otherwise.
    let mut widen = 0;
    while test(hi, &mut steps).is_err() {
        widen += 1;
        if widen > 20 || steps.len() >= settings.max_iter {
            return Err(Error::Invalid(format!(
                "H∞ synthesis with r: no achievable γ up to {:.4e} ({:?} at the last level): the Riccati equations are too ill-conditioned",
                hi * scale,
                steps.last().and_then(|s| s.failure)
            )));
        }
        lo = lo.max(hi);
        hi *= 2.0;
    }
    let mut status = IterationStatus::Converged;
    while hi > lo * (1.0 + settings.rtol) {
        if steps.len() >= settings.max_iter {
            status = IterationStatus::IterationCap;
            break;
        }
        let mid = if lo > 0.0 { (lo * hi).sqrt() } else { 0.5 * hi };
        if test(mid, &mut steps).is_ok() {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // The central controller at factor·γ_opt, verified after the fact: the closed loop
    // must be stable and meet the level (its H∞ norm by crate::system::hinf, not by the
    // synthesis formulas). A level whose Riccati solutions are too inaccurate for that
    // (round-off near the optimum, or a spurious pass) is followed by a few higher ones.
    let mut last_error = String::new();
    let mut found = None;
    for bump in [1.0, 1.02, 1.05, 1.1, 1.25, 1.5, 2.0] {
        let gamma = hi * settings.gamma_factor * bump;
        match verified_controller(&np, &plant, gamma) {
            Ok((k_pos, achieved, rho)) => {
                found = Some((gamma, k_pos, achieved, rho));
                break;
            }
            Err(e) => last_error = e,
        }
    }
    let Some((gamma, k_pos, achieved, rho)) = found else {
        return Err(Error::Invalid(format!(
            "H∞ synthesis with r: no verified controller between {:.6e} and {:.6e} (last: {last_error}); the problem is too ill-conditioned",
            hi * settings.gamma_factor * scale,
            hi * settings.gamma_factor * 2.0 * scale
        )));
    };
    // A level the controller is proven to reach is achievable: near the ω = ∞ bound the
    // Riccati equations fail before the optimum (their Hamiltonians blow up), and the
    // controller may do better than the last level the bisection could certify.
    let floor = {
        let (_, _, mu, pz, _) = np.plant.dims();
        let d1112 = np.plant.d11.rows(0, pz - mu).into_owned();
        d1112.svd(false, false).singular_values.max()
    };
    let (hi, lo) = if achieved <= floor * (1.0 + 1e-6) {
        status = IterationStatus::AtInfinity;
        (achieved, floor)
    } else if achieved < lo {
        status = IterationStatus::RiccatiLimited;
        (achieved, lo_apriori.min(achieved))
    } else {
        (hi.min(achieved), lo)
    };
    let k = StateSpace {
        a: k_pos.a,
        b: k_pos.b,
        c: -k_pos.c,
        d: -k_pos.d,
    };
    Ok(WeightedController {
        gamma_opt: hi * scale,
        gamma_lower: lo * scale,
        alpha_opt: 1.0 / (hi * scale),
        gamma: gamma * scale,
        gamma_achieved: achieved * scale,
        alpha_achieved: 1.0 / (achieved * scale),
        status,
        steps,
        coupling: rho / (gamma * gamma),
        k,
    })
}

/// The central controller at `gamma` (for `u = +K·y`), its closed-loop level `‖T_zw‖∞` and
/// `ρ(X∞Y∞)`, when the loop is stable and meets `gamma` (to 1e-4: round-off near the
/// optimum); otherwise why not, in words.
fn verified_controller(
    np: &NormalizedPlant,
    plant: &GeneralizedPlant,
    gamma: f64,
) -> std::result::Result<(StateSpace, f64, f64), String> {
    let sol = gamma_test(&np.plant, gamma).map_err(|f| format!("{f:?} at this level"))?;
    let k_pos = central_controller(np, gamma, &sol).map_err(|e| e.to_string())?;
    let cl = plant.closed_loop(&k_pos).map_err(|e| e.to_string())?;
    let abscissa = eigenvalues(&cl.a, "H∞ synthesis: closed-loop poles")
        .map(|e| spectral_abscissa(&e))
        .map_err(|e| e.to_string())?;
    if abscissa.is_nan() || abscissa >= 0.0 {
        return Err(format!(
            "the central controller does not stabilize the plant (closed-loop pole with real part {abscissa:.3e})"
        ));
    }
    let achieved = hinf_norm(&cl).map_err(|e| e.to_string())?.upper;
    if achieved > gamma * (1.0 + 1e-4) {
        return Err(format!(
            "the central controller reaches {achieved:.6e}, above its level {gamma:.6e}"
        ));
    }
    Ok((k_pos, achieved, sol.rho))
}
