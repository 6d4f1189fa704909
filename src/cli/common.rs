//! Arguments and loading shared by the subcommands that read a model and data.

use crate::consistency::{noise_free_envelope, Envelope};
use crate::data::{read_frf_csv, FrfData};
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
        let data = read_frf_csv(&path)?;
        if let Some(x) = self.noise_radius {
            if !(x.is_finite() && x >= 0.0) {
                return Err(anyhow!("--noise-radius {x}: must be a finite number ≥ 0"));
            }
        }
        Ok(Inputs { config, data })
    }

    /// Loads inputs and computes the envelope that fits them: noise-free (Theorem 2 or 3),
    /// or noisy SISO (Theorem 4) when a noise radius is known.
    pub fn envelope(&self) -> Result<(Inputs, Envelope)> {
        let inputs = self.load()?;
        let env = noise_free_envelope(&inputs.config.factorization, &inputs.data)?;
        Ok((inputs, env))
    }
}

/// Formats a frequency for tables.
pub fn fmt_g(x: f64) -> String {
    if x.is_infinite() {
        "inf".into()
    } else if x == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&x.abs()) {
        format!("{x:.6}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{x:.4e}")
    }
}
