//! What `rshape diagnose` reports: the retune, the ranked first-level candidates, the chosen
//! effect set with its runner-ups and ties, the path that led to it, the final holdout and
//! the verdict (the JSON names of the `--json` output).

use crate::diagnose::changes::Changes;
use crate::diagnose::compare::Band;
use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::lsq::measures::Measures;
use crate::model::physical::PhysicalModel;
use serde::Serialize;
use std::collections::BTreeMap;

pub use super::peak_account::{Peak, PeakFate, PeakProbe};

/// A fitted candidate of the first level (on top of the retuned model), or the retune.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateReport {
    /// Rank (1-based, by ΔBIC against the configured model).
    pub rank: usize,
    /// Effect name (`retune`, `mode`, `delay`, `delay (output 2)` …).
    pub effect: String,
    /// Fitted parameters in SI units (frequencies in rad/s); empty when there is no fit.
    pub params: BTreeMap<String, f64>,
    /// Two standard deviations of each fitted parameter (from `(2JᵀJ)⁻¹`, the candidate
    /// fitted alone).
    pub uncertainty_2sigma: BTreeMap<String, f64>,
    /// Cost of the configured model.
    pub v_before: f64,
    /// Cost of the least-squares fit with the candidate (after the joint refit when
    /// `joint_refit`); the measures after are those of its consistency polish when that made
    /// it consistent.
    pub v_after: f64,
    /// Error measures of the configured model.
    pub misfit_rms_before: f64,
    /// With the candidate.
    pub misfit_rms_after: f64,
    /// Invalid fraction of the configured model.
    pub invalid_fraction_before: f64,
    /// With the candidate.
    pub invalid_fraction_after: f64,
    /// `2(V_configured − V) − n_new·ln(2F)`: the score every candidate (the retune too) is
    /// ranked by.
    pub delta_bic: f64,
    /// The same against the retuned model (the acceptance test of an added effect).
    pub delta_bic_vs_retune: f64,
    /// Number of new parameters (0 for the retune).
    pub n_params: usize,
    /// True when the numbers are after the joint refit of every parameter.
    pub joint_refit: bool,
    /// Passes: ΔBIC > 10 against the retuned model (the configured one for the retune),
    /// no more invalid data or a lower `misfit_rms` (`rank::improves`),
    /// physically plausible (no flags).
    pub passes: bool,
    /// Within 6 BIC of the best candidate.
    pub tie_with_best: bool,
    /// Plausibility flags (a parameter at its bound, a mode outside the band).
    pub flags: Vec<String>,
    /// Why there is no usable fit (`None` when there is one).
    pub no_fit: Option<String>,
    /// Plain-language signature.
    pub explanation: String,
    /// Bands the candidate explains (invalid before, valid after).
    pub explained_bands: Vec<Band>,
    /// The candidate (`None` for the retune).
    #[serde(skip)]
    pub cand: Option<Cand>,
    /// The ΔBIC it had to exceed (the search settings').
    #[serde(skip)]
    pub min_delta_bic: f64,
    /// The revised model (candidate added, jointly refit when `joint_refit`).
    #[serde(skip)]
    pub model: PhysicalModel,
}

impl CandidateReport {
    /// Why the tool rejected this candidate (`None` when it passes): no fit, a plausibility
    /// flag, too small a ΔBIC, or more invalid data than the retune alone without a clear fall
    /// of `misfit_rms` (`rank::improves`).
    pub fn rejection(&self) -> Option<String> {
        if self.passes {
            return None;
        }
        Some(if let Some(why) = &self.no_fit {
            format!("no fit ({why})")
        } else if !self.flags.is_empty() {
            self.flags.join("; ")
        } else if self.cand.is_none() {
            format!(
                "the refit lowers the cost too little (ΔBIC {:.3} ≤ {})",
                self.delta_bic, self.min_delta_bic
            )
        } else if self.delta_bic_vs_retune <= self.min_delta_bic {
            format!(
                "ΔBIC {:.3} against the retune alone (needs > {})",
                self.delta_bic_vs_retune, self.min_delta_bic
            )
        } else {
            format!(
                "more invalid data than the retune alone ({:.1} % with it) and misfit_rms not lower",
                100.0 * self.invalid_fraction_after
            )
        })
    }
}

