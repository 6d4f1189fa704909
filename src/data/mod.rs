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

/// Checks that the config's `[channel]` (`(output, input)`, 1-based) names a channel of
/// `p×m` data read from `path`: an index beyond the data is the `[channel]`'s fault, not a
/// size mismatch of the model.
pub fn check_channel(
    path: &std::path::Path,
    (output, input): (usize, usize),
    (p, m): (usize, usize),
) -> crate::error::Result<()> {
    if (1..=p).contains(&output) && (1..=m).contains(&input) {
        return Ok(());
    }
    Err(crate::error::Error::Invalid(format!(
        "[channel] output = {output}, input = {input} is not a channel of the data {} ({p} output(s) × {m} input(s)): give output in 1..={p} and input in 1..={m}",
        path.display()
    )))
}
