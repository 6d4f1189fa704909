//! Noise models of the measurements (Boulet & Francis 1998, Sec. III, eqs. (4)–(5)); the
//! three sources and their precedence are in [`resolve_noise`]'s documentation.

mod files;
mod output_bound;

pub use output_bound::{linf_disk_radius, phase_bound, radii_from_output_bound};

use super::Config;
use crate::data::FrfData;
use crate::error::{Error, Result};
use files::{coherence_noise, std_file_noise};

/// Where the radii came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSource {
    /// `--noise-radius` on the command line.
    CliFlag,
    /// `[noise] radius` in the config.
    ConfigRadius,
    /// `[noise] output_bound` in the config (Sec. III, per datum).
    ConfigOutputBound,
    /// `[noise] std_file` × `std_factor` in the config.
    ConfigStdFile,
    /// `[noise] coherence` with `averages` and `coverage` in the config (H1 random error).
    ConfigCoherence,
    /// The `noise_radius` column of the data file.
    DataColumn,
}

/// Resolved per-datum noise radii `L_a,i`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ResolvedNoise {
    /// One radius per datum, in data units.
    pub radii: Vec<f64>,
    /// Where they came from.
    pub source: NoiseSource,
    /// The source in words, with its numbers (for reports).
    pub description: String,
}

/// The source of the noise radii under the precedence CLI flag > config > data column (see
/// the module documentation), decided without reading the data: `data_has_column` says
/// whether the data file has a `noise_radius` column.  `None`: no noise model.  This is the
/// one place the precedence is written; [`resolve_noise`] computes the radii of the source
/// it names, and the streamed envelope uses it to decide whether the data are noise-free.
pub fn noise_source(
    cli_radius: Option<f64>,
    config: Option<&Config>,
    data_has_column: bool,
) -> Option<NoiseSource> {
    if cli_radius.is_some() {
        return Some(NoiseSource::CliFlag);
    }
    if let Some(cfg) = config {
        let sec = &cfg.raw.noise;
        if sec.radius.is_some() {
            return Some(NoiseSource::ConfigRadius);
        }
        if sec.output_bound.is_some() {
            return Some(NoiseSource::ConfigOutputBound);
        }
        if cfg.noise_std.is_some() {
            return Some(NoiseSource::ConfigStdFile);
        }
        if sec.coherence.is_some() {
            return Some(NoiseSource::ConfigCoherence);
        }
    }
    data_has_column.then_some(NoiseSource::DataColumn)
}

/// Whether the noise the precedence selects is known to be zero without reading the data:
/// no source, or a global radius (flag or `[noise] radius`) of exactly 0.  Per-datum sources
/// (output bound, std file, data column) count as noisy.
pub fn is_noise_free(
    cli_radius: Option<f64>,
    config: Option<&Config>,
    data_has_column: bool,
) -> bool {
    match noise_source(cli_radius, config, data_has_column) {
        None => true,
        Some(NoiseSource::CliFlag) => cli_radius == Some(0.0),
        Some(NoiseSource::ConfigRadius) => config.and_then(|c| c.raw.noise.radius) == Some(0.0),
        Some(_) => false,
    }
}

/// Resolves the noise model with precedence CLI flag > config > data column.  `Ok(None)`
/// when no noise is given anywhere.
///
/// A datum `φ_i` is the true response plus a complex noise in the disk
/// `W_i = {w : |w| < L_a,i}` (eq. (5)).  The radius comes from one of three places:
///
/// 1. a global radius `L_a`: the CLI flag `--noise-radius X`, or `[noise] radius = X`;
/// 2. the time-domain `L∞` model of Sec. III, `[noise] output_bound = M`: every datum gets the
///    radius of the largest disk inside its uncertainty set `U` ([`linf_disk_radius`]);
/// 3. per-frequency radii: `[noise] std_file` (radius `std_factor·std`, default 3σ),
///    `[noise] coherence` (the coherence γ² of an H1 estimate over `averages = n`
///    averages: radius `coverage·ε·|H|`, `ε = √(1 − γ²)/(|γ|·√(2n))`, Bendat & Piersol,
///    *Random Data*, Table 9.6; default coverage 3) or a `noise_radius` column in the data
///    file.
///
/// **Precedence**: CLI flag > config (`radius`, `output_bound`, `std_file` or
/// `coherence`, which exclude each other) > data column.  When none is given there is no
/// noise model (use the noise-free theorems).
///
/// `data` must be the SISO data the envelope will use.  The config's `std_file` belongs to
/// the config's own data file; for other data (`--data`), `<data stem>_std.csv` beside them
/// is used, as `rshape compare` does.  Its column is `std_i_j` of the config's `[channel]`
/// (default `std_1_1`); the same for `coherence` (`<data stem>_coherence.csv`, column
/// `coh_i_j`).
pub fn resolve_noise(
    cli_radius: Option<f64>,
    config: Option<&Config>,
    data: &FrfData,
) -> Result<Option<ResolvedNoise>> {
    let channel = config
        .and_then(|c| c.raw.channel)
        .map_or((1, 1), |c| (c.output, c.input));
    resolve_noise_for_channel(cli_radius, config, data, channel)
}