/// An effect refused by physical admissibility, at the search level (`step`) it was met.
#[derive(Debug, Clone, Serialize)]
pub struct RefusedEffect {
    /// Search level (1 = on the configured or retuned model); for a refusal of the kept
    /// set's re-check, the step the effect had in the chosen path.
    pub step: usize,
    /// The refusal.
    #[serde(flatten)]
    pub refusal: crate::diagnose::admissible::Refusal,
    /// Refused when the set the holdout and the backward elimination left was re-checked on
    /// its own refit (`search::recheck`), and removed from it; absent from JSON otherwise.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub in_kept_set: bool,
}

/// A tie between two effects or two effect sets.
#[derive(Debug, Clone, Serialize)]
pub struct Tie {
    /// The two effects (or sets, joined by ` + `).
    pub effects: [String; 2],
    /// BIC gap.
    pub bic_gap: f64,
    /// Which measurement tells them apart.
    pub disambiguation: String,
    /// The nearest frequency above the band (rad/s) where the two fitted models differ by
    /// more than the noise (`None`: not within two decades).
    pub separates_above: Option<f64>,
    /// The same below the band.
    pub separates_below: Option<f64>,
}

/// One step of the chosen path.
#[derive(Debug, Clone, Serialize)]
pub struct Step {
    /// 1-based.
    pub step: usize,
    /// Added effect.
    pub effect: String,
    /// Its parameters after this step's joint refit.
    pub params: BTreeMap<String, f64>,
    /// Its parameters fitted alone on the previous model (before the joint refit).
    pub params_fitted_alone: BTreeMap<String, f64>,
    /// Explanation.
    pub explanation: String,
    /// Measures after the step (effect added and every parameter refit jointly).
    pub misfit_rms: f64,
    /// After the step.
    pub invalid_fraction: f64,
    /// ΔBIC of the step after the joint refit.
    pub delta_bic: f64,
    /// `misfit_rms` with the effect added, before the joint refit.
    pub misfit_rms_before_refit: f64,
    /// `invalid_fraction` before the joint refit.
    pub invalid_fraction_before_refit: f64,
    /// Number of parameters refit jointly.
    pub n_refit: usize,
    /// Ties reported at this step (kept for compatibility; set ties are in `Diagnosis::ties`).
    pub ties: Vec<Tie>,
}

/// An effect set explored by the search.
#[derive(Debug, Clone, Serialize)]
pub struct EffectSet {
    /// The effects (in the order added).
    pub effects: Vec<String>,
    /// `2V + n_θ ln(2F)` of the jointly refit model.
    pub bic: f64,
    /// BIC minus the chosen set's.
    pub bic_gap: f64,
    /// Measures.
    pub misfit_rms: f64,
    /// Measures.
    pub invalid_fraction: f64,
    /// Explained within the noise.
    pub consistent: bool,
}

/// An effect in the final model, with its parameters after the joint refit.
#[derive(Debug, Clone, Serialize)]
pub struct FinalEffect {
    /// Effect label.
    pub effect: String,
    /// Parameters (SI, rad/s).
    pub params: BTreeMap<String, f64>,
    /// One standard deviation of each refit parameter (those with one).
    pub sigma: BTreeMap<String, f64>,
}

/// The final-set holdout of one effect.
#[derive(Debug, Clone, Serialize)]
pub struct Holdout {
    /// Effect label.
    pub effect: String,
    /// Fitted on 3 of every 4 data, the held-out quarter's `V` is lower with the effect than
    /// without it.
    pub interleaved_ok: bool,
    /// Multiplicative effects: fitted below 70 % of the band, the top 30 % is predicted
    /// better with it (`None` for additive effects or too few data).
    pub extrapolation_ok: Option<bool>,
}

/// Search statistics.
#[derive(Debug, Clone, Serialize, Default)]
pub struct SearchStats {
    /// Beam width.
    pub beam: usize,
    /// Nodes whose candidates were screened.
    pub nodes_expanded: usize,
    /// Joint refits of every parameter.
    pub joint_refits: usize,
    /// Joint refits given up: still above three times their reference cost after 10
    /// iterations (they could not pass).
    pub refits_given_up: usize,
    /// The groups of modes proposed together in one step (every mode fitted alone at a node
    /// that would pass the screen; `diagnose::search::multi_mode`), Hz, one list per joint
    /// refit, whatever became of them.
    pub mode_groups_hz: Vec<Vec<f64>>,
    /// Wall time, s.
    pub seconds: f64,
    /// Wall time of each phase, in the order they ran (`--verbose` prints the table).
    pub phases: Vec<PhaseTime>,
}

