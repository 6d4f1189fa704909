//! Reports: text and CSV renderings of envelopes and checks, exports of a fitted `r`, and
//! `report.json` of a run.
pub mod csv;
pub mod export;
pub mod fmt;
pub mod run_report;

pub use self::csv::envelope_csv;
pub use self::export::write_fit_exports;
pub use run_report::RunReport;