/// [`resolve_noise`] for the SISO channel `(output, input)` (1-based) of the data: the
/// channel selects the `std_<out>_<in>` column of a `[noise] std_file`.  Used by `compare`
/// and `diagnose`, which may select the channel with `--channel`.
///
/// With a config's `[scaling]` the data are in the model's units (`Φ_s = D_o·Φ·D_i`, as
/// the pipeline prepares them) while every noise source (a radius, `--noise-radius`, an
/// output bound, a std or coherence file, the data column) is in the data file's: the
/// noise is resolved on the unscaled data `D_o⁻¹·Φ_s·D_i⁻¹` and the radii scaled like the
/// entry they bound, by `d_o,k·d_i,l` of the channel (the only place this is done: `run`,
/// `compare` and the Python package all come here).  A misfit `|G_d − G_m|/L` is then the
/// same in either units.
pub fn resolve_noise_for_channel(
    cli_radius: Option<f64>,
    config: Option<&Config>,
    data: &FrfData,
    channel: (usize, usize),
) -> Result<Option<ResolvedNoise>> {
    let Some(s) = config.and_then(|c| c.scaling.as_ref()) else {
        return resolve_in_file_units(cli_radius, config, data, channel);
    };
    let (p, m) = (data.outputs(), data.inputs());
    if !data.is_empty() && (p, m) != (s.outputs.len(), s.inputs.len()) {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!(
                "the data are {p}×{m} and [scaling] is for a {}×{} plant: the noise cannot be put in the model's units",
                s.outputs.len(),
                s.inputs.len()
            ),
        });
    }
    // SISO data are the channel already; MIMO data hold it at (out, inp).
    let at = if (p, m) == (1, 1) {
        (0, 0)
    } else {
        (channel.0.max(1) - 1, channel.1.max(1) - 1)
    };
    if !data.is_empty() && (at.0 >= p || at.1 >= m) {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!(
                "channel ({}, {}) is not in the {p}×{m} data",
                channel.0, channel.1
            ),
        });
    }
    let k = s.entry_factor(at);
    let file_units = s.unscale_frf(data.clone());
    Ok(
        resolve_in_file_units(cli_radius, config, &file_units, channel)?.map(|r| ResolvedNoise {
            radii: r.radii.iter().map(|x| x * k).collect(),
            source: r.source,
            description: format!(
                "{} (data file's units; × {} = d_o·d_i of [scaling])",
                r.description,
                crate::report::fmt::fmt_g(k)
            ),
        }),
    )
}