/// The wall time of one phase of `diagnose`.
#[derive(Debug, Clone, Serialize)]
pub struct PhaseTime {
    /// What ran: `retune` (with the configured model's screen beside it), `screen` (each
    /// candidate fitted alone on the other nodes), `joint refits` (with
    /// their consistency polish), `first level`, `holdout`, `backward elimination`,
    /// `final refit`, `ties`, `report`.
    pub phase: &'static str,
    /// Seconds.
    pub seconds: f64,
    /// How many times it ran (screened nodes, refits).
    pub count: usize,
}

/// Accumulates [`PhaseTime`]s.
#[derive(Debug, Clone, Default)]
pub struct Phases(pub Vec<PhaseTime>);

impl Phases {
    /// Adds `seconds` (and `count` runs) to `phase`.
    pub fn add(&mut self, phase: &'static str, seconds: f64, count: usize) {
        match self.0.iter_mut().find(|p| p.phase == phase) {
            Some(p) => {
                p.seconds += seconds;
                p.count += count;
            }
            None => self.0.push(PhaseTime {
                phase,
                seconds,
                count,
            }),
        }
    }

    /// Runs `f`, adding its wall time to `phase`.
    pub fn time<T>(&mut self, phase: &'static str, f: impl FnOnce() -> T) -> T {
        let t = std::time::Instant::now();
        let out = f();
        self.add(phase, t.elapsed().as_secs_f64(), 1);
        out
    }
}

/// The verdict of `diagnose` (serialized in snake_case).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DiagnoseVerdict {
    /// The configured model explains the data within the noise: nothing to do.
    Consistent,
    /// The refit of the configured parameters explains the data: nothing added.
    Retuned,
    /// A set of effects was chosen.
    EffectsFound,
    /// Neither the retune nor any catalogue effect explains the data.
    NoEffectFound,
}

impl DiagnoseVerdict {
    /// The snake_case name (as in the JSON).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Consistent => "consistent",
            Self::Retuned => "retuned",
            Self::EffectsFound => "effects_found",
            Self::NoEffectFound => "no_effect_found",
        }
    }
}

