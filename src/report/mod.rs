//! Reports: text and CSV renderings of envelopes and checks, and `report.json` of a run.
pub mod csv;
pub mod run_report;

pub use self::csv::envelope_csv;
pub use run_report::RunReport;