/// [`resolve_noise_for_channel`] on data in the data file's units.
fn resolve_in_file_units(
    cli_radius: Option<f64>,
    config: Option<&Config>,
    data: &FrfData,
    (out, inp): (usize, usize),
) -> Result<Option<ResolvedNoise>> {
    let all = |r: f64| vec![r; data.len()];
    if let (None, Some(cfg)) = (cli_radius, config) {
        cfg.raw.noise.validate().map_err(Error::Invalid)?;
    }
    let Some(source) = noise_source(cli_radius, config, data.noise_radius.is_some()) else {
        return Ok(None);
    };
    let resolved = match (source, config) {
        (NoiseSource::CliFlag, _) => {
            let r = cli_radius.unwrap_or_default();
            if !(r.is_finite() && r >= 0.0) {
                return Err(Error::Argument {
                    arg: format!("--noise-radius {r}"),
                    msg: "must be a finite number ≥ 0".into(),
                });
            }
            ResolvedNoise {
                radii: all(r),
                source,
                description: format!("--noise-radius {r}"),
            }
        }
        (NoiseSource::ConfigRadius, Some(cfg)) => {
            let r = cfg.raw.noise.radius.unwrap_or_default();
            ResolvedNoise {
                radii: all(r),
                source,
                description: format!("[noise] radius = {r}"),
            }
        }
        (NoiseSource::ConfigOutputBound, Some(cfg)) => {
            let sec = &cfg.raw.noise;
            let m = sec.output_bound.unwrap_or_default();
            let u = sec.input_amplitude.unwrap_or(1.0);
            ResolvedNoise {
                radii: radii_from_output_bound(m, u, data)?,
                source,
                description: format!("[noise] output_bound = {m} (Sec. III: L_a = M)"),
            }
        }
        (NoiseSource::ConfigStdFile, Some(cfg)) => std_file_noise(cfg, data, (out, inp))?,
        (NoiseSource::ConfigCoherence, Some(cfg)) => coherence_noise(cfg, data, (out, inp))?,
        _ => {
            let col = data.noise_radius.clone().unwrap_or_default();
            if col.len() != data.len() {
                return Err(Error::Input {
                    path: data.path.to_path_buf(),
                    msg: format!("{} noise radii for {} data", col.len(), data.len()),
                });
            }
            ResolvedNoise {
                radii: col,
                source: NoiseSource::DataColumn,
                description: "noise_radius column of the data".into(),
            }
        }
    };
    Ok(Some(resolved))
}

/// The per-datum radii only (see [`resolve_noise`]): CLI flag > config > data column;
/// `Ok(None)` when there is no noise model.
pub fn noise_radii(
    cli_radius: Option<f64>,
    config: Option<&Config>,
    data: &FrfData,
) -> Result<Option<Vec<f64>>> {
    Ok(resolve_noise(cli_radius, config, data)?.map(|r| r.radii))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn config(noise: &str) -> Config {
        let text = format!("[plant]\ntf = [[{{ num = [1], den = [1, 1] }}]]\n{noise}\n");
        Config::parse(&text, Path::new("c.toml")).expect("valid config")
    }

    /// The precedence CLI flag > config > data column, and zero radii as noise-free.
    #[test]
    fn precedence_and_noise_free_decision() {
        let none = config("");
        let radius = config("[noise]\nradius = 0.1");
        let zero = config("[noise]\nradius = 0");
        let bound = config("[noise]\noutput_bound = 0.01");
        assert_eq!(noise_source(None, Some(&none), false), None);
        assert_eq!(
            noise_source(None, Some(&none), true),
            Some(NoiseSource::DataColumn)
        );
        assert_eq!(
            noise_source(Some(0.0), Some(&radius), true),
            Some(NoiseSource::CliFlag)
        );
        assert_eq!(
            noise_source(None, Some(&radius), true),
            Some(NoiseSource::ConfigRadius)
        );
        assert_eq!(
            noise_source(None, Some(&bound), true),
            Some(NoiseSource::ConfigOutputBound)
        );
        assert!(is_noise_free(None, Some(&none), false));
        assert!(!is_noise_free(None, Some(&none), true));
        assert!(is_noise_free(Some(0.0), Some(&radius), true));
        assert!(!is_noise_free(Some(0.2), Some(&zero), false));
        assert!(is_noise_free(None, Some(&zero), true));
        assert!(!is_noise_free(None, Some(&radius), false));
        assert!(!is_noise_free(None, Some(&bound), false));
        let coherence = config("[noise]\ncoherence = \"coh.csv\"\naverages = 5");
        assert_eq!(
            noise_source(None, Some(&coherence), true),
            Some(NoiseSource::ConfigCoherence)
        );
        assert_eq!(
            noise_source(Some(0.1), Some(&coherence), true),
            Some(NoiseSource::CliFlag)
        );
        assert!(!is_noise_free(None, Some(&coherence), false));
    }
}
