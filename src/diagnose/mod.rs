//! Model discovery: compare a model with the data, diagnose the missing physical effects,
//! add them, and watch the error fall.  The effects and their signatures are those of the
//! catalogue `docs/design/effects.md`.
//!
//! What is here, in the order of a `diagnose` run:
//! * [`channels`]: the data channels, each with its noise radius and model entry;
//!   [`plant_form`], [`factor_form`]: `[plant]` and factor-form configs converted to
//!   `[physical]`;
//! * [`compare`]: per-frequency misfit normalized by the noise radius, failing bands, error
//!   measures (`misfit_rms`, `invalid_fraction`, `r_env_max`); [`agreement`]: two data sets
//!   against each other;
//! * [`problem`]: the least-squares problem (base model, candidate effects, cost `V`);
//!   [`fit`]: Levenberg–Marquardt; `slots` (private): the parameters `retune` refits;
//! * [`retune`]: the joint refit of the configured model's own parameters;
//! * [`candidates`]: the catalogue of effects and how each modifies the model (`explain`,
//!   private: what each means in the data); `starts`
//!   (private): their starting points; [`rank`]: screening and physical plausibility;
//! * [`search`]: the beam search over effect sets with joint refits; [`polish`]: the
//!   consistency polish; [`ties`]: sets the data cannot tell apart; [`holdout`]: the
//!   final set checked on held-out data;
//! * [`engine`]: the whole `diagnose` (entry points [`diagnose`], [`diagnose_channels`],
//!   [`apply_candidate`]); [`report`]: what it reports; [`figures`]: Bode overlay of `compare`;
//!   [`history_figure`]: the error after each revision (`history`).
pub mod compare;
pub mod figures;

pub use compare::{compare, prepare, CompareReport, PlantModel, Siso};
pub mod agreement;
pub mod backward;
pub mod candidates;
pub mod changes;
pub mod channels;
pub mod engine;
mod explain;
pub mod factor_form;
pub mod final_effects;
mod first_level;
pub mod fit;
pub mod history_figure;
pub mod holdout;
pub mod plant_form;
pub mod polish;
pub mod problem;
pub mod rank;
pub mod report;
pub mod retune;
pub mod revision;
pub mod search;
mod slots;
mod starts;
pub mod ties;
mod varpro;

pub use channels::{misfit_channels, Channels};
pub use engine::{
    apply_candidate, apply_chosen, diagnose, diagnose_channels, DiagnoseVerdict, Diagnosis,
};
pub use retune::{refit_nominal, retune, retune_within, NominalRefit};
pub use search::SearchSettings;
