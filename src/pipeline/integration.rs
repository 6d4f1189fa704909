//! The points where the pipeline meets the μ module (Theorem 4, branch `mu`) and the fit of
//! `r` (branch `fit`).  Everything that depends on those modules goes through the functions
//! here, so that landing them changes this file only.
//!
//! Status: see the `INTEGRATION` markers.  Until the modules land:
//! - the noisy envelope falls back to the noise-free one (Theorem 2/3) with a warning;
//! - `μ_Γ` per datum is not available (no `mu.svg`);
//! - the "fit" is a constant unit `r = 1.05·max r_min` (a valid unit of RH∞ that covers
//!   every finite datum), clearly labelled as a placeholder in every output.

use crate::consistency::{noise_free_envelope, Envelope};
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::model::{Config, Factorization};
use crate::system::TransferFunction;
use serde::Serialize;
use serde_json::{json, Value};

/// Per-datum noise radii, in priority order: `--noise-radius` (or a manifest's per-dataset
/// radius), the config's `[noise] radius`, the data file's `noise_radius` column.  `None`
/// (noise-free) when none is given or all radii are zero.
// INTEGRATION(mu): replace with `model::noise::noise_radii` once it lands (same precedence).
pub fn noise_radii(config: &Config, data: &FrfData, cli: Option<f64>) -> Result<Option<Vec<f64>>> {
    if let Some(x) = cli {
        if !(x.is_finite() && x >= 0.0) {
            return Err(Error::Invalid(format!(
                "noise radius {x}: must be a finite number ≥ 0"
            )));
        }
    }
    let radii = match (cli, config.raw.noise.radius, &data.noise_radius) {
        (Some(x), _, _) => vec![x; data.len()],
        (None, Some(x), _) => vec![x; data.len()],
        (None, None, Some(col)) => col.clone(),
        (None, None, None) => return Ok(None),
    };
    Ok(radii.iter().any(|r| *r > 0.0).then_some(radii))
}

/// The envelope of the data: noise-free (Theorem 2 / Theorem 3) when `radii` is `None`,
/// noisy SISO (Theorem 4, bisection on `|r|` of the μ test) otherwise.  Returns the
/// envelope and any warning worth showing.
pub fn envelope(
    f: &Factorization,
    data: &FrfData,
    radii: Option<&[f64]>,
) -> Result<(Envelope, Vec<String>)> {
    match radii {
        None => Ok((noise_free_envelope(f, data)?, Vec::new())),
        Some(_) => {
            // INTEGRATION(mu): `consistency::noisy::noisy_envelope(f, data, radii, settings)`.
            let env = noise_free_envelope(f, data)?;
            Ok((
                env,
                vec!["the noisy envelope (Theorem 4) is not available in this build: the noise radius was ignored and the noise-free envelope (Theorem 2/3) is used".into()],
            ))
        }
    }
}

/// `μ_Γ{F_L[V(jω_i), φ_i⁻¹]}` per datum for the configured `r` (Fig. 8), for noisy data.
/// `None` when not available.
pub fn mu_per_datum(
    _f: &Factorization,
    _data: &FrfData,
    _radii: &[f64],
    _r: &TransferFunction,
) -> Option<Result<Vec<f64>>> {
    // INTEGRATION(mu): call the μ module here.
    None
}

/// A fitted unit `r` with its certificate, ready to be written as `r.json`.
#[derive(Debug, Clone)]
pub struct FittedR {
    /// The fitted unit.
    pub r: TransferFunction,
    /// The `r.json` document (coefficients, poles, zeros, gain, certificate).
    pub json: Value,
    /// The certificate part of `json`.
    pub certificate: Value,
}

/// A complex number as `[re, im]` in JSON.
#[derive(Serialize)]
struct C2([f64; 2]);

/// Fits the smallest unit `r` above the envelope.
// INTEGRATION(fit): call `fit::...` and take `r.json` from `report::export`.
pub fn fit_r(env: &Envelope, a1: Option<&dyn Fn(f64) -> f64>) -> Result<FittedR> {
    let top = env
        .r_min
        .iter()
        .copied()
        .filter(|r| r.is_finite())
        .fold(0.0f64, f64::max);
    if top <= 0.0 {
        return Err(Error::Invalid(
            "no datum with a finite, positive r_min: nothing to fit".into(),
        ));
    }
    let k = 1.05 * top;
    let r = TransferFunction::gain(k);
    let ratios: Vec<f64> = env
        .r_min
        .iter()
        .filter(|x| x.is_finite() && **x > 0.0)
        .map(|x| k / x)
        .collect();
    let min_ratio = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    let a1_ok = match a1 {
        Some(f) => env.omega.iter().all(|w| k < f(*w)),
        None => env
            .a1_limit
            .as_ref()
            .is_none_or(|a| a.iter().all(|l| k < *l)),
    };
    let certificate = json!({
        "covers_all_finite_data": env.r_min.iter().filter(|x| x.is_finite()).all(|x| k > *x),
        "min_ratio_at_data": min_ratio,
        "a1_holds_at_data": a1_ok,
        "infinite_data": env.r_min.iter().filter(|x| x.is_infinite()).count(),
        "dense_grid_checked": false,
    });
    let json = json!({
        "method": "constant_cover_placeholder",
        "note": "placeholder until the fit module lands: r = 1.05 * max finite r_min",
        "num": [k],
        "den": [1.0],
        "gain": k,
        "poles": Vec::<C2>::new(),
        "zeros": Vec::<C2>::new(),
        "certificate": certificate,
    });
    Ok(FittedR {
        r,
        json,
        certificate,
    })
}

/// Writes the exports of a fitted `r` into `dir` and returns the files written.
// INTEGRATION(fit): `report::export` writes r.json, r.m, r.py, r.jl.
pub fn export_r(fit: &FittedR, dir: &std::path::Path) -> Result<Vec<std::path::PathBuf>> {
    let path = dir.join("r.json");
    let text = serde_json::to_string_pretty(&fit.json)
        .map_err(|e| Error::Invalid(format!("r.json: {e}")))?;
    crate::util::write_atomic(&path, text.as_bytes())?;
    Ok(vec![path])
}
