//! Measured frequency-response data: the FRF set and its CSV reader.
pub mod frf;
pub mod reader;
pub mod std_file;

pub use frf::FrfData;
pub use reader::read_frf_csv;
