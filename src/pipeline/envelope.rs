//! The envelope of a config's data, chosen in one place for every subcommand: the
//! closed-loop envelope (Crowder & de Callafon) for a `[closed_loop]` config, otherwise
//! Boulet & Francis 1998: Theorem 4 (the μ bisection) when the resolved noise radii are not
//! all zero, else Theorem 2 or 3.  The noise radii follow the precedence of
//! [`crate::model::noise::noise_source`].

use super::closed_loop;
use super::integration;
use super::RunOptions;
use crate::consistency::closed_loop::ClosedLoopReport;
use crate::consistency::stream::noise_free_envelope_rows;
use crate::consistency::Envelope;
use crate::data::reader::FrfRows;
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::model::noise::is_noise_free;
use crate::model::Config;
use std::path::Path;

/// An envelope with what was resolved on the way.
#[derive(Debug, Clone)]
pub struct EnvelopeOutcome {
    /// Per-datum smallest consistent `|r|` (or `|V|` closed-loop) and the A1 limit.
    pub envelope: Envelope,
    /// Per-datum noise radii (`None`: noise-free).
    pub noise_radii: Option<Vec<f64>>,
    /// Warnings for the reader (data no `r` explains, uninformative closed-loop data).
    pub warnings: Vec<String>,
    /// Per-datum closed-loop diagnostics (closed-loop configs only).
    pub closed_loop: Option<ClosedLoopReport>,
}

/// The envelope of loaded data for a config: the one entry point of every subcommand and of
/// the library.  `options.noise_radius` is a global noise radius that overrides the config
/// (`--noise-radius`); `options.envelope_progress` hears of the data done by a noisy
/// envelope.  Noisy open-loop MIMO data are an error naming the data file: the paper's noisy
/// test (Theorem 4) is SISO.
pub fn envelope(
    config: &Config,
    data: &FrfData,
    options: &RunOptions<'_>,
) -> Result<EnvelopeOutcome> {
    let radii = integration::noise_radii(config, data, options.noise_radius)?;
    if radii.is_some()
        && config.closed_loop.is_none()
        && (data.outputs() != 1 || data.inputs() != 1)
    {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!(
                "noisy consistency (Theorem 4) is for SISO data, these are {}×{}; select a channel with [channel] or pass --noise-radius 0",
                data.outputs(),
                data.inputs(),
            ),
        });
    }
    let (envelope, warnings, closed_loop) =
        closed_loop::envelope_by_kind(config, data, radii.as_deref(), options.envelope_progress)?;
    Ok(EnvelopeOutcome {
        envelope,
        noise_radii: radii,
        warnings,
        closed_loop,
    })
}

/// The envelope of a data file, streamed when the noise-free theorems apply (an open-loop
/// config whose noise, by the precedence of [`crate::model::noise::noise_source`], is absent
/// or zero): memory then stays at about 56 bytes per datum whatever the file size.
/// Otherwise the data are read whole and [`envelope`] decides.
pub fn envelope_of_file(
    config: &Config,
    data_path: &Path,
    cli_noise: Option<f64>,
) -> Result<Envelope> {
    // Scaled data are read whole: the scaling applies to each datum before the envelope.
    if config.closed_loop.is_none() && config.scaling.is_none() {
        let rows = FrfRows::open(data_path)?.with_sample_time(config.sample_time());
        if cli_noise.is_none() {
            config.raw.noise.validate().map_err(|msg| Error::Config {
                path: config.path.clone(),
                msg,
            })?;
        }
        if is_noise_free(cli_noise, Some(config), rows.has_noise_column()) {
            let channel = config.raw.channel.map(|c| (c.output, c.input));
            return noise_free_envelope_rows(&config.factorization, rows, channel);
        }
    }
    let data = load_data(config, data_path)?;
    Ok(envelope(config, &data, &RunOptions::noise_radius(cli_noise))?.envelope)
}

/// Reads a config's data file (closed-loop spectra or FRF), applies its `[channel]` when
/// the data are larger than the model, then its `[scaling]` ([`prepare_data`]).
pub fn load_data(config: &Config, data_path: &Path) -> Result<FrfData> {
    prepare_data(config, read_data_file(config, data_path)?)
}

/// Data in the model's terms: the config's `[channel]` ([`select_channel`]), then its
/// `[scaling]` ([`scale_data`]).  The one place data read from a file or given as arrays
/// (the Python package) meet the model.
pub fn prepare_data(config: &Config, data: FrfData) -> Result<FrfData> {
    scale_data(config, select_channel(config, data)?)
}

/// `Φ_s = D_o·Φ·D_i` for a config with `[scaling]` (data of the model's size), the data
/// unchanged otherwise.  A size that does not fit is an error naming the key and the file.
pub fn scale_data(config: &Config, data: FrfData) -> Result<FrfData> {
    match &config.scaling {
        Some(s) => {
            let path = data.path.clone();
            s.frf(data).map_err(|msg| Error::Config {
                path: config.path.clone(),
                msg: format!("{msg} ({})", path.display()),
            })
        }
        None => Ok(data),
    }
}

/// Reads a data file of a config (closed-loop spectra or FRF) on the config's frequency
/// axis: normalized frequencies are divided by its `sample_time`.  No `[channel]` applied.
pub fn read_data_file(config: &Config, data_path: &Path) -> Result<FrfData> {
    let data = closed_loop::read_data(config, data_path)?;
    match config.sample_time() {
        Some(ts) => crate::data::denormalize_frf(data, ts),
        None => Ok(data),
    }
}

/// Applies a config's `[channel]` to data larger than the model, as [`load_data`] does for
/// a file (for data that come from elsewhere, e.g. arrays of the Python package).
pub fn select_channel(config: &Config, mut data: FrfData) -> Result<FrfData> {
    let f = &config.factorization;
    if let Some(ch) = config.raw.channel {
        let fits = (data.outputs(), data.inputs()) == (f.outputs(), f.inputs());
        if !fits {
            crate::data::check_channel(
                &data.path,
                (ch.output, ch.input),
                (data.outputs(), data.inputs()),
            )
            .map_err(|e| Error::Config {
                path: config.path.clone(),
                msg: e.to_string(),
            })?;
        }
        if !fits
            && ch.output >= 1
            && ch.input >= 1
            && ch.output <= data.outputs()
            && ch.input <= data.inputs()
        {
            data = data.channel(ch.output - 1, ch.input - 1);
        }
    }
    Ok(data)
}
