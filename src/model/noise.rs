//! Noise models of the measurements (Boulet & Francis 1998, Sec. III, eqs. (4)–(5)).
//!
//! A datum `φ_i` is the true response plus a complex noise in the disk
//! `W_i = {w : |w| < L_a,i}` (eq. (5)).  The radius comes from one of three places:
//!
//! 1. a global radius `L_a`: the CLI flag `--noise-radius X`, or `[noise] radius = X`;
//! 2. the time-domain `L∞` model of Sec. III, `[noise] output_bound = M`: every datum gets the
//!    radius of the largest disk inside its uncertainty set `U` ([`linf_disk_radius`]);
//! 3. per-frequency radii: `[noise] std_file` (radius `std_factor·std`, default 3σ) or a
//!    `noise_radius` column in the data file.
//!
//! **Precedence** ([`resolve_noise`]): CLI flag > config (`radius`, `output_bound` or
//! `std_file`, which exclude each other) > data column.  When none is given there is no
//! noise model (use the noise-free theorems).

use super::Config;
use crate::data::std_file::read_std_csv;
use crate::data::FrfData;
use crate::error::{Error, Result};

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

/// The phase-noise bound of Sec. III, `L_θ = M/(A_m − M)` (radians), for an output-noise
/// bound `M` and a measured output amplitude `A_m`.  `None` when `A_m ≤ M` (the noise can
/// hide the whole sinusoid: no phase information).
pub fn phase_bound(output_bound: f64, measured_amplitude: f64) -> Option<f64> {
    (measured_amplitude > output_bound).then(|| output_bound / (measured_amplitude - output_bound))
}

/// Radius `L_a` of the largest disk inside the set (Sec. III)
/// `U = {(A_m + w_A)·e^{j(θ_m + w_θ)} : |w_A| ≤ M, |w_θ| ≤ L_θ}`, `L_θ = M/(A_m − M)`.
///
/// `U` is an annular sector: radii `[A_m − M, A_m + M]`, half-angle `L_θ`.  A disk centred on
/// the bisecting ray at distance `c` from the origin has radius at most `M − |c − A_m|`
/// (the two arcs) and `c·sin(min(L_θ, π/2))` (the two edges).  Maximizing over `c`:
///
/// * if `A_m·sin(min(L_θ, π/2)) ≥ M`: `L_a = M` (centre `c = A_m`);
/// * otherwise: `L_a = (A_m + M)·s/(1 + s)`, `s = sin(min(L_θ, π/2))`.
///
/// With `L_θ = M/(A_m − M)` the first case always holds when `A_m > M`: writing
/// `x = L_θ`, `A_m = M(1 + x)/x`, the condition is `(1 + x)·sin x ≥ x`, true for
/// `0 < x ≤ π/2` (since `sin x ≥ x − x³/6` and `x + x² ≤ 6`), and for `x > π/2` it reads
/// `A_m ≥ M`.  So `L_a = M`, as the paper anticipates ("close to M"); the general formula is
/// kept for clarity.  `W₀` is an *inner* approximation of `U`: it is the paper's model.
///
/// `None` when `A_m ≤ M` (see [`phase_bound`]).  `M = 0` gives 0.
pub fn linf_disk_radius(output_bound: f64, measured_amplitude: f64) -> Option<f64> {
    let (m, am) = (output_bound, measured_amplitude);
    if m == 0.0 {
        return Some(0.0);
    }
    let lt = phase_bound(m, am)?;
    let s = lt.min(std::f64::consts::FRAC_PI_2).sin();
    Some(if am * s >= m {
        m
    } else {
        (am + m) * s / (1.0 + s)
    })
}

