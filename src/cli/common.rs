//! Arguments and loading shared by the subcommands that read a model and data.

use crate::consistency::noisy::BisectionSettings;
use crate::consistency::stream::noise_free_envelope_rows;
use crate::consistency::{noise_free_envelope, noisy_envelope, Envelope};
use crate::data::reader::FrfRows;
use crate::data::FrfData;
use crate::model::noise::noise_radii;
use crate::model::Config;
use crate::util::OutputManifest;
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::PathBuf;

/// Model and data arguments.
#[derive(Debug, Args, Clone)]
pub struct InputArgs {
    /// The TOML config (model, r, data file, noise).
    pub config: PathBuf,
    /// Data file overriding the one named in the config.
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Global noise-disk radius L_a overriding the config (noisy SISO data, Theorem 4).
    #[arg(long, allow_negative_numbers = true)]
    pub noise_radius: Option<f64>,
}

/// A loaded config with its data.
pub struct Inputs {
    /// The config.
    pub config: Config,
    /// The data.
    pub data: FrfData,
}

impl InputArgs {
    /// The files this input reads: the config, `--data` and the data file the config names
    /// (an output the subcommand writes may not be one of them, [`check_out_file`]).
    pub fn files(&self) -> Vec<PathBuf> {
        let mut files = vec![self.config.clone()];
        files.extend(self.data.clone());
        files.extend(config_data(&self.config));
        files
    }

