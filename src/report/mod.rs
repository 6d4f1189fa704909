//! Reports: text and CSV renderings of envelopes and checks; exports of a fitted `r`.
pub mod csv;
pub mod export;

pub use self::csv::envelope_csv;
pub use self::export::write_fit_exports;
