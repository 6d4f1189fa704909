//! Model discovery: compare a model with the data, diagnose the missing physical effects,
//! add them, and watch the error fall.  The effects and their signatures are those of the
//! catalogue `docs/design/effects.md`.
//!
//! In layers, each using only those below it (checked by `tests/docs/diagnose_layers.rs`):
//! * `effects`: the catalogue of effects, one file per effect implementing the `Effect`
//!   trait (`effect`) and one registration line each (`effects/mod.rs`; the how-to is
//!   docs/design/effects.md); `candidates`: the candidate `Cand` and what it dispatches to
//!   its effect; `explain`: what each means in the data; `lscf`: mode proposals from the
//!   residual by an LSCF stabilization diagram;
//! * `lsq`: the least squares: `channels` (the data channels, each with its noise radius
//!   and model entry), `measures` (error measures), `shapes` (a model's path and mode
//!   shapes), `problem` (base model, candidate effects, cost `V`), `starts` (each candidate's
//!   starting points), `lm` (Levenberg–Marquardt), `slots` (the parameters `retune` refits),
//!   `varpro` (variable projection), `mode_grid`, `retune` (the joint refit of the model's own
//!   parameters), `resolution`, `profile` and `whiteness` (what the record resolves of a
//!   damping, its profile likelihood, whether the residual is the stated noise);
//! * `search`: `rank` (screening and physical plausibility), `node` (an effect set written
//!   into the model), `beam` (the beam search over effect sets with joint refits),
//!   `first_level`, `polish` (the consistency polish), `ties` (sets the data cannot tell
//!   apart), `holdout` (the final set checked on held-out data), `choice` (the set kept after the
//!   holdout and the elimination), `backward` (backward
//!   elimination), `peaks` (every peak of the residual and its fate), `peak_modes` (a mode
//!   proposed at each peak), `assign` (added modes matched to the refit's), `final_effects`,
//!   `final_refit`;
//! * on top: `engine` (the whole `diagnose`: entry points [`diagnose`],
//!   [`diagnose_channels`], [`apply_candidate`]), `conclude` (after the search: the set kept,
//!   the report; [`conclude`] also concludes a search done elsewhere), `verdict` (the verdict and the stop
//!   explanation in words), `report` (what it reports; the per-peak account in
//!   `peak_account`), `changes` (the
//!   parameter changes and their σ), [`admissible`] (physical admissibility of a refit),
//!   `revision` (a revised config); beside them `compare` (per-frequency misfit normalized by
//!   the noise radius, failing bands, error measures `misfit_rms`, `invalid_fraction`,
//!   `r_env_max`), `agreement` (two data sets against each other), `plant_form` and
//!   `factor_form` (`[plant]` and factor-form configs converted to `[physical]`).
//!
//! Its figures (the Bode overlay of `compare`, the error after each revision of `history`)
//! are in [`crate::plot`].
pub mod admissible;
pub(crate) mod agreement;
pub(crate) mod changes;
pub(crate) mod compare;
pub(crate) mod conclude;
pub(crate) mod effects;
pub(crate) mod engine;
pub(crate) mod factor_form;
pub(crate) mod lsq;
pub(crate) mod peak_account;
pub(crate) mod plant_form;
pub(crate) mod progress;
pub(crate) mod report;
pub(crate) mod revision;
pub(crate) mod search;
pub(crate) mod verdict;

pub use agreement::{data_vs_data, AgreementVerdict, DataAgreement};
pub use changes::{changes, Changes, CommonGain, ParamChange};
pub use compare::{
    compare, misfit, prepare, Band, CompareReport, CompareRow, CompareVerdict, PlantModel, Siso,
};
pub use conclude::conclude;
pub use effects::candidates::{Cand, Sel, EFFECT_NAMES};
pub use engine::{apply_candidate, apply_chosen, diagnose, diagnose_channels};
pub use factor_form::physical_from_factors;
pub use lsq::channels::{misfit_channels, Channels};
pub use lsq::lm::{lm, LmResult};
pub use lsq::measures::Measures as ErrorMeasures;
pub use lsq::retune::{
    cost, refit_nominal, retune, retune_within, NominalRefit, ITERATING as RETUNE_ITERATING,
    PLACING as RETUNE_PLACING,
};
pub use plant_form::{physical_from_config, physical_from_tf, plant_tf, CONVERSION_TOL};
pub use progress::{DiagnoseOptions, DiagnoseProgress, DiagnoseProgressFn};
pub use report::{
    CandidateReport, DampingInterval, DiagnoseVerdict, Diagnosis, EffectSet, FinalEffect, Holdout,
    Peak, PeakFate, PeakProbe, PhaseTime, Phases, RefusedEffect, ResidualAccount, Retuned,
    SearchStats, Step, Tie,
};
pub use revision::{params_text, write_revision, Apply, Revise, Revision};
pub use search::backward::eliminate;
pub use search::beam::{SearchResult, SearchSettings};
pub use search::final_effects::final_effects;
pub use search::holdout::{model_of, same_set};
pub use search::node::{add_effect, Node};
pub use search::rank::candidate_list;

// The figures moved to `crate::plot`; their paths here are kept for the library's users.
pub use crate::plot::bode_overlay::{
    bode_overlay, bode_svg, dense_grid, unwrap_deg, BodeData, ModelCurve, FREQ_LABEL,
};
pub use crate::plot::history::{error_history, history_svg, model_name, revision_label};
