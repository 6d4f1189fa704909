//! Reports: text and CSV renderings of envelopes and checks, exports of a fitted `r`, and
//! `report.json` of a run.
//!
//! What is here (the submodules are private except [`fmt`]; everything below is re-exported
//! here):
//! * `envelope.csv` of an envelope: [`envelope_csv`] (a string) or [`write_envelope_csv`]
//!   (streamed), numbers by [`num`] (17 significant digits, so files round-trip);
//! * the exports of a fitted `r(s)`: [`write_fit_exports`] writes `r.json` ([`r_json`]),
//!   `r.m` ([`r_matlab`]), `r.py` ([`r_python`]) and `r.jl` ([`r_julia`]);
//! * `report.json` of `rshape run`: [`RunReport`] ([`ReportDatum`], [`Coeffs`],
//!   [`ClosedLoopFields`]);
//! * the `scaling` entry of the JSON outputs of a scaled config: [`ScalingNote`];
//! * number and message formatting shared by reports, figures and the CLI: [`fmt`].
pub(crate) mod csv;
pub(crate) mod export;
pub mod fmt;
pub(crate) mod run_report;
pub(crate) mod scaling_note;

pub use self::csv::{envelope_csv, num, write_envelope_csv};
pub use self::export::{r_json, r_julia, r_matlab, r_python, write_fit_exports};
pub use run_report::{ClosedLoopFields, Coeffs, ReportDatum, RunReport};
pub use scaling_note::ScalingNote;
