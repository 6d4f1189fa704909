//! Model discovery: compare a model with the data, diagnose the missing physical effects,
//! add them, and watch the error fall.  The effects and their signatures are those of the
//! catalogue `docs/design/effects.md`.
//!
//! What is here, in the order of a `diagnose` run:
//! * `channels`: the data channels, each with its noise radius and model entry;
//!   `plant_form`, `factor_form`: `[plant]` and factor-form configs converted to
//!   `[physical]`;
//! * `compare`: per-frequency misfit normalized by the noise radius, failing bands, error
//!   measures (`misfit_rms`, `invalid_fraction`, `r_env_max`); `agreement`: two data sets
//!   against each other;
//! * `problem`: the least-squares problem (base model, candidate effects, cost `V`);
//!   `fit`: Levenberg–Marquardt; `slots` (private): the parameters `retune` refits;
//! * `retune`: the joint refit of the configured model's own parameters;
//! * `candidates`: the catalogue of effects and how each modifies the model (`explain`,
//!   private: what each means in the data); `starts`
//!   (private): their starting points (`lscf`, private: mode proposals from the residual by
//!   an LSCF stabilization diagram); `rank`: screening and physical plausibility;
//! * `search`: the beam search over effect sets with joint refits; `polish`: the
//!   consistency polish; `ties`: sets the data cannot tell apart; `holdout`: the
//!   final set checked on held-out data; `peaks`: every peak of the residual and its fate;
//! * `engine`: the whole `diagnose` (entry points [`diagnose`], [`diagnose_channels`],
//!   [`apply_candidate`]); `report`: what it reports; `figures`: Bode overlay of `compare`;
//!   `history_figure`: the error after each revision (`history`).
pub(crate) mod compare;
pub(crate) mod figures;

pub use compare::{compare, prepare, CompareReport, PlantModel, Siso};
pub mod admissible;
pub(crate) mod agreement;
pub(crate) mod assign;
pub(crate) mod backward;
pub(crate) mod candidates;
pub(crate) mod changes;
pub(crate) mod channels;
pub(crate) mod engine;
mod explain;
pub(crate) mod factor_form;
pub(crate) mod final_effects;
mod first_level;
pub(crate) mod fit;
pub(crate) mod history_figure;
pub(crate) mod holdout;
pub(crate) mod lscf;
pub(crate) mod peaks;
pub(crate) mod plant_form;
pub(crate) mod polish;
pub(crate) mod problem;
pub(crate) mod rank;
pub(crate) mod report;
pub(crate) mod retune;
pub(crate) mod revision;
pub(crate) mod search;
mod slots;
mod starts;
pub(crate) mod ties;
mod varpro;

pub use agreement::{data_vs_data, AgreementVerdict, DataAgreement};
pub use backward::eliminate;
pub use candidates::{Cand, Sel, EFFECT_NAMES};
pub use changes::{changes, Changes, CommonGain, ParamChange};
pub use channels::{misfit_channels, Channels};
pub use compare::{misfit, Band, CompareRow, CompareVerdict};
pub use engine::{apply_candidate, apply_chosen, diagnose, diagnose_channels};
pub use factor_form::physical_from_factors;
pub use figures::{
    bode_overlay, bode_svg, dense_grid, unwrap_deg, BodeData, ModelCurve, FREQ_LABEL,
};
pub use final_effects::final_effects;
pub use fit::{lm, LmResult};
pub use history_figure::{error_history, history_svg, model_name, revision_label};
pub use holdout::{model_of, same_set};
pub use plant_form::{physical_from_config, physical_from_tf, plant_tf, CONVERSION_TOL};
pub use problem::Measures as ErrorMeasures;
pub use rank::candidate_list;
pub use report::{
    CandidateReport, DiagnoseVerdict, Diagnosis, EffectSet, FinalEffect, Holdout, Peak, PeakFate,
    PeakProbe, PhaseTime, Phases, RefusedEffect, Retuned, SearchStats, Step, Tie,
};
pub use retune::cost;
pub use retune::{refit_nominal, retune, retune_within, NominalRefit};
pub use revision::{params_text, write_revision, Apply, Revise, Revision};
pub use search::{add_effect, Node, SearchSettings};