    /// Loads the config and the data (from `--data` or the config).
    pub fn load(&self) -> Result<Inputs> {
        let config = Config::load(&self.config)?;
        let path = self.data_path(&config)?;
        let mut data = crate::pipeline::closed_loop::read_data(&config, &path)?;
        let f = &config.factorization;
        if let Some(ch) = config.raw.channel {
            let fits = (data.outputs(), data.inputs()) == (f.outputs(), f.inputs());
            if !fits {
                crate::data::check_channel(
                    &data.path,
                    (ch.output, ch.input),
                    (data.outputs(), data.inputs()),
                )
                .map_err(|e| anyhow::anyhow!("{}: {e}", self.config.display()))?;
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
        self.check_noise_radius()?;
        Ok(Inputs { config, data })
    }

    /// The data file: `--data`, else the config's `data`.
    fn data_path(&self, config: &Config) -> Result<PathBuf> {
        self.data
            .clone()
            .or_else(|| config.data.clone())
            .ok_or_else(|| {
                anyhow!(
                    "{}: no data file: add `data = \"FILE.csv\"` to the config or pass --data FILE",
                    self.config.display()
                )
            })
    }

    fn check_noise_radius(&self) -> Result<()> {
        match self.noise_radius {
            Some(x) if !(x.is_finite() && x >= 0.0) => {
                Err(anyhow!("--noise-radius {x}: must be a finite number ≥ 0"))
            }
            _ => Ok(()),
        }
    }

    /// The envelope alone, as [`envelope`](Self::envelope) computes it, but with the data
    /// streamed when the noise-free theorems apply (no noise model, or all radii 0): then
    /// memory stays at about 56 bytes per datum whatever the file size.
    pub fn envelope_only(&self) -> Result<Envelope> {
        let config = Config::load(&self.config)?;
        self.check_noise_radius()?;
        if config.closed_loop.is_some() {
            return Ok(self.envelope()?.1);
        }
        let rows = FrfRows::open(&self.data_path(&config)?)?;
        let sec = &config.raw.noise;
        sec.validate()
            .map_err(|e| anyhow!("{}: {e}", self.config.display()))?;
        // The precedence of `model::noise::resolve_noise`: flag > config > data column.
        let noise_free = match (self.noise_radius, sec.radius) {
            (Some(x), _) | (None, Some(x)) => x == 0.0,
            (None, None) => {
                sec.output_bound.is_none() && config.noise_std.is_none() && !rows.has_noise_column()
            }
        };
        if !noise_free {
            return Ok(self.envelope()?.1);
        }
        let channel = config.raw.channel.map(|c| (c.output, c.input));
        Ok(noise_free_envelope_rows(
            &config.factorization,
            rows,
            channel,
        )?)
    }

    /// Loads inputs and computes the envelope that fits them: noise-free (Theorem 2 or 3),
    /// or noisy SISO (Theorem 4) when a nonzero noise radius is known (`--noise-radius`,
    /// else the config's `[noise]`, else the data's `noise_radius` column).
    pub fn envelope(&self) -> Result<(Inputs, Envelope)> {
        let inputs = self.load()?;
        let env = envelope_for(&inputs, self.noise_radius)?;
        Ok((inputs, env))
    }
}

/// The envelope of loaded inputs: Theorem 4 (μ bisection) when the resolved noise radii are
/// not all zero, else Theorem 2 or 3.  Noisy MIMO data are an error: the paper's noisy test
/// is SISO; select a channel (`[channel]`) or drop the noise (`--noise-radius 0`).
pub fn envelope_for(inputs: &Inputs, cli_noise: Option<f64>) -> Result<Envelope> {
    let f = &inputs.config.factorization;
    let data = &inputs.data;
    if inputs.config.closed_loop.is_some() {
        let radii = crate::pipeline::integration::noise_radii(&inputs.config, data, cli_noise)?;
        let (env, _, _) =
            crate::pipeline::closed_loop::envelope(&inputs.config, data, radii.as_deref())?;
        return Ok(env);
    }
    match noise_radii(cli_noise, Some(&inputs.config), data)? {
        Some(radii) if radii.iter().any(|r| *r > 0.0) => {
            if data.outputs() != 1 || data.inputs() != 1 {
                return Err(anyhow!(
                    "{}: noisy consistency (Theorem 4) is for SISO data, these are {}×{}; select a channel with [channel] or pass --noise-radius 0",
                    data.path.display(),
                    data.outputs(),
                    data.inputs()
                ));
            }
            Ok(noisy_envelope(
                f,
                data,
                &radii,
                &BisectionSettings::default(),
            )?)
        }
        _ => Ok(noise_free_envelope(f, data)?),
    }
}

pub use crate::report::fmt::{fmt_g, fmt_omegas};

/// Checks `--out DIR` before any work and clears the previous run's files there (see
/// [`OutputManifest`]).  `DIR` must not be an existing file, nor the folder of an input
/// (outputs would mix with inputs).  Keep the guard alive while the run writes.
pub fn prepare_out(out: &std::path::Path, inputs: &[&std::path::Path]) -> Result<OutputManifest> {
    if out.exists() && !out.is_dir() {
        return Err(anyhow!(
            "--out {}: is an existing file; give a folder (it is created if needed)",
            out.display()
        ));
    }
    if let Ok(o) = out.canonicalize() {
        for input in inputs {
            let folder = match input.canonicalize() {
                Ok(p) if p.is_dir() => p,
                Ok(p) => p.parent().map(|p| p.to_path_buf()).unwrap_or(p),
                Err(_) => continue,
            };
            if folder == o {
                return Err(anyhow!(
                    "--out {}: is the folder of the input {}; outputs would mix with inputs: choose a new folder such as {}",
                    out.display(),
                    input.display(),
                    out.join("out").display()
                ));
            }
        }
    }
    Ok(OutputManifest::begin(out)?)
}

/// Checks a single output file given by `flag` (`--svg FILE`, `--write FILE`) before any
/// work: it must not be an existing folder nor one of the inputs (a figure or a revised
/// config written over the config or the data would destroy it).  The file itself is
/// written atomically (temporary file + rename) by the writer.
pub fn check_out_file(
    flag: &str,
    path: &std::path::Path,
    inputs: &[impl AsRef<std::path::Path>],
) -> Result<()> {
    if path.is_dir() {
        return Err(anyhow!(
            "{flag} {}: is an existing folder; give a file name",
            path.display()
        ));
    }
    if let Ok(p) = path.canonicalize() {
        for input in inputs.iter().map(|i| i.as_ref()) {
            if input.canonicalize().is_ok_and(|i| i == p) {
                return Err(anyhow!(
                    "{flag} {}: is the input {}; writing there would destroy it: choose a new file name",
                    path.display(),
                    input.display()
                ));
            }
        }
    }
    Ok(())
}

/// The data file a config names (for the output checks), if it loads.
pub fn config_data(config: &std::path::Path) -> Option<PathBuf> {
    crate::model::Config::load(config).ok().and_then(|c| c.data)
}
