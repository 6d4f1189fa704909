//! What `rshape diagnose` reports: ranked candidates, ties, the greedy steps and the
//! verdict (the JSON names of the `--json` output).

use super::candidates::Cand;
use super::compare::Band;
use super::problem::{Measures, Mods};
use crate::model::physical::PhysicalModel;
use serde::Serialize;
use std::collections::BTreeMap;

/// A fitted candidate.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateReport {
    /// Rank (1-based, by ΔBIC).
    pub rank: usize,
    /// Effect name.
    pub effect: String,
    /// Fitted parameters in SI units (frequencies in rad/s).
    pub params: BTreeMap<String, f64>,
    /// Two standard deviations of each fitted parameter (from `(2JᵀJ)⁻¹`).
    pub uncertainty_2sigma: BTreeMap<String, f64>,
    /// Cost before and after.
    pub v_before: f64,
    /// Cost after.
    pub v_after: f64,
    /// Error measures before.
    pub misfit_rms_before: f64,
    /// After.
    pub misfit_rms_after: f64,
    /// Invalid fraction before.
    pub invalid_fraction_before: f64,
    /// After.
    pub invalid_fraction_after: f64,
    /// `2(V₀ − V) − n_θ ln(2F)`.
    pub delta_bic: f64,
    /// Number of new parameters.
    pub n_params: usize,
    /// Both holdout checks pass (`holdout_interleaved_ok` and, for a global candidate,
    /// `holdout_extrapolation_ok`).
    pub holdout_ok: bool,
    /// Fitted on 3 of every 4 data, the held-out quarter's `V` falls.
    pub holdout_interleaved_ok: bool,
    /// Global (multiplicative) candidates only: fitted below 70 % of the band (log
    /// frequency), the top 30 % is predicted better than by the model without it. `None`
    /// for local candidates, or when either part holds fewer than 8 data.
    pub holdout_extrapolation_ok: Option<bool>,
    /// Passes all acceptance tests.
    pub passes: bool,
    /// Within 6 BIC of the best candidate.
    pub tie_with_best: bool,
    /// Plain-language signature.
    pub explanation: String,
    /// Bands the candidate explains (invalid before, valid after).
    pub explained_bands: Vec<Band>,
    /// The candidate itself.
    #[serde(skip)]
    pub cand: Cand,
    /// All parameters of the jointly refit model (accepted effects first).
    #[serde(skip)]
    pub mods: Mods,
}

/// A tie between the best candidate and another.
#[derive(Debug, Clone, Serialize)]
pub struct Tie {
    /// The two effects.
    pub effects: [String; 2],
    /// BIC gap.
    pub bic_gap: f64,
    /// Which measurement tells them apart.
    pub disambiguation: String,
}

/// One greedy step.
#[derive(Debug, Clone, Serialize)]
pub struct Step {
    /// 1-based.
    pub step: usize,
    /// Accepted effect.
    pub effect: String,
    /// Its parameters (after the joint refit).
    pub params: BTreeMap<String, f64>,
    /// Explanation.
    pub explanation: String,
    /// Measures after the step (effect added and every parameter refit jointly).
    pub misfit_rms: f64,
    /// After the step.
    pub invalid_fraction: f64,
    /// ΔBIC of the step (the effect alone, before the joint refit).
    pub delta_bic: f64,
    /// `misfit_rms` with the effect added, before the joint refit of the nominal parameters.
    pub misfit_rms_before_refit: f64,
    /// `invalid_fraction` before the joint refit.
    pub invalid_fraction_before_refit: f64,
    /// Number of parameters refit jointly (the model's own and every accepted effect's).
    pub n_refit: usize,
    /// Ties reported at this step.
    pub ties: Vec<Tie>,
}

/// The diagnosis.
#[derive(Debug, Clone, Serialize)]
pub struct Diagnosis {
    /// `consistent` (nothing to add), `effects_found`, or `no_effect_found` (inconsistent,
    /// but no candidate passes).
    pub verdict: String,
    /// Human summary.
    pub message: String,
    /// Number of data.
    pub n_data: usize,
    /// Measures of the model as given.
    pub before: Measures,
    /// Measures after the accepted effects.
    pub after: Measures,
    /// Candidates of the first step, ranked (what `--apply K` refers to).
    pub candidates: Vec<CandidateReport>,
    /// Ties among the first-step candidates.
    pub ties: Vec<Tie>,
    /// The greedy path.
    pub steps: Vec<Step>,
    /// Expected `V` of a right model (`F − n_θ/2`), and the achieved `V`.
    pub cost_test: Option<[f64; 2]>,
    /// The model after the greedy steps (effects added, everything refit jointly).
    #[serde(skip)]
    pub final_model: PhysicalModel,
}
