//! Reports: text and CSV renderings of envelopes and checks.
pub mod csv;

pub use self::csv::envelope_csv;