impl std::fmt::Display for DiagnoseVerdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Compares with the JSON name (`verdict == "effects_found"`), for scripts and tests that
/// read the report.
impl PartialEq<&str> for DiagnoseVerdict {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

/// The diagnosis.
#[derive(Debug, Clone, Serialize)]
pub struct Diagnosis {
    /// The verdict ([`DiagnoseVerdict`]).
    pub verdict: DiagnoseVerdict,
    /// Human summary.
    pub message: String,
    /// Number of complex data (frequencies × channels).
    pub n_data: usize,
    /// Number of channels diagnosed jointly.
    pub n_channels: usize,
    /// Measures of the model as given.
    pub before: Measures,
    /// Measures after the retune (no effect added), and the configured parameters it moved.
    pub retuned: Retuned,
    /// Measures of the final model.
    pub after: Measures,
    /// First-level candidates (the retune and each effect on top of it), ranked (what
    /// `--apply K` refers to).
    pub candidates: Vec<CandidateReport>,
    /// Ties among the first-level candidates and between the chosen set and a runner-up.
    pub ties: Vec<Tie>,
    /// The chosen path.
    pub steps: Vec<Step>,
    /// The chosen effect set.
    pub chosen: Vec<String>,
    /// The next best sets.
    pub runner_up: Vec<EffectSet>,
    /// Final-set holdout per effect.
    pub holdout: Vec<Holdout>,
    /// Effects the final holdout removed.
    pub dropped: Vec<String>,
    /// Effects the backward elimination removed (the data do not need them: ΔBIC ≤ 10).
    pub eliminated: Vec<String>,
    /// Every chosen effect (in `chosen` order) with its parameters in the final model and
    /// their σ.
    pub final_effects: Vec<FinalEffect>,
    /// The configured parameters the final joint refit (of the chosen set) moved.
    pub retuned_in_chosen: Changes,
    /// Effects the likelihood wanted but physical admissibility refused (on their joint
    /// refit), each with its rule and reason ([`crate::diagnose::admissible`]).
    pub refused: Vec<RefusedEffect>,
    /// Modes of the final model whose damping the data do not identify: the likelihood is
    /// flat from the record's floor up (`lsq::profile`).
    pub dampings_not_identified: Vec<DampingInterval>,
    /// When nothing admissible passes (`no_effect_found`): what the remaining misfit is
    /// (`lsq::whiteness`); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual: Option<ResidualAccount>,
    /// Expected `V` of a right model (`F − n_θ/2`, F complex data), and the achieved `V`.
    pub cost_test: Option<[f64; 2]>,
    /// Every peak of the residual that stands out of the noise, with its fate (at most
    /// `peaks::MAX_PEAKS`, the highest).
    pub peaks: Vec<Peak>,
    /// Peaks found but not listed.
    pub peaks_not_listed: usize,
    /// Search statistics.
    pub search: SearchStats,
    /// The final model (effects added, everything refit jointly).
    #[serde(skip)]
    pub final_model: PhysicalModel,
}

/// What the residual of a stop is (`lsq::whiteness`), for the verdict `no_effect_found`: its
/// level against the stated noise and whether it is white along frequency.
#[derive(Debug, Clone, Serialize)]
pub struct ResidualAccount {
    /// `V/E[V]`: 1 at the stated noise.
    pub level: f64,
    /// The complex Ljung–Box statistic `Q` over `lags` lags per channel, and its
    /// `1 − α` quantile (α = 1e-3).
    pub ljung_box_q: f64,
    /// The quantile `Q` is compared with.
    pub q_critical: f64,
    /// Lags per channel.
    pub lags: usize,
    /// `Q ≤ q_critical`: no structure is left along frequency.
    pub white: bool,
    /// `white_at_noise` (nothing more to find), `scatter_above_noise` (white but above the
    /// stated σ: a `std_factor`), `structured` (missing dynamics), `outlier_line` (one line
    /// holds half of `V` or more: a spectral line or a dropout there).
    pub kind: &'static str,
    /// Where a structured residual concentrates, Hz (absent when white or spread).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub concentrated_hz: Option<[f64; 2]>,
    /// `V` per datum there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub concentrated_level: Option<f64>,
    /// For `scatter_above_noise`: the factor `√(V/E[V])` by which `std_factor` (or the
    /// noise radius) would have to grow to cover the scatter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub std_factor_times: Option<f64>,
    /// For `outlier_line`: the line's frequency, Hz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outlier_hz: Option<f64>,
    /// For `outlier_line`: its share of `V`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outlier_share: Option<f64>,
}

/// A damping the data do not identify (`lsq::profile`): every `ζ` from
/// the record's floor to `zeta_upper` is supported (95 % likelihood-ratio interval); the
/// model carries the interval's log-midpoint.
#[derive(Debug, Clone, Serialize)]
pub struct DampingInterval {
    /// The mode's frequency, Hz.
    pub frequency_hz: f64,
    /// The record's floor at the mode (the interval's bottom).
    pub zeta_floor: f64,
    /// The interval's top.
    pub zeta_upper: f64,
    /// The damping written (the log-midpoint).
    pub zeta_written: f64,
    /// The profile: `(ζ, V_p(ζ) − V_p(floor))` at every point profiled, and the rise that
    /// bounds the interval.
    pub profile: Vec<[f64; 2]>,
    /// The rise of `V` that bounds the interval (`½ χ²₁(0.95)`, widened by the residual's
    /// own level when it exceeds the noise).
    pub threshold: f64,
    /// In words.
    pub reason: String,
}

/// The retune: its measures and what it moved (`retuned.changes` in the JSON).
#[derive(Debug, Clone, Serialize)]
pub struct Retuned {
    /// Error measures after the retune.
    #[serde(flatten)]
    pub measures: Measures,
    /// The configured parameters it moved by more than 3σ.
    #[serde(flatten)]
    pub moved: Changes,
}

impl std::ops::Deref for Retuned {
    type Target = Measures;
    fn deref(&self) -> &Measures {
        &self.measures
    }
}
