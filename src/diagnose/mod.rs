//! Model discovery: compare a model with the data, diagnose the missing physical effect,
//! add it, and watch the error fall.
//!
//! * [`compare`]: per-frequency misfit normalized by the noise radius, failing bands, error
//!   measures (`misfit_rms`, `invalid_fraction`, `r_env_max`);
//! * [`figures`]: Bode overlay and error-vs-revision SVGs.
pub mod compare;
pub mod figures;

pub use compare::{compare, prepare, CompareReport, PlantModel, Siso};
pub mod candidates;
pub mod engine;
pub mod fit;
pub mod nominal;
pub mod problem;
pub mod rank;
pub mod report;
mod starts;

pub use engine::{apply_candidate, diagnose, Diagnosis};
pub use nominal::{refit_nominal, NominalRefit};
