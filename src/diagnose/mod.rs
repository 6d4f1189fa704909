//! Model discovery: compare a model with the data, diagnose the missing physical effects,
//! add them, and watch the error fall.
//!
//! * [`compare`]: per-frequency misfit normalized by the noise radius, failing bands, error
//!   measures (`misfit_rms`, `invalid_fraction`, `r_env_max`); [`agreement`]: two data sets
//!   against each other;
//! * [`retune`], [`search`], [`engine`]: refit the configured model, search effect sets,
//!   report;
//! * [`figures`]: Bode overlay and error-vs-revision SVGs.
pub mod compare;
pub mod figures;

pub use compare::{compare, prepare, CompareReport, PlantModel, Siso};
pub mod agreement;
pub mod backward;
pub mod candidates;
pub mod changes;
pub mod channels;
pub mod engine;
pub mod factor_form;
pub mod final_effects;
pub mod fit;
pub mod holdout;
pub mod plant_form;
pub mod polish;
pub mod problem;
pub mod rank;
pub mod report;
pub mod retune;
pub mod search;
mod slots;
mod starts;
pub mod ties;

pub use channels::{misfit_channels, Channels};
pub use engine::{apply_candidate, apply_chosen, diagnose, diagnose_channels, Diagnosis};
pub use retune::{refit_nominal, retune, retune_within, NominalRefit};
pub use search::Settings;
