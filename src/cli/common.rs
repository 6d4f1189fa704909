//! Arguments and loading shared by the subcommands that read a model and data.

use crate::consistency::noisy::BisectionSettings;
use crate::consistency::{noise_free_envelope, noisy_envelope, Envelope};
use crate::data::FrfData;
use crate::model::noise::noise_radii;
use crate::model::Config;
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
    #[arg(long)]
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
    /// Loads the config and the data (from `--data` or the config).
    pub fn load(&self) -> Result<Inputs> {
        let config = Config::load(&self.config)?;
        let path = self
            .data
            .clone()
            .or_else(|| config.data.clone())
            .ok_or_else(|| {
                anyhow!(
                    "{}: no data file: add `data = \"FILE.csv\"` to the config or pass --data FILE",
                    self.config.display()
                )
            })?;
        let mut data = crate::pipeline::closed_loop::read_data(&config, &path)?;
        let f = &config.factorization;
        if let Some(ch) = config.raw.channel {
            let fits = (data.outputs(), data.inputs()) == (f.outputs(), f.inputs());
            if !fits
                && ch.output >= 1
                && ch.input >= 1
                && ch.output <= data.outputs()
                && ch.input <= data.inputs()
            {
                data = data.channel(ch.output - 1, ch.input - 1);
            }
        }
        if let Some(x) = self.noise_radius {
            if !(x.is_finite() && x >= 0.0) {
                return Err(anyhow!("--noise-radius {x}: must be a finite number ≥ 0"));
            }
        }
        Ok(Inputs { config, data })
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