/// Per-datum radii from the `L∞` output bound `M` (Sec. III): `L_a,i = R(M, U·|φ_i|)/U`, with
/// `R` = [`linf_disk_radius`] and `U` the input amplitude (the measured output amplitude is
/// `A_m = U·|φ_i|`; dividing by `U` brings the disk back to the units of `φ`).  SISO only.
pub fn radii_from_output_bound(
    output_bound: f64,
    input_amplitude: f64,
    data: &FrfData,
) -> Result<Vec<f64>> {
    if data.outputs() != 1 || data.inputs() != 1 {
        return Err(Error::Invalid(format!(
            "{}: [noise] output_bound (Sec. III) is defined for SISO data; these are {}×{}",
            data.path.display(),
            data.outputs(),
            data.inputs()
        )));
    }
    data.omega
        .iter()
        .zip(&data.response)
        .map(|(&omega, phi)| {
            let am = input_amplitude * phi[(0, 0)].norm();
            linf_disk_radius(output_bound, am)
                .map(|r| r / input_amplitude)
                .ok_or_else(|| Error::Assumption {
                    omega,
                    msg: format!(
                        "the measured amplitude A_m = {am:.4e} is not above the output-noise bound M = {output_bound:.4e} ({}): the phase is unknown (Sec. III); lower output_bound or remove the datum",
                        data.path.display()
                    ),
                })
        })
        .collect()
}

/// Resolves the noise model with precedence CLI flag > config > data column (see the module
/// documentation).  `Ok(None)` when no noise is given anywhere.
///
/// `data` must be the SISO data the envelope will use.  The config's `std_file` belongs to
/// the config's own data file; for other data (`--data`), `<data stem>_std.csv` beside them
/// is used, as `rshape compare` does.  Its column is `std_i_j` of the config's `[channel]`
/// (default `std_1_1`).
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
pub fn resolve_noise_for_channel(
    cli_radius: Option<f64>,
    config: Option<&Config>,
    data: &FrfData,
    (out, inp): (usize, usize),
) -> Result<Option<ResolvedNoise>> {
    let all = |r: f64| vec![r; data.len()];
    if let Some(r) = cli_radius {
        if !(r.is_finite() && r >= 0.0) {
            return Err(Error::Invalid(format!(
                "--noise-radius {r}: must be a finite number ≥ 0"
            )));
        }
        return Ok(Some(ResolvedNoise {
            radii: all(r),
            source: NoiseSource::CliFlag,
            description: format!("--noise-radius {r}"),
        }));
    }
    if let Some(cfg) = config {
        let sec = &cfg.raw.noise;
        sec.validate().map_err(Error::Invalid)?;
        if let Some(r) = sec.radius {
            return Ok(Some(ResolvedNoise {
                radii: all(r),
                source: NoiseSource::ConfigRadius,
                description: format!("[noise] radius = {r}"),
            }));
        }
        if let Some(m) = sec.output_bound {
            let u = sec.input_amplitude.unwrap_or(1.0);
            return Ok(Some(ResolvedNoise {
                radii: radii_from_output_bound(m, u, data)?,
                source: NoiseSource::ConfigOutputBound,
                description: format!("[noise] output_bound = {m} (Sec. III: L_a = M)"),
            }));
        }
        if let Some((file, k)) = &cfg.noise_std {
            let own = cfg.data.as_ref().is_some_and(|d| {
                d == &data.path
                    || d.canonicalize()
                        .ok()
                        .is_some_and(|a| Some(a) == data.path.canonicalize().ok())
            });
            let file = if own {
                file.clone()
            } else {
                let stem = data
                    .path
                    .file_stem()
                    .map(|s| s.to_string_lossy().to_string())
                    .unwrap_or_default();
                let sib = data.path.with_file_name(format!("{stem}_std.csv"));
                if !sib.exists() {
                    return Err(Error::Invalid(format!(
                        "{}: the config's [noise] std_file belongs to its own data; put {} beside these data or pass --noise-radius",
                        data.path.display(),
                        sib.display()
                    )));
                }
                sib
            };
            let radii = read_std_csv(&file)?.radius_at(&file, &data.omega, out, inp, *k)?;
            return Ok(Some(ResolvedNoise {
                description: format!("{k} × std_{out}_{inp} of {}", file.display()),
                radii,
                source: NoiseSource::ConfigStdFile,
            }));
        }
    }
    if let Some(col) = &data.noise_radius {
        if col.len() != data.len() {
            return Err(Error::Invalid(format!(
                "{}: {} noise radii for {} data",
                data.path.display(),
                col.len(),
                data.len()
            )));
        }
        return Ok(Some(ResolvedNoise {
            radii: col.clone(),
            source: NoiseSource::DataColumn,
            description: "noise_radius column of the data".into(),
        }));
    }
    Ok(None)
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
