//! Measured frequency-response data: the FRF set and its CSV reader; envelope CSV files.
//!
//! What is here (the submodules are private; everything below is re-exported here):
//! * the data: [`FrfData`], the measurements `Φ_i = G_p(jω_i)` (BF98 Sec. II) with their
//!   file lines and optional noise radii;
//! * FRF CSV files (`omega_rad_s` or `freq_hz`, then `re_i_j,im_i_j` or
//!   `mag_i_j,phase_deg_i_j`, optional `noise_radius`): [`read_frf_csv`] and
//!   [`parse_frf_csv`], or one datum ([`Datum`]) at a time with [`FrfRows`] for files too
//!   large to hold; channel indices up to [`MAX_CHANNEL`]; the config's `[channel]` checked
//!   by [`check_channel`];
//! * closed-loop files (Crowder & de Callafon eqs. (8)–(9)), a `Φ_cl` FRF or the spectra
//!   `Y`, `R` ([`SPECTRA_COLUMNS`]): [`read_closed_loop_csv`], [`parse_closed_loop_csv`];
//! * standard-deviation and coherence files, turned into noise radii: [`read_std_csv`],
//!   [`read_coherence_csv`] ([`StdData`]) and [`h1_random_error`];
//! * normalized frequency axes (cycles or radians per sample, the config's `sample_time`):
//!   [`denormalize_frf`], [`denormalize_std`], [`check_sample_time`];
//! * envelope CSV files (`omega_rad_s,r_min[,a1_limit]`, as `rshape envelope` writes them):
//!   [`read_envelope_csv`], [`parse_envelope_csv`];
//! * the CSV layer under all of them, every error naming file and line: [`TableReader`]
//!   (records streamed from any reader, at most [`MAX_RECORD_BYTES`] bytes and
//!   [`MAX_RECORD_FIELDS`] fields each) and [`read_text`] (UTF-8 or UTF-16 text).
pub(crate) mod closed_loop;
pub(crate) mod envelope_csv;
pub(crate) mod frf;
pub(crate) mod reader;
pub(crate) mod sample_time;
pub(crate) mod std_file;
pub(crate) mod table;

pub use closed_loop::{parse_closed_loop_csv, read_closed_loop_csv, SPECTRA_COLUMNS};
pub use envelope_csv::{parse_envelope_csv, read_envelope_csv};
pub use frf::FrfData;
pub use reader::{parse_frf_csv, read_frf_csv, Datum, FrfRows, MAX_CHANNEL};
pub use sample_time::{check_sample_time, denormalize_frf, denormalize_std};
pub use std_file::{h1_random_error, read_coherence_csv, read_std_csv, StdData};
pub use table::{read_text, TableReader, MAX_RECORD_BYTES, MAX_RECORD_FIELDS};

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
