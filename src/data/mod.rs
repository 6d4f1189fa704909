//! Measured frequency-response data: the FRF set and its CSV reader; envelope CSV files.
pub mod closed_loop;
pub mod envelope_csv;
pub mod frf;
pub mod reader;
pub mod std_file;
pub mod table;

pub use envelope_csv::read_envelope_csv;
pub use frf::FrfData;
pub use reader::read_frf_csv;
